#include "hiltwin/relbot/ecs_task.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hiltwin/relbot/pid_controller.h"
#include "hiltwin/relbot/relbot_telemetry.h"

namespace hiltwin::app {
namespace {

constexpr std::size_t kLeft = 0;  // index into EcsCycleRecord::counts and origin_counts_
constexpr std::size_t kRight = 1;

std::int64_t CheckedPeriodNs(std::int64_t period_ns) {
  if (period_ns <= 0) {
    throw std::invalid_argument("the ECS period must be > 0 ns, got " + std::to_string(period_ns) +
                                " ns");
  }
  return period_ns;
}

double TimeS(std::uint64_t cycle, std::int64_t period_ns) noexcept {
  // From the integer nanosecond count, so every time is the exact multiple's nearest double
  // and nothing drifts over a long run.
  return static_cast<double>(static_cast<std::int64_t>(cycle) * period_ns) * 1e-9;
}

}  // namespace

EcsTask::EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints,
                 std::unique_ptr<controller::Controller> owned, const io::WheelGeometry& geometry,
                 std::int64_t period_ns)
    : EcsTask(board, setpoints, *owned,
              controller::BindControllerMap(RelbotControllerMap(geometry), *owned), geometry,
              period_ns) {
  owned_controller_ = std::move(owned);
}

EcsTask::EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints, const PidGains& gains,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : EcsTask(board, setpoints, std::make_unique<PidController>(gains), geometry, period_ns) {}

EcsTask::EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints,
                 controller::Controller& controller, controller::BoundControllerMap map,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : board_(board),
      mode_(EcsMode::kClosedLoop),
      setpoints_(&setpoints),
      duty_profile_(nullptr),
      geometry_(geometry),
      period_ns_(CheckedPeriodNs(period_ns)) {
  columns_.emplace(setpoints);
  loop_.emplace(board, controller, std::move(map), *columns_, period_ns);
  pid_ = dynamic_cast<const PidController*>(&controller);
}

EcsTask::EcsTask(io::IcoBoard& board, const InputProfile& duty_profile,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : board_(board),
      mode_(EcsMode::kOpenLoop),
      setpoints_(nullptr),
      duty_profile_(&duty_profile),
      geometry_(geometry),
      period_ns_(CheckedPeriodNs(period_ns)) {}

std::array<double, 2> EcsTask::ProfileColumns::At(double time_s) const noexcept {
  const WheelPositions setpoint = profile_.At(time_s);
  return {setpoint.left_m, setpoint.right_m};
}

const io::EcsInputs& EcsTask::inputs() const noexcept {
  return loop_ ? loop_->board_inputs() : inputs_;
}

io::ExchangeStatus EcsTask::Exchange(bool live_outputs) noexcept {
  if (loop_) return loop_->Exchange(live_outputs);
  // One full-duplex frame: the duty of the previous step goes out, the counts at this
  // moment come in (held by the driver on a bad frame). Safe outputs: motors off.
  if (live_outputs) {
    pwm_sent_ = pwm_next_;
  } else {
    pwm_sent_.fill(0);
    ++held_cycles_;  // paused (or stopping): the profile waits, see Step
  }
  const io::ExchangeStatus status = board_.Exchange(pwm_sent_, inputs_);
  if (status.ok()) have_inputs_ = true;
  return status;
}

void EcsTask::ReadWheels() noexcept {
  const std::int64_t left = inputs_.absolute_counts[kLeftChannel];
  const std::int64_t right = inputs_.absolute_counts[kRightChannel];
  // Setpoints are travel from where the run started: the real robot's encoders power up
  // anywhere, so the first reading is the origin. Until a frame has arrived the counts are
  // not a reading at all, so they cannot be the origin either.
  if (!started_) {
    if (!have_inputs_) {
      last_.counts = {0, 0};
      last_.measured = WheelPositions{};
      return;
    }
    origin_counts_ = {left, right};
    started_ = true;
  }
  last_.counts = {left - origin_counts_[kLeft], right - origin_counts_[kRight]};
  last_.measured = WheelPositions{io::CountsToMetres(last_.counts[kLeft], geometry_),
                                  io::CountsToMetres(last_.counts[kRight], geometry_)};
}

void EcsTask::RecordClosedLoop() noexcept {
  const std::array<std::int32_t, io::kChannels>& sent = loop_->pwm_sent();
  const std::array<std::int32_t, io::kChannels>& next = loop_->pwm_next();
  const std::array<std::int64_t, io::kChannels>& counts = loop_->counts();
  last_.time_s = loop_->time_s();
  last_.duty_sent = Duty{io::PwmToDuty(sent[kLeftChannel]), io::PwmToDuty(sent[kRightChannel])};
  last_.duty_next = Duty{io::PwmToDuty(next[kLeftChannel]), io::PwmToDuty(next[kRightChannel])};
  last_.counts = {counts[kLeftChannel], counts[kRightChannel]};
  last_.measured = WheelPositions{io::CountsToMetres(last_.counts[kLeft], geometry_),
                                  io::CountsToMetres(last_.counts[kRight], geometry_)};
  const std::array<double, 2>& setpoint = loop_->setpoint_columns();
  last_.setpoint = WheelPositions{setpoint[0], setpoint[1]};
}

void EcsTask::SetNextDuty(const Duty& duty) noexcept {
  pwm_next_.fill(0);
  pwm_next_[kLeftChannel] = io::DutyToPwm(duty.left);
  pwm_next_[kRightChannel] = io::DutyToPwm(duty.right);
  last_.duty_next =
      Duty{io::PwmToDuty(pwm_next_[kLeftChannel]), io::PwmToDuty(pwm_next_[kRightChannel])};
}

runtime::StepStatus EcsTask::Step(const scheduler::CycleContext& context) noexcept {
  if (context.period_ns != 0 && context.period_ns != period_ns_) {
    return runtime::StepStatus::ModelFault(
        "the session's period differs from the ECS task's period (the PID was discretised "
        "for the task's)");
  }
  last_.cycle = context.cycle;
  if (loop_) {
    const runtime::StepStatus status = loop_->Step(context);
    RecordClosedLoop();
    if (pid_ != nullptr && status.code == runtime::StepStatus::Code::kOk &&
        (pid_->left().last().saturated || pid_->right().last().saturated)) {
      ++pid_saturated_cycles_;
    }
    return status;
  }
  // The profile's clock runs only while the task runs: after a pause the duties go on from
  // where they stopped instead of jumping ahead by the pause. Skipped releases (skip policy)
  // still count, so the profile keeps to the wall clock then.
  const std::uint64_t profile_cycle = context.cycle - held_cycles_;
  last_.time_s = TimeS(profile_cycle, period_ns_);
  last_.duty_sent =
      Duty{io::PwmToDuty(pwm_sent_[kLeftChannel]), io::PwmToDuty(pwm_sent_[kRightChannel])};
  ReadWheels();
  // Sampled at the moment it goes on the wire (the next exchange), so the duty on the wire
  // over [t_j, t_j+1) is the profile at t_j: the signal ProfilePwmSource plays into a twin.
  SetNextDuty(duty_profile_->At(TimeS(profile_cycle + 1, period_ns_)));
  return runtime::StepStatus::Ok();
}

std::vector<std::string> EcsTask::LogColumns() const {
  if (mode_ == EcsMode::kOpenLoop) {
    return {"duty_left", "duty_right", "wheel_left_m", "wheel_right_m", "enc_left", "enc_right"};
  }
  return {"setpoint_left_m", "setpoint_right_m", "wheel_left_m", "wheel_right_m", "error_left_m",
          "error_right_m",   "duty_left",        "duty_right",   "enc_left",      "enc_right"};
}

void EcsTask::FillLogRow(std::span<double> values) const noexcept {
  const auto enc_left = static_cast<double>(last_.counts[kLeft]);
  const auto enc_right = static_cast<double>(last_.counts[kRight]);
  if (mode_ == EcsMode::kOpenLoop) {
    const std::array<double, 6> row = {last_.duty_sent.left,
                                       last_.duty_sent.right,
                                       last_.measured.left_m,
                                       last_.measured.right_m,
                                       enc_left,
                                       enc_right};
    std::copy_n(row.begin(), std::min(row.size(), values.size()), values.begin());
    return;
  }
  const std::array<double, 10> row = {last_.setpoint.left_m,
                                      last_.setpoint.right_m,
                                      last_.measured.left_m,
                                      last_.measured.right_m,
                                      last_.setpoint.left_m - last_.measured.left_m,
                                      last_.setpoint.right_m - last_.measured.right_m,
                                      last_.duty_sent.left,
                                      last_.duty_sent.right,
                                      enc_left,
                                      enc_right};
  std::copy_n(row.begin(), std::min(row.size(), values.size()), values.begin());
}

double EcsTask::length_s() const noexcept {
  return mode_ == EcsMode::kClosedLoop ? setpoints_->length_s() : duty_profile_->period_s();
}

TrackingStats EcsTask::tracking() const noexcept {
  TrackingStats stats;
  if (!loop_) return stats;
  // The left_m and right_m pairs of the controller map (the RELbot's: each wheel's setpoint
  // against its encoder); a map without one leaves that wheel's figures at zero.
  double sum_sq_m2 = 0.0;
  for (const controller::TrackingPair& pair : loop_->tracking()) {
    const bool left = pair.column == "left_m";
    (left ? stats.max_abs_error_left_m : stats.max_abs_error_right_m) = pair.max_abs_error;
    (left ? stats.rms_error_left_m : stats.rms_error_right_m) = pair.rms_error;
    (left ? stats.final_error_left_m : stats.final_error_right_m) = pair.final_error;
    stats.samples = pair.samples;
    sum_sq_m2 += pair.sum_sq_error;
  }
  if (stats.samples > 0) {
    stats.rms_error_m = std::sqrt(sum_sq_m2 / (2.0 * static_cast<double>(stats.samples)));
  }
  stats.saturated_cycles = pid_ != nullptr ? pid_saturated_cycles_ : loop_->saturated_cycles();
  stats.max_abs_duty = loop_->max_abs_duty();
  return stats;
}

}  // namespace hiltwin::app

namespace hiltwin::app {

runtime::TelemetryShape EcsTask::TelemetryShapeOf() const {
  return RelbotTelemetryShape("controller", false);
}

void EcsTask::FillTelemetry(runtime::TaskTelemetry& out) const noexcept {
  FillWheelJoints(out, last_.measured.left_m, last_.measured.right_m, geometry_.wheel_radius_m);
  // The profile's setpoint, as logged (not the PID's value on the encoder grid).
  if (mode_ == EcsMode::kClosedLoop) {
    FillWheelSetpoint(out, last_.setpoint.left_m, last_.setpoint.right_m);
  }
}

}  // namespace hiltwin::app
