#pragma once
/// The one interface every controller implements, beside the plant's (plant.h): HiL exists to
/// test the user's controller (thesis §1), and a student's code must be separable from the
/// infrastructure around it (thesis §3.2). A controller has named input ports (encoder
/// readings, setpoints) and output ports (motor duties), each with a unit, and steps by a fixed
/// step. Everything that may allocate, load or do I/O happens in Start(); Step() is the
/// real-time path: noexcept, no allocation, no locks, no system calls, and it reports trouble
/// with a status value.
///
/// Which board channel feeds which input, and which output drives which PWM channel, is not the
/// controller's: a controller map (controller_map.h) configures it, so the same controller runs
/// the twin and the robot, and a controller never knows the board.
///
/// Kinds (controller_registry.h, `hiltwin ecs --controller SPEC`):
///   pid          the built-in position PID per wheel (thesis §7.2), the default
///   lib:PATH.so  a shared library with the C ABI of hiltwin/controller_abi.h
///   20sim:NAME   a 20-sim "C++ class for 20-sim submodel" LoopController built into hiltwin
///   fmu:PATH.fmu an FMI 2.0 co-simulation FMU

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/plant/plant.h"

namespace hiltwin::controller {

/// One input or output of a controller: a name and a unit, as a plant's.
using Port = plant::Port;

/// What a controller is, fixed once it is built: what the run report and the start line say,
/// so a result can be traced to the code that produced it.
struct ControllerInfo {
  std::string spec;  ///< as given to --controller ("pid", "lib:./my_pd.so", "20sim:pid20sim")
  std::string kind;  ///< "built-in", "C ABI shared library", "20-sim C++ class",
                     ///< "FMI 2.0 co-simulation"
  std::string name;  ///< the controller's own name (the ABI descriptor's, the FMU's modelName)
  /// The file the code came from ("" for code built into hiltwin) and the SHA-256 of its
  /// bytes, lower-case hex ("" when there is no file).
  std::string file;
  std::string content_sha256;
  std::vector<Port> inputs;
  std::vector<Port> outputs;
  /// The step the controller was made for, in seconds (20-sim's m_step_size, an FMU's
  /// DefaultExperiment stepSize, the ABI descriptor's step); 0 when any step will do.
  double model_step_s = 0.0;
  /// True when the controller can only run at model_step_s (20-sim code: the step is compiled
  /// in; an ABI controller that says so).
  bool step_is_fixed = false;
  /// Further facts for the report (ABI version, gains, FMU GUID...).
  std::vector<std::pair<std::string, std::string>> details;
};

/// A controller that cannot be built or run as asked (no such file, wrong ABI version, a
/// missing symbol, a step it cannot run at). The message says what, where and what to do;
/// commands turn it into exit 2.
class ControllerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How one step ended. `reason` is static text or text the controller owns until Finish (the
/// real-time path cannot build strings).
struct ControllerStatus {
  enum class Code : std::uint8_t {
    kOk,
    kError,  ///< the controller says it cannot go on (its step returned an error)
  };
  Code code = Code::kOk;
  const char* reason = "";

  [[nodiscard]] static ControllerStatus Ok() noexcept { return {}; }
  [[nodiscard]] static ControllerStatus Error(const char* why) noexcept {
    return {Code::kError, why};
  }
  [[nodiscard]] bool ok() const noexcept { return code == Code::kOk; }
};

class Controller {
 public:
  virtual ~Controller() = default;

  [[nodiscard]] virtual const ControllerInfo& Info() const noexcept = 0;

  /// Not real-time. Makes the controller ready to step every `step_s` seconds from time 0.
  /// Throws ControllerError when it cannot run at that step or cannot start (its start entry
  /// point failed, an FMU that does not initialise).
  virtual void Start(double step_s) = 0;

  /// Real-time. One step: the inputs `in` (Info().inputs.size() values, sampled at the start
  /// of the step) give the outputs `out` (Info().outputs.size() values) to apply from the next
  /// exchange on. The caller checks the outputs (finite, within the map's duty limits); the
  /// controller need not.
  [[nodiscard]] virtual ControllerStatus Step(std::span<const double> in,
                                              std::span<double> out) noexcept = 0;

  /// Not real-time. Ends the controller after the run; safe to call more than once and
  /// without Start().
  virtual void Finish() noexcept {}
};

}  // namespace hiltwin::controller
