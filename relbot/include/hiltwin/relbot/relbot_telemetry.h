#pragma once
/// The RELbot's telemetry (runtime/telemetry.h), one definition for both sides of a HiL pair:
/// the twin publishes its pose and its wheels as the model moves them; the controller its
/// wheels as its encoders measure them. Joint names follow ROS conventions for a
/// differential drive, so a robot description's wheel joints line up.

#include <string>
#include <vector>

#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::app {

/// The shape of `role` ("twin" has a pose; "controller" does not) with the two wheel joints.
[[nodiscard]] inline runtime::TelemetryShape RelbotTelemetryShape(const char* role, bool has_pose) {
  return {role, has_pose, {"wheel_left_joint", "wheel_right_joint"}};
}

/// Wheel travel in metres as joints: the angle is travel / radius (a rolling wheel).
inline void FillWheelJoints(runtime::TaskTelemetry& out, double left_m, double right_m,
                            double wheel_radius_m) noexcept {
  out.joint_count = 2;
  out.joint_position_m[0] = left_m;
  out.joint_position_m[1] = right_m;
  out.joint_position_rad[0] = left_m / wheel_radius_m;
  out.joint_position_rad[1] = right_m / wheel_radius_m;
}

/// The two wheels' setpoints (travel, m) beside their joints: a closed loop's.
inline void FillWheelSetpoint(runtime::TaskTelemetry& out, double left_m, double right_m) noexcept {
  out.has_setpoint = true;
  out.joint_setpoint_m[0] = left_m;
  out.joint_setpoint_m[1] = right_m;
}

}  // namespace hiltwin::app
