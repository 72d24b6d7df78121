#pragma once
/// Any controller as the ECS's run task, as PlantTwinTask runs any plant as the twin's
/// (docs/architecture.md, "One cycle, as data flows"). Per cycle: one full-duplex exchange (the
/// duty of the last step goes out, the encoder counts come in), then one step: the counts since
/// the first reading through the controller map's encoder routes into the controller's
/// inputs, the setpoint columns at the task's time into theirs (on_encoder_grid: rounded to
/// the tracked encoder's whole counts), the controller's Step, and its outputs through the
/// PWM routes (gain, direction) into the PWM words of the next exchange.
///
/// The controller's step runs inside the task's step, so its time is the ECS's compute and its
/// overruns reach the ECS's QoS verdict. Its outputs are checked before they reach a motor: an
/// error status, a non-finite output or a duty beyond its route's duty_limit stops the
/// controller with zero duty (safe outputs) and a model fault naming the controller, the port
/// and what was wrong: the run ends as a plant's model fault does (exit 1, "the run did NOT
/// finish: model fault at cycle N", docs/architecture.md "Exit codes"), and fault() has the
/// details for the report.
///
/// Time is the task's own: (cycle − paused cycles) × period_ns, so a pause stops the setpoint
/// profile rather than skipping part of it. Everything on the loop's path is noexcept and
/// allocation-free: the port vectors and the fault texts are made in the constructor.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_map.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::controller {

/// The setpoint profile's columns at a time: [0] left_m, [1] right_m
/// (BoundControllerMap::Setpoint::column_index). The ECS adapts its own profile to it, so this
/// tier does not depend on the RELbot's. Called on the loop's path: noexcept, no allocation.
class SetpointColumns {
 public:
  virtual ~SetpointColumns() = default;
  [[nodiscard]] virtual std::array<double, 2> At(double time_s) const noexcept = 0;
};

/// The tracking error (setpoint column − the tracked encoder input, before any grid rounding)
/// of one `tracks` pair over every step since the start.
struct TrackingPair {
  std::string column;   ///< "left_m" or "right_m"
  std::string input;    ///< the setpoint's controller input
  std::string tracked;  ///< the encoder-fed input it is a setpoint for
  std::uint64_t samples = 0;
  double max_abs_error = 0.0;
  double sum_sq_error = 0.0;  ///< Σ error², for an rms over several pairs
  double rms_error = 0.0;
  double final_error = 0.0;  ///< at the last step
};

/// Why the controller was stopped, for the report (what the fault's reason says, in parts).
struct ControllerFault {
  enum class Kind : std::uint8_t { kNone, kErrorStatus, kNotFinite, kBeyondLimit };
  Kind kind = Kind::kNone;
  std::string output;        ///< the output port at fault ("" for an error status)
  double value = 0.0;        ///< the duty it asked for (kNotFinite, kBeyondLimit)
  double duty_limit = 0.0;   ///< its route's limit
  std::string reason;        ///< the controller's own words (kErrorStatus), or ""
  std::uint64_t cycle = 0;   ///< the cycle whose step stopped it
};

class ControllerTask final : public runtime::RunTask {
 public:
  /// Starts `controller` at period_ns (Controller::Start: ControllerError when it cannot run
  /// at it; without starting it when its step is fixed (ControllerInfo::step_is_fixed) at
  /// another). None of the references is owned; all must outlive the task. `map` must be bound
  /// to `controller`. Throws std::invalid_argument for period_ns <= 0.
  ControllerTask(io::IcoBoard& board, Controller& controller, BoundControllerMap map,
                 const SetpointColumns& setpoints, std::int64_t period_ns);
  ~ControllerTask() override;
  ControllerTask(const ControllerTask&) = delete;
  ControllerTask& operator=(const ControllerTask&) = delete;

  /// Live: sends the duty of the last step. Safe: sends zero duty (motors off).
  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  /// The controller's inputs, then its outputs, by port name.
  [[nodiscard]] std::vector<std::string> LogColumns() const override;
  [[nodiscard]] double LogTimeS() const noexcept override { return time_s_; }
  void FillLogRow(std::span<double> values) const noexcept override;

  [[nodiscard]] std::span<const double> inputs() const noexcept { return in_; }
  [[nodiscard]] std::span<const double> outputs() const noexcept { return out_; }
  /// The setpoint columns at the last step's time, as the profile gives them.
  [[nodiscard]] const std::array<double, 2>& setpoint_columns() const noexcept { return columns_; }
  /// Counts per channel since the first reading (0 until a frame has arrived).
  [[nodiscard]] const std::array<std::int64_t, io::kChannels>& counts() const noexcept {
    return counts_;
  }
  [[nodiscard]] const std::array<std::int32_t, io::kChannels>& pwm_sent() const noexcept {
    return pwm_sent_;
  }
  [[nodiscard]] const std::array<std::int32_t, io::kChannels>& pwm_next() const noexcept {
    return pwm_next_;
  }
  [[nodiscard]] const io::EcsInputs& board_inputs() const noexcept { return board_in_; }
  [[nodiscard]] double time_s() const noexcept { return time_s_; }
  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_; }
  [[nodiscard]] const Controller& controller() const noexcept { return controller_; }
  [[nodiscard]] const BoundControllerMap& map() const noexcept { return map_; }

  /// Per `tracks` pair, in map order. Not synchronised: read after the run.
  [[nodiscard]] std::vector<TrackingPair> tracking() const;
  /// Steps in which any output's duty was at its route's duty_limit.
  [[nodiscard]] std::uint64_t saturated_cycles() const noexcept { return saturated_cycles_; }
  /// The largest |duty| the controller commanded (before the PWM's quantisation).
  [[nodiscard]] double max_abs_duty() const noexcept { return max_abs_duty_; }
  /// kNone while the controller runs.
  [[nodiscard]] ControllerFault fault() const;

 private:
  /// One `tracks` pair's running sums (kept on the loop thread).
  struct PairSums {
    std::size_t setpoint = 0;  ///< index into map_.setpoints
    std::size_t encoder = 0;   ///< index into map_.encoders
    std::uint64_t samples = 0;
    double max_abs = 0.0;
    double sum_sq = 0.0;
    double final_error = 0.0;
  };
  /// The fault texts of one PWM route, made once (the loop cannot build strings).
  struct RouteTexts {
    std::string not_finite;
    std::string beyond_limit;
  };

  void ReadCounts() noexcept;
  void FeedInputs() noexcept;
  [[nodiscard]] runtime::StepStatus DriveOutputs() noexcept;
  [[nodiscard]] runtime::StepStatus Stop(ControllerFault::Kind kind, std::size_t route,
                                         double value, const char* reason) noexcept;
  void Track() noexcept;
  /// The fault text of an error status, with the controller's reason (fault_reason_).
  [[nodiscard]] const char* ComposeErrorStatusText() noexcept;

  io::IcoBoard& board_;
  Controller& controller_;
  BoundControllerMap map_;
  const SetpointColumns& setpoints_;
  std::int64_t period_ns_;
  std::vector<double> in_;
  std::vector<double> out_;
  std::vector<double> duty_;  ///< per PWM route, this step
  std::vector<PairSums> pairs_;
  std::vector<RouteTexts> texts_;
  std::string error_status_text_;  ///< "<who> stopped: its step returned an error"
  /// error_status_text_, the controller's own reason and the end, composed at the fault
  /// without allocating; longer texts are cut (the report's fault.reason has it whole).
  std::array<char, 512> error_status_buffer_{};
  std::string period_text_;
  io::EcsInputs board_in_{};
  std::array<double, 2> columns_{};
  std::array<std::int32_t, io::kChannels> pwm_next_{};  ///< computed by the last step
  std::array<std::int32_t, io::kChannels> pwm_sent_{};  ///< on the wire since the last exchange
  std::array<std::int64_t, io::kChannels> origin_{};    ///< absolute counts of the first reading
  std::array<std::int64_t, io::kChannels> counts_{};
  bool have_inputs_ = false;  ///< an exchange has succeeded: the counts are a reading
  bool started_ = false;      ///< the origin is taken
  std::uint64_t held_cycles_ = 0;  ///< exchanges with safe outputs (paused): not profile time
  double time_s_ = 0.0;
  std::uint64_t saturated_cycles_ = 0;
  double max_abs_duty_ = 0.0;
  // The fault, as the loop recorded it; fault() turns it into text.
  ControllerFault::Kind fault_kind_ = ControllerFault::Kind::kNone;
  std::size_t fault_route_ = 0;
  double fault_value_ = 0.0;
  const char* fault_reason_ = "";
  std::uint64_t fault_cycle_ = 0;
  const char* fault_text_ = "";
};

}  // namespace hiltwin::controller
