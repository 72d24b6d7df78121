#include "hiltwin/app_relbot/twin_task.h"

#include <cmath>

#include "hiltwin/app_relbot/relbot_telemetry.h"

namespace hiltwin::app {

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                                   double twin_rate_hz) noexcept
    : profile_(profile),
      controller_rate_hz_(controller_rate_hz),
      twin_rate_hz_(twin_rate_hz),
      twin_period_ns_(static_cast<double>(kernel_glue::PeriodNsFromRateHz(twin_rate_hz))) {}

void ProfilePwmSource::DutyAt(std::int64_t t_ns,
                              std::array<double, io::kChannels>& duty_out) noexcept {
  // Sample-and-hold at the controller's rate: the duty the ECS last wrote, on the frame grid.
  const double frame = t_ns < 0 ? 0.0 : std::round(static_cast<double>(t_ns) / twin_period_ns_);
  const double sample = std::floor(frame * controller_rate_hz_ / twin_rate_hz_);
  const Duty duty = profile_.At(sample / controller_rate_hz_);
  duty_out.fill(0.0);
  duty_out[kLeftChannel] = duty.left;
  duty_out[kRightChannel] = duty.right;
}

TwinTask::TwinTask(io::IcoBoardInverse& board, RelbotModel& model,
                   const io::WheelGeometry& geometry) noexcept
    : board_(board), model_(model), geometry_(geometry) {}

io::ExchangeStatus TwinTask::Exchange(bool live_outputs) noexcept {
  // One full-duplex frame: the positions of the previous step go out, the PWM measured over
  // the last period comes in (the one-period twin delay of thesis §3.7). The driver sends
  // differences against what it sent before, so repeating encoder_sent_ means zero pulses.
  if (live_outputs) encoder_sent_ = encoder_out_;
  return board_.Exchange(encoder_sent_, inputs_);
}

runtime::StepStatus TwinTask::Step(const scheduler::CycleContext& context) noexcept {
  const Duty duty{inputs_.duty[kLeftChannel], inputs_.duty[kRightChannel]};
  model_.Step(duty.left, duty.right);
  if (!model_.StateIsFinite()) {
    return runtime::StepStatus::ModelFault("the model state became non-finite (NaN or Inf)");
  }
  const RelbotOutputs outputs = model_.Outputs();
  encoder_out_[kLeftChannel] =
      static_cast<std::int32_t>(io::MetresToCounts(outputs.wheel_left_m, geometry_));
  encoder_out_[kRightChannel] =
      static_cast<std::int32_t>(io::MetresToCounts(outputs.wheel_right_m, geometry_));
  last_.cycle = context.cycle;
  last_.model_time_s = model_.time_s();
  last_.duty = duty;
  last_.outputs = outputs;
  last_.encoder_counts = encoder_out_;
  return runtime::StepStatus::Ok();
}

runtime::TelemetryShape TwinTask::TelemetryShapeOf() const {
  return RelbotTelemetryShape("twin", true);
}

void TwinTask::FillTelemetry(runtime::TaskTelemetry& out) const noexcept {
  out.has_pose = true;
  out.x_m = last_.outputs.x_m;
  out.y_m = last_.outputs.y_m;
  out.theta_rad = last_.outputs.theta_rad;
  FillWheelJoints(out, last_.outputs.wheel_left_m, last_.outputs.wheel_right_m,
                  geometry_.wheel_radius_m);
}

std::vector<std::string> TwinTask::LogColumns() const {
  return {"duty_left", "duty_right", "wheel_left_m", "wheel_right_m", "x_m",
          "y_m",       "theta_rad",  "enc_left",     "enc_right"};
}

void TwinTask::FillLogRow(std::span<double> values) const noexcept {
  const std::array<double, 9> row = {last_.duty.left,
                                     last_.duty.right,
                                     last_.outputs.wheel_left_m,
                                     last_.outputs.wheel_right_m,
                                     last_.outputs.x_m,
                                     last_.outputs.y_m,
                                     last_.outputs.theta_rad,
                                     static_cast<double>(last_.encoder_counts[kLeftChannel]),
                                     static_cast<double>(last_.encoder_counts[kRightChannel])};
  std::copy_n(row.begin(), std::min(row.size(), values.size()), values.begin());
}

}  // namespace hiltwin::app
