#pragma once
// An in-process controller whose ports and step a test chooses: the controller task's and the
// map binder's tests need controllers that misbehave on purpose.
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller::test {

class FakeController final : public Controller {
 public:
  using StepFn = std::function<ControllerStatus(std::span<const double>, std::span<double>)>;

  FakeController(std::vector<Port> inputs, std::vector<Port> outputs, StepFn step = {})
      : step_(std::move(step)) {
    info_.spec = "fake";
    info_.kind = "test";
    info_.name = "fake";
    info_.inputs = std::move(inputs);
    info_.outputs = std::move(outputs);
  }

  /// The RELbot's ports (controller_registry.h's default wiring).
  static std::vector<Port> RelbotInputs() {
    return {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"}, {"wheel_left_m", "m"},
            {"wheel_right_m", "m"}};
  }
  static std::vector<Port> RelbotOutputs() { return {{"duty_left", "1"}, {"duty_right", "1"}}; }

  [[nodiscard]] const ControllerInfo& Info() const noexcept override { return info_; }
  /// A controller that runs only at `step_s` (20-sim code, an ABI controller that says so).
  void FixStep(double step_s) {
    info_.model_step_s = step_s;
    info_.step_is_fixed = true;
  }
  void Start(double step_s) override {
    started_step_s = step_s;
    ++starts;
  }
  [[nodiscard]] ControllerStatus Step(std::span<const double> in,
                                      std::span<double> out) noexcept override {
    ++steps;
    if (record_inputs) last_in.assign(in.begin(), in.end());  // allocates: off under a counter
    return step_ ? step_(in, out) : ControllerStatus::Ok();
  }
  void Finish() noexcept override { ++finishes; }

  bool record_inputs = true;
  double started_step_s = 0.0;
  int starts = 0;
  int steps = 0;
  int finishes = 0;
  std::vector<double> last_in;

 private:
  ControllerInfo info_;
  StepFn step_;
};

}  // namespace hiltwin::controller::test
