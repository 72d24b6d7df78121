#include "hiltwin/io/encoder_emulator.h"

#include <limits>

namespace hiltwin::io {

std::uint32_t ClockDividerForStep(std::int64_t step_ns) noexcept {
  const std::int64_t step_clocks = step_ns / kNsPerFpgaClock;
  if (step_clocks < kMinClockDivider) return 0;
  const std::int64_t divider = step_clocks / kMaxRepresentablePulses;
  if (divider < kMinClockDivider) return kMinClockDivider;
  if (divider > 0xFFFF'FFFFLL) return 0xFFFF'FFFFU;
  return static_cast<std::uint32_t>(divider);
}

std::uint32_t SubticksPerStep(std::int64_t step_ns, std::uint32_t divider) noexcept {
  if (divider == 0 || step_ns <= 0) return 0;
  const std::int64_t subticks = step_ns / kNsPerFpgaClock / divider;
  return subticks > 0xFFFF'FFFFLL ? 0xFFFF'FFFFU : static_cast<std::uint32_t>(subticks);
}

std::uint32_t MaxCountsPerStep(std::int64_t step_ns, std::uint32_t divider) noexcept {
  return MaxPulsesPerPeriod(SubticksPerStep(step_ns, divider));
}

namespace {
// Table 4.1, inlined into StartPeriod: it runs for every channel of every ALL frame.
inline PulsePlan PlanTable41(std::int32_t old_counts, std::int32_t new_counts,
                             std::int32_t resolution) noexcept {
  const std::int32_t half = resolution / 2;
  const std::int32_t difference = new_counts - old_counts;  // in (-resolution, resolution)
  PulsePlan plan;
  if (difference == 0) return plan;
  // The four situations of thesis Table 4.1, decided at once (no sequential steps).
  if (difference > 0 && difference < half) {
    plan = {static_cast<std::uint32_t>(difference), +1, DifferenceCase::kA};
  } else if (difference < 0 && difference >= -half) {
    plan = {static_cast<std::uint32_t>(-difference), -1, DifferenceCase::kB};
  } else if (difference > 0) {
    plan = {static_cast<std::uint32_t>(resolution - difference), -1, DifferenceCase::kC};
  } else {
    plan = {static_cast<std::uint32_t>(resolution + difference), +1, DifferenceCase::kD};
  }
  return plan;
}
}  // namespace

PulsePlan PlanPulses(std::int32_t old_counts, std::int32_t new_counts,
                     std::int32_t resolution) noexcept {
  return PlanTable41(old_counts, new_counts, resolution);
}

std::uint32_t PulseSegment::EdgesBy(std::int64_t t_ns) const noexcept {
  if (pulses == 0 || t_ns <= start_ns || subticks == 0) return 0;
  const std::int64_t subtick_ns = std::int64_t{divider} * kNsPerFpgaClock;
  // Usual case on the per-cycle path: the period is over. No division needed.
  if (t_ns - start_ns >= subtick_ns * subticks) return pulses;
  const std::int64_t elapsed = (t_ns - start_ns) / subtick_ns;
  if (elapsed >= subticks) return pulses;
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(elapsed) * pulses / subticks);
}

std::int32_t PulseSegment::PositionAt(std::int64_t t_ns) const noexcept {
  const std::int64_t edges = EdgesBy(t_ns);
  return WrapToRelative(std::int64_t{start_counts} + direction * edges);
}

std::int64_t PulseSegment::EdgeTimeNs(std::uint32_t j) const noexcept {
  if (pulses == 0) return start_ns;
  const std::uint64_t numerator = std::uint64_t{j} * subticks;
  const std::uint64_t subtick = (numerator + pulses - 1) / pulses;  // ceil(j·S/N)
  return start_ns + static_cast<std::int64_t>(subtick) * divider * kNsPerFpgaClock;
}

bool EncoderEmulator::Configure(std::int64_t step_ns, std::uint32_t clock_divider) noexcept {
  // The twin image's INIT range: the gateware's divider and sub-tick counters are 16 bits wide.
  if (step_ns < kNsPerFpgaClock || clock_divider < kMinClockDivider ||
      clock_divider > kMaxClockDivider) {
    return false;
  }
  const std::uint32_t subticks = SubticksPerStep(step_ns, clock_divider);
  if (subticks < 1 || subticks > kMaxSubticksPerStep) return false;
  step_ns_ = step_ns;
  segment_.subticks = subticks;
  segment_.divider = clock_divider;
  period_ns_ = std::int64_t{clock_divider} * kNsPerFpgaClock * subticks;
  return true;
}

void EncoderEmulator::Reset() noexcept {
  segment_.start_counts = 0;
  segment_.pulses = 0;
  segment_.direction = 0;
  segment_.start_ns = 0;
  end_counts_ = 0;
  last_case_ = DifferenceCase::kNone;
  limit_events_ = 0;
}

bool EncoderEmulator::PlanPeriod(std::int32_t target_counts, std::int64_t t_ns) noexcept {
  // The position reached so far: the whole previous period normally, part of it when the
  // sampling moment came early (wire backend, wall-clock jitter). Once the period is over,
  // EdgesBy() is all the pulses, so the position is end_counts_ (exact, no arithmetic redone).
  const std::int32_t reached = ReachedAt(t_ns);
  segment_.start_counts = reached;
  segment_.start_ns = t_ns;
  end_counts_ = reached;
  if (stuck_) {
    segment_.pulses = 0;
    segment_.direction = 0;
    return true;
  }
  const PulsePlan plan = PlanTable41(reached, WrapToRelative(target_counts), kEncoderResolution);
  last_case_ = plan.difference_case;
  segment_.direction = plan.direction;
  // At most one edge per sub-tick, and never half a turn: a move of 8192 on the 14-bit wrapping
  // position reads as -8192, so its direction would be a guess (the gateware caps the same way).
  const std::uint32_t most = MaxPulsesPerPeriod(segment_.subticks);
  const bool within = plan.pulses <= most;
  segment_.pulses = within ? plan.pulses : most;
  if (!within) ++limit_events_;
  // PositionAt(start + period) of the segment just set: all its pulses emitted.
  end_counts_ =
      WrapToRelative(std::int64_t{reached} + plan.direction * std::int64_t{segment_.pulses});
  return within;
}

QuadratureLevels LevelsAt(std::int64_t counts) noexcept {
  switch (counts & 3) {
    case 0: return {false, false};
    case 1: return {true, false};
    case 2: return {true, true};
    default: return {false, true};
  }
}

namespace {
int StateIndex(QuadratureLevels levels) noexcept {
  if (!levels.a) return levels.b ? 3 : 0;
  return levels.b ? 2 : 1;
}
}  // namespace

void QuadratureReader::Reset(QuadratureLevels levels, std::int64_t counts,
                             std::int64_t t_ns) noexcept {
  levels_ = levels;
  counts_ = counts;
  last_change_ns_ = t_ns;
  illegal_ = 0;
  too_fast_ = 0;
}

void QuadratureReader::Resync(QuadratureLevels levels, std::int64_t counts) noexcept {
  levels_ = levels;
  counts_ = counts;
  // Held "forever": the next edge cannot count as too fast (no real state change happened).
  last_change_ns_ = std::numeric_limits<std::int64_t>::min() / 2;
}

void QuadratureReader::OnLevels(QuadratureLevels levels, std::int64_t t_ns) noexcept {
  if (levels == levels_) return;
  if (t_ns - last_change_ns_ < kReaderMinStateClocks * kNsPerFpgaClock) ++too_fast_;
  const int step = (StateIndex(levels) - StateIndex(levels_) + 4) % 4;
  if (step == 1) {
    ++counts_;
  } else if (step == 3) {
    --counts_;
  } else {
    ++illegal_;  // both lines changed at once: direction unknown, count lost
  }
  levels_ = levels;
  last_change_ns_ = t_ns;
}

}  // namespace hiltwin::io
