// Any controller as the ECS's run task (controller_task.h).
#include "hiltwin/controller/controller_task.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "hiltwin/io/conversions.h"

namespace hiltwin::controller {
namespace {

std::int64_t PositivePeriodNs(std::int64_t period_ns) {
  if (period_ns <= 0) {
    throw std::invalid_argument("the ECS period must be > 0 ns, got " +
                                std::to_string(period_ns) + " ns");
  }
  return period_ns;
}

double TimeS(std::uint64_t cycle, std::int64_t period_ns) noexcept {
  // From the integer nanosecond count, so every time is the exact multiple's nearest double
  // and nothing drifts over a long run.
  return static_cast<double>(static_cast<std::int64_t>(cycle) * period_ns) * 1e-9;
}

/// `value` rounded to the nearest whole count at `counts_per_unit`, through the same division
/// as the encoder input, so an encoder on the setpoint's count has an error of exactly zero.
/// Beyond ±2^62 counts (no robot travels that far) it stays as is.
double OnEncoderGrid(double value, double counts_per_unit) noexcept {
  const double counts = value * counts_per_unit;
  if (!(std::abs(counts) < 4.6e18)) return value;
  return static_cast<double>(std::llround(counts)) / counts_per_unit;
}

/// `value` in its shortest form that reads back to the same double ("0.8").
std::string Shortest(double value) {
  std::array<char, 32> text{};
  const auto end = std::to_chars(text.data(), text.data() + text.size(), value).ptr;
  return {text.data(), end};
}

std::string Describe(const ControllerInfo& info) {
  return "controller '" + info.name + "' (--controller " + info.spec + ")";
}

/// A controller whose step is compiled in runs only at that step (to a part in 10^9: the
/// period is whole nanoseconds).
void CheckFixedStep(const ControllerInfo& info, std::int64_t period_ns) {
  const double step_s = static_cast<double>(period_ns) * 1e-9;
  if (!info.step_is_fixed || std::abs(step_s - info.model_step_s) <= 1e-9 * info.model_step_s) {
    return;
  }
  throw ControllerError(Describe(info) + " runs only at its own step of " +
                        Shortest(info.model_step_s) + " s, but the ECS's period is " +
                        Shortest(step_s) + " s: run the ECS at --rate " +
                        Shortest(1.0 / info.model_step_s) + ", or regenerate the controller "
                        "for this step");
}

}  // namespace

ControllerTask::ControllerTask(io::IcoBoard& board, Controller& controller,
                               BoundControllerMap map, const SetpointColumns& setpoints,
                               std::int64_t period_ns)
    : board_(board),
      controller_(controller),
      map_(std::move(map)),
      setpoints_(setpoints),
      period_ns_(PositivePeriodNs(period_ns)),
      in_(map_.initial_inputs),
      out_(controller.Info().outputs.size(), 0.0),
      duty_(map_.pwm.size(), 0.0) {
  const ControllerInfo& info = controller.Info();
  const std::string who = Describe(info);
  for (const BoundControllerMap::Pwm& route : map_.pwm) {
    const std::string& port = info.outputs[route.output_index].name;
    texts_.push_back(
        {who + " stopped: output '" + port + "' is not finite (NaN or infinite); the motors "
                                             "were stopped",
         who + " stopped: output '" + port + "' asks for a duty beyond its duty_limit " +
             Shortest(route.duty_limit) + "; the motors were stopped"});
  }
  error_status_text_ = who + " stopped: its step returned an error";
  period_text_ = who + ": the session's period differs from the ECS task's (the controller "
                       "was started for the task's)";
  for (std::size_t s = 0; s < map_.setpoints.size(); ++s) {
    if (const auto e = map_.setpoints[s].tracked_encoder) pairs_.push_back({s, *e});
  }
  CheckFixedStep(info, period_ns_);
  controller_.Start(static_cast<double>(period_ns_) * 1e-9);
}

ControllerTask::~ControllerTask() { controller_.Finish(); }

io::ExchangeStatus ControllerTask::Exchange(bool live_outputs) noexcept {
  // One full-duplex frame: the duty of the previous step goes out, the counts at this moment
  // come in (held by the driver on a bad frame). Safe outputs: motors off.
  if (live_outputs) {
    pwm_sent_ = pwm_next_;
  } else {
    pwm_sent_.fill(0);
    ++held_cycles_;  // paused (or stopping): the profile waits, see Step
  }
  const io::ExchangeStatus status = board_.Exchange(pwm_sent_, board_in_);
  if (status.ok()) have_inputs_ = true;
  return status;
}

void ControllerTask::ReadCounts() noexcept {
  // Travel from where the run started: the real robot's encoders power up anywhere, so the
  // first reading is the origin. Until a frame has arrived the counts are no reading at all.
  if (!started_) {
    if (!have_inputs_) return;  // counts_ stay 0
    origin_ = board_in_.absolute_counts;
    started_ = true;
  }
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    counts_[c] = board_in_.absolute_counts[c] - origin_[c];
  }
}

void ControllerTask::FeedInputs() noexcept {
  for (const BoundControllerMap::Encoder& e : map_.encoders) {
    in_[e.input_index] = static_cast<double>(counts_[e.channel_index]) / e.counts_per_unit;
  }
  columns_ = setpoints_.At(time_s_);
  for (const BoundControllerMap::Setpoint& s : map_.setpoints) {
    const double value = columns_[s.column_index];
    // The encoder reads whole counts only, so a setpoint between two of them could never be
    // met and an integrating controller would hunt across the count edge at rest.
    in_[s.input_index] =
        s.on_encoder_grid
            ? OnEncoderGrid(value, map_.encoders[*s.tracked_encoder].counts_per_unit)
            : value;
  }
}

const char* ControllerTask::ComposeErrorStatusText() noexcept {
  // The line a user reads last says why in the controller's own words: "<who> stopped: its
  // step returned an error (<reason>); the motors were stopped", cut to the buffer.
  std::size_t used = 0;
  const auto append = [&](std::string_view text) noexcept {
    const std::size_t room = error_status_buffer_.size() - 1 - used;
    const std::size_t n = std::min(text.size(), room);
    std::memcpy(error_status_buffer_.data() + used, text.data(), n);
    used += n;
  };
  append(error_status_text_);
  if (*fault_reason_ != '\0') {
    append(" (");
    append(fault_reason_);
    append(")");
  }
  append("; the motors were stopped");
  error_status_buffer_[used] = '\0';
  return error_status_buffer_.data();
}

runtime::StepStatus ControllerTask::Stop(ControllerFault::Kind kind, std::size_t route,
                                         double value, const char* reason) noexcept {
  pwm_next_.fill(0);  // safe outputs from the next exchange on
  if (fault_kind_ == ControllerFault::Kind::kNone) {
    fault_kind_ = kind;
    fault_route_ = route;
    fault_value_ = value;
    fault_reason_ = reason != nullptr ? reason : "";
    fault_text_ = kind == ControllerFault::Kind::kErrorStatus ? ComposeErrorStatusText()
                  : kind == ControllerFault::Kind::kNotFinite ? texts_[route].not_finite.c_str()
                                                               : texts_[route].beyond_limit.c_str();
  }
  return runtime::StepStatus::ModelFault(fault_text_);
}

runtime::StepStatus ControllerTask::DriveOutputs() noexcept {
  bool saturated = false;
  for (std::size_t r = 0; r < map_.pwm.size(); ++r) {
    const BoundControllerMap::Pwm& route = map_.pwm[r];
    const double duty = route.gain * out_[route.output_index];
    if (!std::isfinite(duty)) return Stop(ControllerFault::Kind::kNotFinite, r, duty, nullptr);
    if (std::abs(duty) > route.duty_limit) {
      return Stop(ControllerFault::Kind::kBeyondLimit, r, duty, nullptr);
    }
    saturated = saturated || std::abs(duty) >= route.duty_limit;
    duty_[r] = duty;
  }
  pwm_next_.fill(0);
  for (std::size_t r = 0; r < map_.pwm.size(); ++r) {
    pwm_next_[map_.pwm[r].channel_index] = io::DutyToPwm(duty_[r]);
    max_abs_duty_ = std::max(max_abs_duty_, std::abs(duty_[r]));
  }
  if (saturated) ++saturated_cycles_;
  return runtime::StepStatus::Ok();
}

void ControllerTask::Track() noexcept {
  for (PairSums& pair : pairs_) {
    const double setpoint = columns_[map_.setpoints[pair.setpoint].column_index];
    const double error = setpoint - in_[map_.encoders[pair.encoder].input_index];
    ++pair.samples;
    pair.max_abs = std::max(pair.max_abs, std::abs(error));
    pair.sum_sq += error * error;
    pair.final_error = error;
  }
}

runtime::StepStatus ControllerTask::Step(const scheduler::CycleContext& context) noexcept {
  if (context.period_ns != 0 && context.period_ns != period_ns_) {
    return runtime::StepStatus::ModelFault(period_text_.c_str());
  }
  // A stopped controller stays stopped: its state is no longer trusted.
  if (fault_kind_ != ControllerFault::Kind::kNone) {
    pwm_next_.fill(0);
    return runtime::StepStatus::ModelFault(fault_text_);
  }
  // The profile's clock runs only while the controller runs: after a pause the setpoints go on
  // from where they stopped. Skipped releases (skip policy) still count.
  time_s_ = TimeS(context.cycle - held_cycles_, period_ns_);
  ReadCounts();
  FeedInputs();
  Track();
  const ControllerStatus status = controller_.Step(in_, out_);
  if (!status.ok()) {
    fault_cycle_ = context.cycle;
    return Stop(ControllerFault::Kind::kErrorStatus, 0, 0.0, status.reason);
  }
  const runtime::StepStatus driven = DriveOutputs();
  if (driven.code != runtime::StepStatus::Code::kOk) fault_cycle_ = context.cycle;
  return driven;
}

std::vector<std::string> ControllerTask::LogColumns() const {
  std::vector<std::string> columns;
  for (const Port& port : controller_.Info().inputs) columns.push_back(port.name);
  for (const Port& port : controller_.Info().outputs) columns.push_back(port.name);
  return columns;
}

void ControllerTask::FillLogRow(std::span<double> values) const noexcept {
  const std::size_t n_in = std::min(in_.size(), values.size());
  std::copy_n(in_.begin(), n_in, values.begin());
  const std::size_t n_out = std::min(out_.size(), values.size() - n_in);
  std::copy_n(out_.begin(), n_out, values.begin() + static_cast<std::ptrdiff_t>(n_in));
}

std::vector<TrackingPair> ControllerTask::tracking() const {
  const ControllerInfo& info = controller_.Info();
  std::vector<TrackingPair> out;
  for (const PairSums& pair : pairs_) {
    const BoundControllerMap::Setpoint& s = map_.setpoints[pair.setpoint];
    TrackingPair t;
    t.column = s.column_index == 0 ? "left_m" : "right_m";
    t.input = info.inputs[s.input_index].name;
    t.tracked = info.inputs[map_.encoders[pair.encoder].input_index].name;
    t.samples = pair.samples;
    t.max_abs_error = pair.max_abs;
    t.sum_sq_error = pair.sum_sq;
    if (pair.samples > 0) t.rms_error = std::sqrt(pair.sum_sq / static_cast<double>(pair.samples));
    t.final_error = pair.final_error;
    out.push_back(t);
  }
  return out;
}

ControllerFault ControllerTask::fault() const {
  ControllerFault f;
  f.kind = fault_kind_;
  if (fault_kind_ == ControllerFault::Kind::kNone) return f;
  f.cycle = fault_cycle_;
  f.reason = fault_reason_;
  if (fault_kind_ != ControllerFault::Kind::kErrorStatus) {
    const BoundControllerMap::Pwm& route = map_.pwm[fault_route_];
    f.output = controller_.Info().outputs[route.output_index].name;
    f.value = fault_value_;
    f.duty_limit = route.duty_limit;
  }
  return f;
}

}  // namespace hiltwin::controller
