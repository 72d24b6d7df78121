#pragma once
/// The encoder emulator of the twin image (thesis §2.2.1, §4.2.4, Table 4.1) and the quadrature
/// reader of the ECS image, as clock-accurate models. Pure logic, noexcept, allocation-free.
///
/// Pulse spreading: INIT gives the step in 100 MHz clocks and a clock divider D. A period has
/// S = step_clocks / D sub-ticks; N pulses (quadrature counts, one A/B edge each) are spread over
/// them with a division-free accumulator, edge j (1..N) at sub-tick ceil(j·S/N). So at most S
/// counts fit in one period (100 MHz / D counts per second), and never 8192 (half a turn, whose
/// direction is ambiguous): the pulse-rate limit min(S, 8191). A larger change is emitted at the
/// limit, flagged, and the rest follows in the next periods.

#include <cstdint>

#include "hiltwin/io/conversions.h"

namespace hiltwin::io {

/// Smallest divider: edges at least 4 clocks (40 ns) apart, twice what the reader needs.
constexpr std::uint32_t kMinClockDivider = 4;
/// Largest divider and sub-tick count INIT accepts (the gateware's 16-bit counters). The host's
/// ClockDividerForStep stays within them: S <= 16383 and D <= 52428 for any step up to 2^32 ns.
constexpr std::uint32_t kMaxClockDivider = 65535;
constexpr std::uint32_t kMaxSubticksPerStep = 65535;
/// The reader's two-flop synchroniser must see each A/B state for this many clocks.
constexpr std::int64_t kReaderMinStateClocks = 2;
/// Largest change per period the 14-bit relative position can express (half a turn).
constexpr std::uint32_t kMaxRepresentablePulses = 8192;

/// The divider the host sends in INIT: floor(step_clocks / 8192), the largest that still gives
/// at least 8192 sub-ticks per period (so any representable change fits), but never below
/// kMinClockDivider. 0 when the step is shorter than 4 clocks.
[[nodiscard]] std::uint32_t ClockDividerForStep(std::int64_t step_ns) noexcept;
/// Sub-ticks per period S = step_clocks / divider (0 when the divider is 0).
[[nodiscard]] std::uint32_t SubticksPerStep(std::int64_t step_ns, std::uint32_t divider) noexcept;
/// Most pulses one period of S sub-ticks emits: one per sub-tick, and never half a turn (a move
/// of 8192 on the 14-bit wrapping position reads as -8192: its direction is ambiguous), so
/// min(S, 8191). The gateware caps at the same value and raises PULSE_LIMIT.
[[nodiscard]] constexpr std::uint32_t MaxPulsesPerPeriod(std::uint32_t subticks) noexcept {
  return subticks < kMaxRepresentablePulses - 1 ? subticks : kMaxRepresentablePulses - 1;
}
/// Largest position change per period that is emitted within that period:
/// MaxPulsesPerPeriod(SubticksPerStep(step_ns, divider)).
[[nodiscard]] std::uint32_t MaxCountsPerStep(std::int64_t step_ns, std::uint32_t divider) noexcept;

/// Thesis Table 4.1: sign of (new - old) and whether it overflowed the relative range.
enum class DifferenceCase : std::uint8_t {
  kNone,  ///< no change
  kA,     ///< positive, no overflow: direction positive
  kB,     ///< negative, no overflow: direction negative
  kC,     ///< positive with overflow: direction negative
  kD,     ///< negative with overflow: direction positive
};

/// Pulses and direction for one period.
struct PulsePlan {
  std::uint32_t pulses = 0;
  int direction = 0;  ///< +1, -1 or 0
  DifferenceCase difference_case = DifferenceCase::kNone;
};

/// Table 4.1 for relative positions `old_counts`, `new_counts` in [-res/2, res/2).
[[nodiscard]] PulsePlan PlanPulses(std::int32_t old_counts, std::int32_t new_counts,
                                   std::int32_t resolution = kEncoderResolution) noexcept;

/// One period of emitted pulses; enough to tell the position at any time (what an ideal reader
/// counts). Plain data, so the wire backend can publish it through shared memory.
struct PulseSegment {
  std::int32_t start_counts = 0;  ///< relative position when the period began
  std::uint32_t pulses = 0;
  std::int32_t direction = 0;
  std::int64_t start_ns = 0;
  std::uint32_t subticks = 1;  ///< S
  std::uint32_t divider = kMinClockDivider;

  /// Edges emitted by `t_ns` (0 before start, all of them once the period is over).
  [[nodiscard]] std::uint32_t EdgesBy(std::int64_t t_ns) const noexcept;
  /// Relative position at `t_ns`.
  [[nodiscard]] std::int32_t PositionAt(std::int64_t t_ns) const noexcept;
  /// Time of edge j (1-based, j <= pulses).
  [[nodiscard]] std::int64_t EdgeTimeNs(std::uint32_t j) const noexcept;
};

/// One channel of the twin image's encoder emulator.
class EncoderEmulator {
 public:
  /// Applies the INIT parameters; false (and no change) unless step_ns >= 10,
  /// kMinClockDivider <= divider <= kMaxClockDivider and 1 <= S <= kMaxSubticksPerStep with
  /// S = floor(floor(step_ns / 10) / divider) (docs/spi-protocol.md, INIT).
  bool Configure(std::int64_t step_ns, std::uint32_t clock_divider) noexcept;
  /// Position 0, nothing pending.
  void Reset() noexcept;
  /// The sampling moment at `t_ns`: plans the pulses from the position reached so far to
  /// `target_counts` (relative) and spreads them over [t_ns, t_ns + step). Returns false when the
  /// change needs more pulses than MaxPulsesPerPeriod (emitted at the limit, rest carried over):
  /// a change of exactly half a turn (8192) included, whatever S.
  bool StartPeriod(std::int32_t target_counts, std::int64_t t_ns) noexcept {
    // The usual case, inline: the period is over and the target is where it ended. What the
    // plan below gives for it, exactly: a period of no pulses from there (Table 4.1's no change).
    if (!stuck_ && t_ns - segment_.start_ns >= period_ns_ &&
        WrapToRelative(target_counts) == end_counts_) {
      segment_.start_counts = end_counts_;
      segment_.start_ns = t_ns;
      segment_.pulses = 0;
      segment_.direction = 0;
      last_case_ = DifferenceCase::kNone;
      return true;
    }
    return PlanPeriod(target_counts, t_ns);
  }
  /// While stuck, StartPeriod emits nothing (fault injection: a frozen encoder line).
  void SetStuck(bool stuck) noexcept { stuck_ = stuck; }

  [[nodiscard]] std::int32_t PositionAt(std::int64_t t_ns) const noexcept {
    return segment_.PositionAt(t_ns);
  }
  [[nodiscard]] const PulseSegment& segment() const noexcept { return segment_; }
  [[nodiscard]] DifferenceCase last_case() const noexcept { return last_case_; }
  /// Periods whose change exceeded the pulse-rate limit.
  [[nodiscard]] std::uint64_t limit_events() const noexcept { return limit_events_; }
  [[nodiscard]] std::int64_t step_ns() const noexcept { return step_ns_; }

 private:
  /// StartPeriod's general case: Table 4.1 from the position reached at `t_ns`.
  bool PlanPeriod(std::int32_t target_counts, std::int64_t t_ns) noexcept;
  /// The segment's position once its period is over, and the period's length: StartPeriod's
  /// usual case (the sampling moment after the whole period) without EdgesBy.
  [[nodiscard]] std::int32_t ReachedAt(std::int64_t t_ns) const noexcept {
    return t_ns - segment_.start_ns >= period_ns_ ? end_counts_ : segment_.PositionAt(t_ns);
  }

  PulseSegment segment_{};
  std::int32_t end_counts_ = 0;  ///< segment_.PositionAt(any time after the period)
  std::int64_t period_ns_ =      ///< divider · 10 ns · subticks of segment_
      std::int64_t{kMinClockDivider} * kNsPerFpgaClock;
  DifferenceCase last_case_ = DifferenceCase::kNone;
  std::uint64_t limit_events_ = 0;
  std::int64_t step_ns_ = 0;
  bool stuck_ = false;
};

/// A/B levels of the quadrature signal.
struct QuadratureLevels {
  bool a = false;
  bool b = false;
  friend bool operator==(const QuadratureLevels&, const QuadratureLevels&) = default;
};
/// Levels at absolute position `counts`: 00, 10, 11, 01 for counts mod 4 = 0..3 (A leads B
/// when counting up).
[[nodiscard]] QuadratureLevels LevelsAt(std::int64_t counts) noexcept;

/// The ECS image's quadrature reader: 4x decoding of A/B level changes, sampled at 100 MHz.
class QuadratureReader {
 public:
  /// A level change seen at `t_ns`. A jump of two states or a state held for less than
  /// kReaderMinStateClocks is a reader error (a real reader loses or misreads that count).
  void OnLevels(QuadratureLevels levels, std::int64_t t_ns) noexcept;
  /// Starts from `levels` at position `counts` (power-up / reset).
  void Reset(QuadratureLevels levels, std::int64_t counts, std::int64_t t_ns) noexcept;
  /// The lines were loaded or jumped without edges (emulation: power-up, lost history): takes
  /// `levels` as held since long ago and `counts` as the count, keeping the error counters.
  void Resync(QuadratureLevels levels, std::int64_t counts) noexcept;
  [[nodiscard]] std::int64_t counts() const noexcept { return counts_; }
  /// The 14-bit register the ECS reads over SPI.
  [[nodiscard]] std::int32_t relative_counts() const noexcept { return WrapToRelative(counts_); }
  [[nodiscard]] std::uint64_t illegal_transitions() const noexcept { return illegal_; }
  [[nodiscard]] std::uint64_t too_fast() const noexcept { return too_fast_; }

 private:
  QuadratureLevels levels_{};
  std::int64_t counts_ = 0;
  std::int64_t last_change_ns_ = 0;
  std::uint64_t illegal_ = 0;
  std::uint64_t too_fast_ = 0;
};

}  // namespace hiltwin::io
