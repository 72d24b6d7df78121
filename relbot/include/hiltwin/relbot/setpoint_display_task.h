#pragma once
/// A twin task whose telemetry also carries a setpoint profile (`run --show-setpoint`): the
/// setpoint a controller follows, sampled at the twin's own time, so a page served by the twin
/// (`hil --web`: the twin serves it) draws it beside the robot. The twin's dynamics and log are
/// untouched: only FillTelemetry adds to the wrapped task's.

#include <span>
#include <string>
#include <vector>

#include "hiltwin/relbot/relbot_telemetry.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::app {

/// Wraps a RELbot twin's task (its joints are the two wheels, left then right). The task and
/// the profile must outlive the wrapper. The profile's time is the task's (LogTimeS): a pause
/// stops both, as the ECS's profile clock stops while it is paused.
class SetpointDisplayTask final : public runtime::RunTask {
 public:
  SetpointDisplayTask(runtime::RunTask& task, const SetpointProfile& setpoints) noexcept
      : task_(task), setpoints_(setpoints) {}

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override {
    return task_.Exchange(live_outputs);
  }
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override {
    return task_.Step(context);
  }
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return task_.LogColumns(); }
  [[nodiscard]] double LogTimeS() const noexcept override { return task_.LogTimeS(); }
  void FillLogRow(std::span<double> values) const noexcept override { task_.FillLogRow(values); }
  [[nodiscard]] runtime::TelemetryShape TelemetryShapeOf() const override {
    return task_.TelemetryShapeOf();
  }
  /// The wrapped task's values and the profile's setpoint at its time (allocation-free).
  void FillTelemetry(runtime::TaskTelemetry& out) const noexcept override {
    task_.FillTelemetry(out);
    const WheelPositions setpoint = setpoints_.At(task_.LogTimeS());
    FillWheelSetpoint(out, setpoint.left_m, setpoint.right_m);
  }

 private:
  runtime::RunTask& task_;
  const SetpointProfile& setpoints_;
};

}  // namespace hiltwin::app
