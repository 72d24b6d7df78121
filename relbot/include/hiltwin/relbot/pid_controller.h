#pragma once
/// The built-in position PID (thesis §7.2) as a controller (controller/controller.h),
/// `--controller pid`, the default: inputs setpoint_left_m, setpoint_right_m, wheel_left_m,
/// wheel_right_m (m), outputs duty_left, duty_right (1), one PositionPid per wheel with the
/// --gains. And the RELbot's controller map, the board wiring every controller kind runs with
/// when no --controller-map is given (relbot/ecs_controller_map.toml is the same map as a file).

#include <memory>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_map.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/relbot/position_pid.h"

namespace hiltwin::app {

/// The name `--controller` knows it by.
inline constexpr const char* kPidControllerName = "pid";

class PidController final : public controller::Controller {
 public:
  /// Throws ConfigError for invalid gains.
  explicit PidController(const PidGains& gains);

  [[nodiscard]] const controller::ControllerInfo& Info() const noexcept override { return info_; }
  /// Discretises both PIDs for `step_s` (any step > 0 will do).
  void Start(double step_s) override;
  [[nodiscard]] controller::ControllerStatus Step(std::span<const double> in,
                                                  std::span<double> out) noexcept override;

  [[nodiscard]] const PositionPid& left() const noexcept { return left_; }
  [[nodiscard]] const PositionPid& right() const noexcept { return right_; }
  [[nodiscard]] const PidGains& gains() const noexcept { return gains_; }

 private:
  PidGains gains_;
  controller::ControllerInfo info_;
  PositionPid left_;
  PositionPid right_;
};

/// The RELbot's controller map for a wheel geometry (WheelGeometryOf(params) of --config):
/// encoder channels per relbot_channels.h into wheel_left_m / wheel_right_m, setpoint columns
/// left_m / right_m into setpoint_left_m / setpoint_right_m (tracking their wheels, on the
/// encoder grid), duty_left / duty_right onto the PWM channels with gain 1 and duty_limit 1.
[[nodiscard]] controller::ControllerMap RelbotControllerMap(const io::WheelGeometry& geometry);

/// Registers `pid` (controller_registry.h); idempotent. The command line calls it before it
/// looks a controller up, as it calls RegisterRelbotPlant.
void RegisterPidController();

}  // namespace hiltwin::app
