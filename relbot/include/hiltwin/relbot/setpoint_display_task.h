#pragma once
/// A twin task whose telemetry also carries a setpoint profile (`run --show-setpoint`): the
/// setpoint a controller follows, sampled at the twin's own time, so a page served by the twin
/// (`hil --web`: the twin serves it) draws it beside the robot. The twin's dynamics and log are
/// untouched: only FillTelemetry adds to the wrapped task's.

#include "hiltwin/relbot/relbot_telemetry.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runtime/forwarding_task.h"

namespace hiltwin::app {

/// Wraps a RELbot twin's task (its joints are the two wheels, left then right). The task and
/// the profile must outlive the wrapper. The profile's time is the task's (LogTimeS): a pause
/// stops both, as the ECS's profile clock stops while it is paused.
class SetpointDisplayTask final : public runtime::ForwardingTask {
 public:
  SetpointDisplayTask(runtime::RunTask& task, const SetpointProfile& setpoints) noexcept
      : ForwardingTask(task), setpoints_(setpoints) {}

  /// The wrapped task's values and the profile's setpoint at its time (allocation-free).
  void FillTelemetry(runtime::TaskTelemetry& out) const noexcept override {
    wrapped().FillTelemetry(out);
    const WheelPositions setpoint = setpoints_.At(wrapped().LogTimeS());
    FillWheelSetpoint(out, setpoint.left_m, setpoint.right_m);
  }

 private:
  const SetpointProfile& setpoints_;
};

}  // namespace hiltwin::app
