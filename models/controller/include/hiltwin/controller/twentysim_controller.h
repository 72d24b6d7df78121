#pragma once
/// A controller made of 20-sim's "C++ class for 20-sim submodel" code (docs/20sim.md, "20-sim
/// controllers"): the thesis's ECS runs the LoopController class 20-sim generates from the
/// position controller (thesis §6, appendix F). TwentySimController wraps any class of that
/// shape over the life cycle the plant adapter shares (plant/twentysim_submodel.h);
/// `hiltwin_add_20sim_controller` (cmake/TwentySimPlant.cmake) instantiates it for a generated
/// folder and registers it: `--controller 20sim:NAME` (the `20sim` kind) and `--controller
/// NAME` both find it.
///
/// What the adapter calls when:
///   constructor  builds the submodel and reads m_step_size for Info();
///   Start        checks the ECS's step against m_step_size (ControllerError naming --rate),
///                then Initialize(u = 0, y, 0.0);
///   Step         Calculate(u, y): exactly one step of m_step_size (real-time);
///   Finish       Terminate, once.

#include <algorithm>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/plant/twentysim_submodel.h"

namespace hiltwin::controller {

/// Adds a 20-sim controller: a named entry (RegisterController) that the `20sim` kind also
/// finds. Returns true so it can initialise a namespace-scope constant (the registration file
/// hiltwin_add_20sim_controller generates).
bool RegisterTwentySimController(ControllerEntry entry);

/// Registers the `20sim` kind (`--controller 20sim:NAME`); idempotent. Its loader names the
/// 20-sim controllers built in when NAME is not one of them.
void RegisterTwentySimControllerKind();

/// The names of the 20-sim controllers built in, sorted.
[[nodiscard]] std::vector<std::string> TwentySimControllerNames();

/// Throws ControllerError for the options a 20-sim controller cannot honour (--gains): the
/// generated code has its parameters compiled in.
void RefuseTwentySimControllerOptions(const ControllerOptions& options, std::string_view name,
                                      std::string_view class_name);

/// Any 20-sim submodel class as a Controller. Not thread-safe; Step() is the real-time path.
template <class Submodel>
class TwentySimController final : public Controller {
 public:
  /// `content_sha256`: of the generated folder (hiltwin_add_20sim_controller computes it).
  /// Throws ControllerError when the code's step is not a positive number or the finish time
  /// is negative.
  TwentySimController(plant::TwentySimSpec spec, std::string content_sha256)
      : core_(std::move(spec), "controller") {
    core_.Describe(info_);
    info_.spec = "20sim:" + core_.spec().name;
    info_.file = core_.spec().source_dir;
    info_.content_sha256 = std::move(content_sha256);
  }

  ~TwentySimController() override = default;  // the core terminates the submodel
  TwentySimController(const TwentySimController&) = delete;
  TwentySimController& operator=(const TwentySimController&) = delete;
  TwentySimController(TwentySimController&&) = delete;
  TwentySimController& operator=(TwentySimController&&) = delete;

  [[nodiscard]] const ControllerInfo& Info() const noexcept override { return info_; }

  /// A fresh submodel initialised with all inputs 0 (a second Start begins again).
  void Start(double step_s) override {
    core_.CheckStep(step_s);
    core_.Initialize({});
  }

  [[nodiscard]] ControllerStatus Step(std::span<const double> in,
                                      std::span<double> out) noexcept override {
    if (!core_.initialized()) {
      return ControllerStatus::Error(
          "the 20-sim controller was stepped before Start or after "
          "Finish");
    }
    if (in.size() != info_.inputs.size() || out.size() != info_.outputs.size()) {
      return ControllerStatus::Error(
          "the 20-sim controller was stepped with the wrong port "
          "count");
    }
    const bool running = core_.Calculate(in);
    const std::span<const double> y = core_.outputs();
    std::copy(y.begin(), y.end(), out.begin());
    if (!running) {
      return ControllerStatus::Error(
          "the 20-sim controller reached its finish time "
          "(m_finish_time)");
    }
    return ControllerStatus::Ok();
  }

  void Finish() noexcept override { core_.Terminate(); }

  /// The submodel itself (m_time, state...), for diagnostics and tests.
  [[nodiscard]] const Submodel& model() const noexcept { return core_.model(); }

 private:
  plant::TwentySimCore<Submodel, ControllerError> core_;
  ControllerInfo info_;
};

}  // namespace hiltwin::controller
