#include "hiltwin/app_relbot/twin_task.h"

#include <cmath>

#include "hiltwin/tracing/trace.h"

namespace hiltwin::app {

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz) noexcept
    : profile_(profile),
      controller_period_ns_(kernel_glue::PeriodNsFromRateHz(controller_rate_hz)) {}

void ProfilePwmSource::DutyAt(std::int64_t t_ns,
                              std::array<double, io::kChannels>& duty_out) noexcept {
  // Sample-and-hold at the controller's period: the duty the ECS last wrote.
  const std::int64_t held_ns = t_ns < 0 ? 0 : t_ns - t_ns % controller_period_ns_;
  const Duty duty = profile_.At(static_cast<double>(held_ns) * 1e-9);
  duty_out.fill(0.0);
  duty_out[kLeftChannel] = duty.left;
  duty_out[kRightChannel] = duty.right;
}

TwinTask::TwinTask(io::IcoBoardInverse& board, RelbotModel& model,
                   const io::WheelGeometry& geometry, kernel_glue::Clock& clock,
                   const OverrunInjector& injector, statemachine::Lifecycle& lifecycle) noexcept
    : board_(board),
      model_(model),
      geometry_(geometry),
      clock_(clock),
      injector_(injector),
      lifecycle_(lifecycle) {}

scheduler::CycleAction TwinTask::Step(const scheduler::CycleContext& context) noexcept {
  // One full-duplex frame: the positions of the previous step go out, the PWM measured over
  // the last period comes in (the one-period twin delay of thesis §3.7).
  const io::ExchangeStatus status = board_.Exchange(encoder_out_, inputs_);
  last_.io_status = status.code;
  if (status.code == io::ExchangeStatus::Code::kFault) {
    fault_reason_ = status.reason;
    fault_cycle_ = context.cycle;
    lifecycle_.Handle(statemachine::Event::kIoFault);
    return scheduler::CycleAction::kStop;
  }
  if (!status.ok()) ++io_errors_;  // inputs_ untouched: the previous duty holds
  if (status.peer_absent) ++controller_absent_cycles_;

  const kernel_glue::TimeNs extra_ns = injector_.ExtraNs(context.cycle);
  if (extra_ns > 0) clock_.SpendNs(extra_ns);

  const Duty duty{inputs_.duty[kLeftChannel], inputs_.duty[kRightChannel]};
  model_.Step(duty.left, duty.right);
  if (!model_.StateIsFinite()) {
    fault_reason_ = "the model state became non-finite (NaN or Inf)";
    fault_cycle_ = context.cycle;
    lifecycle_.Handle(statemachine::Event::kModelFault);
    return scheduler::CycleAction::kStop;
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
  return scheduler::CycleAction::kContinue;
}

io::ExchangeStatus TwinTask::HoldOutputs() noexcept {
  // The driver sends differences against what it sent before: repeating the last positions
  // means zero pulses over the next period.
  io::TwinInputs ignored{};
  return board_.Exchange(encoder_out_, ignored);
}

scheduler::CycleAction QosObserver::OnCycle(const scheduler::TimingSample& sample) noexcept {
  HILTWIN_TRACE(cycle, sample.cycle, sample.release_ns, sample.wake_ns, sample.start_ns,
                sample.end_ns, sample.releases_skipped, static_cast<std::uint8_t>(sample.missed));
  bool stop = monitor_.Record(sample.cycle, sample.missed);
  for (std::uint32_t i = 1; i <= sample.releases_skipped; ++i) {
    stop = monitor_.Record(sample.cycle + i, true) || stop;
  }
  const qos::LiveQos live = monitor_.Live();
  HILTWIN_TRACE(qos, sample.cycle, static_cast<std::int64_t>(live.distance_to_failure),
                static_cast<std::uint8_t>(live.verdict));
  return stop ? scheduler::CycleAction::kStop : scheduler::CycleAction::kContinue;
}

const std::vector<std::string>& LogObserver::Columns() {
  static const std::vector<std::string> columns = {
      "duty_left",   "duty_right", "wheel_left_m", "wheel_right_m", "x_m",
      "y_m",         "theta_rad",  "enc_left",     "enc_right",     "cycle",
      "latency_us",  "compute_us", "missed"};
  return columns;
}

scheduler::CycleAction LogObserver::OnCycle(const scheduler::TimingSample& sample) noexcept {
  const TwinCycleRecord& r = task_.last();
  if (r.cycle != sample.cycle) return scheduler::CycleAction::kContinue;  // a faulted step
  const std::array<double, 13> row = {
      r.duty.left,
      r.duty.right,
      r.outputs.wheel_left_m,
      r.outputs.wheel_right_m,
      r.outputs.x_m,
      r.outputs.y_m,
      r.outputs.theta_rad,
      static_cast<double>(r.encoder_counts[kLeftChannel]),
      static_cast<double>(r.encoder_counts[kRightChannel]),
      static_cast<double>(sample.cycle),  // release index: model time lags it under skip
      static_cast<double>(sample.wake_ns - sample.release_ns) * 1e-3,
      static_cast<double>(sample.end_ns - sample.start_ns) * 1e-3,
      sample.missed ? 1.0 : 0.0};
  logger_.TryLog(r.model_time_s, row);
  return scheduler::CycleAction::kContinue;
}

}  // namespace hiltwin::app
