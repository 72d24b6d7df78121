#include "hiltwin/io/encoder_emulator.h"

#include <gtest/gtest.h>

namespace hiltwin::io {
namespace {

TEST(EncoderEmulator, TableFourOneCases) {
  // A: positive difference, no overflow.
  auto p = PlanPulses(100, 300);
  EXPECT_EQ(p.difference_case, DifferenceCase::kA);
  EXPECT_EQ(p.pulses, 200U);
  EXPECT_EQ(p.direction, +1);
  // B: negative, no overflow.
  p = PlanPulses(300, 100);
  EXPECT_EQ(p.difference_case, DifferenceCase::kB);
  EXPECT_EQ(p.pulses, 200U);
  EXPECT_EQ(p.direction, -1);
  // C: thesis §4.2.4's example, -200 steps that read as +16184: positive with overflow.
  p = PlanPulses(-8100, 8084);
  EXPECT_EQ(p.difference_case, DifferenceCase::kC);
  EXPECT_EQ(p.pulses, 200U);
  EXPECT_EQ(p.direction, -1);
  // D: negative with overflow: +200 across the wrap.
  p = PlanPulses(8100, -8084);
  EXPECT_EQ(p.difference_case, DifferenceCase::kD);
  EXPECT_EQ(p.pulses, 200U);
  EXPECT_EQ(p.direction, +1);
  // No change.
  p = PlanPulses(5, 5);
  EXPECT_EQ(p.difference_case, DifferenceCase::kNone);
  EXPECT_EQ(p.pulses, 0U);
  // Boundaries: 8191 is A, 8192 overflows (reads as -8192, C), -8192 is B, -8193 overflows (D).
  EXPECT_EQ(PlanPulses(-8192, -1).difference_case, DifferenceCase::kA);
  EXPECT_EQ(PlanPulses(-8192, 0).difference_case, DifferenceCase::kC);
  EXPECT_EQ(PlanPulses(0, -8192).difference_case, DifferenceCase::kB);
  EXPECT_EQ(PlanPulses(8191, -2).difference_case, DifferenceCase::kD);
  EXPECT_EQ(PlanPulses(8191, -2).pulses, 16384U - 8193U);
}

TEST(EncoderEmulator, DividerAndLimitPerRate) {
  EXPECT_EQ(ClockDividerForStep(1'000'000), 12U);  // 1 kHz: 100 000 clocks / 8192
  EXPECT_EQ(SubticksPerStep(1'000'000, 12), 8333U);
  EXPECT_EQ(MaxCountsPerStep(1'000'000, 12), 8191U);
  EXPECT_EQ(ClockDividerForStep(250'000), kMinClockDivider);  // 4 kHz
  EXPECT_EQ(MaxCountsPerStep(250'000, 4), 6250U);
  EXPECT_EQ(MaxCountsPerStep(62'500, ClockDividerForStep(62'500)), 1562U);  // 16 kHz
  EXPECT_EQ(ClockDividerForStep(30), 0U);  // 3 clocks: no divider fits
  EXPECT_EQ(SubticksPerStep(1'000, 0), 0U);
}

TEST(EncoderEmulator, PulsesAreSpreadUniformlyOverThePeriod) {
  EncoderEmulator e;
  const std::int64_t step_ns = 1'000'000;
  ASSERT_TRUE(e.Configure(step_ns, ClockDividerForStep(step_ns)));
  ASSERT_TRUE(e.StartPeriod(18, 0));  // thesis §2.2.1's example: 18 pulses in the next 1 ms
  const PulseSegment& s = e.segment();
  EXPECT_EQ(s.pulses, 18U);
  EXPECT_EQ(e.PositionAt(0), 0);
  // Edge 9 of 18 sits at sub-tick ceil(9·8333/18) = 4167, just after the middle (4166.5).
  EXPECT_EQ(e.PositionAt(step_ns / 2), 8);
  EXPECT_EQ(e.PositionAt(4167 * 120), 9);
  EXPECT_EQ(e.PositionAt(step_ns), 18);
  EXPECT_EQ(e.PositionAt(10 * step_ns), 18);
  // Edges evenly spaced: gaps differ by at most one sub-tick, last edge inside the period.
  const std::int64_t subtick_ns = std::int64_t{s.divider} * 10;
  std::int64_t previous = s.start_ns;
  std::int64_t min_gap = step_ns;
  std::int64_t max_gap = 0;
  for (std::uint32_t j = 1; j <= s.pulses; ++j) {
    const std::int64_t t = s.EdgeTimeNs(j);
    EXPECT_EQ(s.EdgesBy(t), j);
    EXPECT_EQ(s.EdgesBy(t - subtick_ns), j - 1);
    min_gap = std::min(min_gap, t - previous);
    max_gap = std::max(max_gap, t - previous);
    previous = t;
  }
  EXPECT_LE(max_gap - min_gap, subtick_ns);
  EXPECT_LE(previous, step_ns);
  EXPECT_EQ(e.last_case(), DifferenceCase::kA);
}

TEST(EncoderEmulator, ChangesAboveTheLimitAreReportedAndCaughtUp) {
  EncoderEmulator e;
  const std::int64_t step_ns = 62'500;  // 16 kHz: 1562 counts per period at most
  const std::uint32_t divider = ClockDividerForStep(step_ns);
  ASSERT_TRUE(e.Configure(step_ns, divider));
  const auto limit = static_cast<std::int32_t>(MaxCountsPerStep(step_ns, divider));
  EXPECT_FALSE(e.StartPeriod(limit + 100, 0));
  EXPECT_EQ(e.limit_events(), 1U);
  EXPECT_EQ(e.PositionAt(step_ns), limit);
  EXPECT_TRUE(e.StartPeriod(limit + 100, step_ns));  // the rest follows in the next period
  EXPECT_EQ(e.PositionAt(2 * step_ns), limit + 100);
  EXPECT_EQ(e.limit_events(), 1U);
}

TEST(EncoderEmulator, AHalfTurnIsCappedAt8191AndFlaggedWhateverTheSubticks) {
  // A move of exactly 8192 on the 14-bit wrapping position cannot be told from -8192: even when
  // the period has sub-ticks for it (S >= 8192), at most 8191 are emitted, the limit is flagged
  // and the last count follows in the next period (as the gateware's encoder_emulator.v does).
  struct Rate {
    std::int64_t step_ns;
    std::uint32_t divider;
  };
  for (const Rate rate : {Rate{1'000'000, 12}, Rate{5'242'800, 8}}) {  // S = 8333, 65535
    EncoderEmulator e;
    ASSERT_TRUE(e.Configure(rate.step_ns, rate.divider));
    ASSERT_GE(e.segment().subticks, 8192U);
    EXPECT_FALSE(e.StartPeriod(-8192, 0)) << rate.divider;  // from 0: 8192 down
    EXPECT_EQ(e.segment().pulses, 8191U) << rate.divider;
    EXPECT_EQ(e.segment().direction, -1);
    EXPECT_EQ(e.limit_events(), 1U);
    EXPECT_EQ(e.PositionAt(rate.step_ns), -8191);
    EXPECT_TRUE(e.StartPeriod(-8192, rate.step_ns));
    EXPECT_EQ(e.PositionAt(2 * rate.step_ns), -8192);
    // Back by +8192 (reads as -8192 again: Table 4.1 case C, down): capped the same way.
    EXPECT_FALSE(e.StartPeriod(0, 2 * rate.step_ns));
    EXPECT_EQ(e.segment().pulses, 8191U);
    EXPECT_EQ(e.limit_events(), 2U);
    // 8191 itself fits in one period.
    EXPECT_TRUE(e.StartPeriod(8191, 3 * rate.step_ns));
    EXPECT_EQ(e.PositionAt(4 * rate.step_ns), 8191);
  }
  EXPECT_EQ(MaxPulsesPerPeriod(65'535), 8191U);
  EXPECT_EQ(MaxPulsesPerPeriod(8192), 8191U);
  EXPECT_EQ(MaxPulsesPerPeriod(6250), 6250U);
}

TEST(EncoderEmulator, StuckEmitsNothingAndEarlySamplingKeepsPartialProgress) {
  EncoderEmulator e;
  ASSERT_TRUE(e.Configure(1'000'000, 12));
  e.SetStuck(true);
  e.StartPeriod(500, 0);
  EXPECT_EQ(e.PositionAt(2'000'000), 0);
  e.SetStuck(false);
  e.StartPeriod(1000, 2'000'000);
  // A sampling moment half-way through the period (wall-clock jitter): start from what was emitted.
  const std::int32_t reached = e.PositionAt(2'500'000);
  EXPECT_NEAR(reached, 500, 1);
  e.StartPeriod(1000, 2'500'000);
  EXPECT_EQ(e.segment().start_counts, reached);
  EXPECT_EQ(e.segment().pulses, static_cast<std::uint32_t>(1000 - reached));
  EXPECT_EQ(e.PositionAt(3'500'000), 1000);
  EXPECT_FALSE(e.Configure(1'000'000, 2));  // below the minimum divider
}

TEST(QuadratureReader, DecodesBothDirectionsAndFlagsErrors) {
  QuadratureReader r;
  r.Reset(LevelsAt(0), 0, 0);
  std::int64_t t = 0;
  for (int i = 1; i <= 10; ++i) r.OnLevels(LevelsAt(i), t += 100);
  EXPECT_EQ(r.counts(), 10);
  for (int i = 9; i >= -5; --i) r.OnLevels(LevelsAt(i), t += 100);
  EXPECT_EQ(r.counts(), -5);
  EXPECT_EQ(r.relative_counts(), -5);
  EXPECT_EQ(r.illegal_transitions(), 0U);
  EXPECT_EQ(r.too_fast(), 0U);
  r.OnLevels(LevelsAt(-3), t += 100);  // two states at once
  EXPECT_EQ(r.illegal_transitions(), 1U);
  r.OnLevels(LevelsAt(-2), t += 10);   // one clock after the previous change
  EXPECT_EQ(r.too_fast(), 1U);
  EXPECT_EQ(LevelsAt(0), (QuadratureLevels{false, false}));
  EXPECT_EQ(LevelsAt(1), (QuadratureLevels{true, false}));  // A leads B counting up
  EXPECT_EQ(LevelsAt(-1), (QuadratureLevels{false, true}));
}

}  // namespace
}  // namespace hiltwin::io
