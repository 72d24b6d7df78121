// The built-in position PID as a controller, and the RELbot's controller map
// (pid_controller.h).
#include "hiltwin/relbot/pid_controller.h"

#include <mutex>

#include "hiltwin/controller/controller_registry.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {
namespace {

// Port order: what Step indexes.
constexpr std::size_t kSetpointLeft = 0;
constexpr std::size_t kSetpointRight = 1;
constexpr std::size_t kWheelLeft = 2;
constexpr std::size_t kWheelRight = 3;
constexpr std::size_t kDutyLeft = 0;
constexpr std::size_t kDutyRight = 1;

const PidGains& Validated(const PidGains& gains) {
  ValidateEcsGains(gains, "ECS gains");
  return gains;
}

controller::ControllerInfo PidInfo() {
  controller::ControllerInfo info;
  info.spec = kPidControllerName;
  info.kind = "built-in";
  info.name = "pid";
  info.inputs = {{"setpoint_left_m", "m"},
                 {"setpoint_right_m", "m"},
                 {"wheel_left_m", "m"},
                 {"wheel_right_m", "m"}};
  info.outputs = {{"duty_left", "1"}, {"duty_right", "1"}};
  info.details = {{"algorithm", "position PID per wheel (thesis 7.2), gains from --gains"}};
  return info;
}

controller::EncoderInput WheelEncoder(std::size_t channel_index, const char* input,
                                      const io::WheelGeometry& geometry) {
  controller::EncoderInput route;
  route.channel = static_cast<int>(channel_index) + 1;
  route.input = input;
  route.unit = "m";
  route.counts_per_unit = io::CountsPerMetre(geometry);  // what io::CountsToMetres divides by
  return route;
}

controller::PwmOutput WheelMotor(std::size_t channel_index, const char* output) {
  controller::PwmOutput route;
  route.channel = static_cast<int>(channel_index) + 1;
  route.output = output;
  return route;  // gain 1, forward, duty_limit 1
}

}  // namespace

PidController::PidController(const PidGains& gains)
    : gains_(Validated(gains)), info_(PidInfo()), left_(gains_, 1.0), right_(gains_, 1.0) {}

void PidController::Start(double step_s) {
  if (!(step_s > 0.0)) throw controller::ControllerError("the PID needs a step > 0 s");
  left_ = PositionPid(gains_, step_s);
  right_ = PositionPid(gains_, step_s);
}

controller::ControllerStatus PidController::Step(std::span<const double> in,
                                                 std::span<double> out) noexcept {
  out[kDutyLeft] = left_.Step(in[kSetpointLeft], in[kWheelLeft]);
  out[kDutyRight] = right_.Step(in[kSetpointRight], in[kWheelRight]);
  return controller::ControllerStatus::Ok();
}

controller::ControllerMap RelbotControllerMap(const io::WheelGeometry& geometry) {
  controller::ControllerMap map;
  map.source = "the built-in RELbot controller map";
  // Appendix G: channel 2 is the left wheel, channel 1 the right, for encoders and motors.
  map.encoders = {WheelEncoder(kLeftChannel, "wheel_left_m", geometry),
                  WheelEncoder(kRightChannel, "wheel_right_m", geometry)};
  map.setpoints = {{"left_m", "setpoint_left_m", "wheel_left_m", true, 0, 0},
                   {"right_m", "setpoint_right_m", "wheel_right_m", true, 0, 0}};
  map.pwm = {WheelMotor(kLeftChannel, "duty_left"), WheelMotor(kRightChannel, "duty_right")};
  return map;
}

void RegisterPidController() {
  static std::once_flag once;
  std::call_once(once, [] {
    controller::RegisterController(
        {kPidControllerName,
         "the built-in position PID per wheel, thesis 7.2 (--gains)",
         [](const controller::ControllerOptions& o) -> std::unique_ptr<controller::Controller> {
           try {
             const PidGains gains =
                 o.gains_path.empty() ? DefaultEcsGains() : LoadEcsGains(o.gains_path);
             return std::make_unique<PidController>(gains);
           } catch (const ConfigError& e) {
             throw controller::ControllerError(e.what());
           }
         }});
  });
}

}  // namespace hiltwin::app
