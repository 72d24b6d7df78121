// Any plant behind the IcoBoard (plant_twin_task.h).
#include "hiltwin/plant/plant_twin_task.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <iterator>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/encoder_emulator.h"

namespace hiltwin::plant {
namespace {

// Static reasons per board channel: the loop cannot build strings.
#define HILTWIN_ENCODER_REASONS(what)                                                           \
  {                                                                                             \
    "encoder channel 1: " what, "encoder channel 2: " what, "encoder channel 3: " what,        \
        "encoder channel 4: " what                                                              \
  }
constexpr const char* kHalfTurnReasons[] = HILTWIN_ENCODER_REASONS(
    "the plant's output moved by half an encoder turn (8192 counts) or more in one period, "
    "which the board cannot represent: lower the map's counts_per_unit or raise --rate");
constexpr const char* kBeyondReasons[] = HILTWIN_ENCODER_REASONS(
    "the plant's output times counts_per_unit is beyond +-2^62 counts (or not finite), which no "
    "encoder counts: check the map's scale and the plant's output");
#undef HILTWIN_ENCODER_REASONS
static_assert(std::size(kHalfTurnReasons) == io::kChannels &&
              std::size(kBeyondReasons) == io::kChannels);
static_assert(io::kMaxRepresentablePulses == 8192, "the reasons above say 8192");

// std::isfinite of every value, without a test and a branch per value: a double is not finite
// exactly when its exponent is all ones, and then (only then) adding one to the exponent of
// its magnitude carries into the sign bit. One or-reduction over the outputs.
bool AllFinite(std::span<const double> values) noexcept {
  constexpr std::uint64_t kMagnitude = 0x7fff'ffff'ffff'ffffULL;
  constexpr std::uint64_t kExponentOne = std::uint64_t{1} << 52;
  std::uint64_t carries = 0;
  for (const double v : values) {
    carries |= (std::bit_cast<std::uint64_t>(v) & kMagnitude) + kExponentOne;
  }
  return (carries >> 63) == 0;
}

}  // namespace

PlantTwinTask::PlantTwinTask(io::IcoBoardInverse& board, Plant& plant, BoundPlantMap map,
                             double step_s, std::span<const double> initial_outputs)
    : board_(board),
      plant_(plant),
      map_(std::move(map)),
      step_s_(step_s),
      u_(map_.initial_inputs),
      y_(initial_outputs.begin(), initial_outputs.end()) {
  y_.resize(plant_.Info().outputs.size(), 0.0);
  // An incremental encoder counts from 0 at power-up wherever the shaft stands, so the counts
  // are the travel since the plant's initial outputs: a plant that starts at x0 = 0.1 m sends
  // 0 counts in cycle 1, not a burst of pulses that would drive the controller's view there.
  for (const BoundPlantMap::Encoder& e : map_.encoders) {
    counts_origin_[e.channel_index] = io::ValueToCounts(y_[e.output_index], e.counts_per_unit);
  }
}

runtime::StepStatus PlantTwinTask::CountsFromOutputs() noexcept {
  for (const BoundPlantMap::Encoder& e : map_.encoders) {
    const std::size_t c = e.channel_index;
    // Counts the twin cannot hold were clamped (or zeroed) and read as standing still.
    if (!(std::abs(y_[e.output_index] * e.counts_per_unit) < io::kMaxAbsCounts)) {
      return runtime::StepStatus::ModelFault(kBeyondReasons[c]);
    }
    const std::int64_t counts =
        io::ValueToCounts(y_[e.output_index], e.counts_per_unit) - counts_origin_[c];
    // The 14-bit relative position cannot tell a change of half a turn or more from a smaller
    // one the other way (docs/spi-protocol.md, "Pulse-rate limit"): the ECS would misread it.
    const std::int64_t change = counts - counts_[c];
    constexpr auto kHalfTurn = static_cast<std::int64_t>(io::kMaxRepresentablePulses);
    if (change >= kHalfTurn || -change >= kHalfTurn) {
      return runtime::StepStatus::ModelFault(kHalfTurnReasons[c]);
    }
    counts_[c] = counts;
    encoder_out_[c] = static_cast<std::int32_t>(counts);
  }
  return runtime::StepStatus::Ok();
}

io::ExchangeStatus PlantTwinTask::Exchange(bool live_outputs) noexcept {
  // One full-duplex frame: the counts of the previous step go out, the PWM measured over the
  // last period comes in (the one-period twin delay of thesis §3.7). The driver sends
  // differences against what it sent before, so repeating encoder_sent_ means zero pulses.
  if (live_outputs) encoder_sent_ = encoder_out_;
  return board_.Exchange(encoder_sent_, inputs_);
}

runtime::StepStatus PlantTwinTask::Step(const scheduler::CycleContext&) noexcept {
  for (const BoundPlantMap::Pwm& p : map_.pwm) u_[p.input_index] = p.gain * inputs_.duty[p.channel_index];
  const PlantStatus status = plant_.Step(u_, y_);
  if (status.code == PlantStatus::Code::kFault) return runtime::StepStatus::ModelFault(status.reason);
  ++steps_;
  model_time_s_ = static_cast<double>(steps_) * step_s_;
  if (status.code == PlantStatus::Code::kFinished) {
    return {runtime::StepStatus::Code::kFinished, status.reason};
  }
  if (!AllFinite(y_)) [[unlikely]] {
    return runtime::StepStatus::ModelFault("the plant's output became non-finite (NaN or Inf)");
  }
  return CountsFromOutputs();
}

std::vector<std::string> PlantTwinTask::LogColumns() const {
  std::vector<std::string> columns;
  for (const Port& port : plant_.Info().inputs) columns.push_back(port.name);
  for (const Port& port : plant_.Info().outputs) columns.push_back(port.name);
  columns.insert(columns.end(), map_.encoder_columns.begin(), map_.encoder_columns.end());
  return columns;
}

void PlantTwinTask::FillLogRow(std::span<double> values) const noexcept {
  std::size_t i = 0;
  const auto put = [&](double v) {
    if (i < values.size()) values[i++] = v;
  };
  for (const double v : u_) put(v);
  for (const double v : y_) put(v);
  for (const BoundPlantMap::Encoder& e : map_.encoders) {
    put(static_cast<double>(encoder_out_[e.channel_index]));
  }
}

runtime::TelemetryShape PlantTwinTask::TelemetryShapeOf() const {
  return {"twin", map_.pose.has_value(), map_.joint_names};
}

void PlantTwinTask::FillTelemetry(runtime::TaskTelemetry& out) const noexcept {
  out.has_pose = map_.pose.has_value();
  if (map_.pose) {
    out.x_m = y_[(*map_.pose)[0]];
    out.y_m = y_[(*map_.pose)[1]];
    out.theta_rad = y_[(*map_.pose)[2]];
  }
  const std::size_t joints = std::min(map_.joints.size(), out.joint_position_rad.size());
  out.joint_count = static_cast<std::uint8_t>(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const double value = y_[map_.joints[j].output_index];
    out.joint_position_rad[j] = value * map_.joints[j].to_rad;
    out.joint_position_m[j] = value * map_.joints[j].to_m;
  }
}

}  // namespace hiltwin::plant
