#include "hiltwin/relbot/ecs_task.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hiltwin/relbot/ecs_gains.h"
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

const PidGains& CheckedGains(const PidGains& gains) {
  ValidateEcsGains(gains, "ECS gains");
  return gains;
}

double TimeS(std::uint64_t cycle, std::int64_t period_ns) noexcept {
  // From the integer nanosecond count, so every time is the exact multiple's nearest double
  // and nothing drifts over a long run.
  return static_cast<double>(static_cast<std::int64_t>(cycle) * period_ns) * 1e-9;
}

}  // namespace

EcsTask::EcsTask(io::IcoBoard& board, EcsMode mode, const SetpointProfile* setpoints,
                 const InputProfile* duty_profile, const PidGains& gains,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : board_(board),
      mode_(mode),
      setpoints_(setpoints),
      duty_profile_(duty_profile),
      geometry_(geometry),
      counts_per_m_(io::CountsPerMetre(geometry)),
      period_ns_(CheckedPeriodNs(period_ns)),
      pid_left_(CheckedGains(gains), static_cast<double>(period_ns) * 1e-9),
      pid_right_(gains, static_cast<double>(period_ns) * 1e-9) {}

EcsTask::EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints, const PidGains& gains,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : EcsTask(board, EcsMode::kClosedLoop, &setpoints, nullptr, gains, geometry, period_ns) {}

EcsTask::EcsTask(io::IcoBoard& board, const InputProfile& duty_profile,
                 const io::WheelGeometry& geometry, std::int64_t period_ns)
    : EcsTask(board, EcsMode::kOpenLoop, nullptr, &duty_profile, PidGains{}, geometry, period_ns) {}

io::ExchangeStatus EcsTask::Exchange(bool live_outputs) noexcept {
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

double EcsTask::OnEncoderGrid(double metres) const noexcept {
  // Through the same conversion as the measurement, so a wheel on the setpoint's count has an
  // error of exactly zero. Beyond ±2^62 counts (no robot travels that far) it stays as is.
  const double counts = metres * counts_per_m_;
  if (!(std::abs(counts) < 4.6e18)) return metres;
  return io::CountsToMetres(std::llround(counts), geometry_);
}

Duty EcsTask::StepClosedLoop() noexcept {
  const WheelPositions setpoint = setpoints_->At(last_.time_s);
  const WheelPositions& measured = last_.measured;
  // The encoder only ever reads whole counts, so a setpoint between two counts can never be
  // met: the integral would push the wheel back and forth across the count edge for ever
  // (hunting). On the grid, error zero is reachable and the wheel can rest.
  const Duty duty{pid_left_.Step(OnEncoderGrid(setpoint.left_m), measured.left_m),
                  pid_right_.Step(OnEncoderGrid(setpoint.right_m), measured.right_m)};
  last_.setpoint = setpoint;

  const double error_left_m = setpoint.left_m - measured.left_m;
  const double error_right_m = setpoint.right_m - measured.right_m;
  ++sums_.samples;
  sums_.max_abs_left_m = std::max(sums_.max_abs_left_m, std::abs(error_left_m));
  sums_.max_abs_right_m = std::max(sums_.max_abs_right_m, std::abs(error_right_m));
  sums_.sum_sq_left_m2 += error_left_m * error_left_m;
  sums_.sum_sq_right_m2 += error_right_m * error_right_m;
  sums_.final_left_m = error_left_m;
  sums_.final_right_m = error_right_m;
  if (pid_left_.last().saturated || pid_right_.last().saturated) ++sums_.saturated_cycles;
  sums_.max_abs_duty = std::max({sums_.max_abs_duty, std::abs(duty.left), std::abs(duty.right)});
  return duty;
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
  // The profile's clock runs only while the controller runs: after a pause the setpoints go
  // on from where they stopped instead of jumping ahead by the pause. Skipped releases (skip
  // policy) still count, so the profile keeps to the wall clock then.
  const std::uint64_t profile_cycle = context.cycle - held_cycles_;
  last_.cycle = context.cycle;
  last_.time_s = TimeS(profile_cycle, period_ns_);
  last_.duty_sent =
      Duty{io::PwmToDuty(pwm_sent_[kLeftChannel]), io::PwmToDuty(pwm_sent_[kRightChannel])};
  ReadWheels();
  if (mode_ == EcsMode::kClosedLoop) {
    SetNextDuty(StepClosedLoop());
  } else {
    // Sampled at the moment it goes on the wire (the next exchange), so the duty on the wire
    // over [t_j, t_j+1) is the profile at t_j: the signal ProfilePwmSource plays into a twin.
    SetNextDuty(duty_profile_->At(TimeS(profile_cycle + 1, period_ns_)));
  }
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
  stats.samples = sums_.samples;
  stats.max_abs_error_left_m = sums_.max_abs_left_m;
  stats.max_abs_error_right_m = sums_.max_abs_right_m;
  if (sums_.samples > 0) {
    const auto n = static_cast<double>(sums_.samples);
    stats.rms_error_left_m = std::sqrt(sums_.sum_sq_left_m2 / n);
    stats.rms_error_right_m = std::sqrt(sums_.sum_sq_right_m2 / n);
    stats.rms_error_m = std::sqrt((sums_.sum_sq_left_m2 + sums_.sum_sq_right_m2) / (2.0 * n));
  }
  stats.final_error_left_m = sums_.final_left_m;
  stats.final_error_right_m = sums_.final_right_m;
  stats.saturated_cycles = sums_.saturated_cycles;
  stats.max_abs_duty = sums_.max_abs_duty;
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
