// The two-board link check behind `hiltwin io-test --io mock`: its encoder pattern exercises
// what it claims (both directions, all four cases of thesis Table 4.1, zero changes, changes of
// exactly the pulse limit and never more), a clean run delivers every message in both
// directions, and each injected fault on the encoder path loses messages where it was injected.
#include "hiltwin/io/board_pair_check.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>

#include "fakes/alloc_counter.h"
#include "hiltwin/io/encoder_emulator.h"

namespace hiltwin::io {
namespace {

struct PatternStats {
  std::array<std::uint64_t, 5> cases{};  ///< Table 4.1 case of each channel's change
  std::uint64_t at_limit_up = 0;
  std::uint64_t at_limit_down = 0;
  std::uint64_t over_limit = 0;
  std::array<std::uint64_t, kChannels> reversals{};
  std::int64_t max_abs_position = 0;
};

PatternStats Walk(std::uint32_t limit, int frames) {
  EncoderTestPattern pattern(limit);
  PatternStats stats;
  std::array<std::int32_t, kChannels> previous{};
  std::array<int, kChannels> last_sign{};
  for (int k = 0; k < frames; ++k) {
    const std::array<std::int32_t, kChannels> now = pattern.Next();
    for (std::size_t c = 0; c < kChannels; ++c) {
      const std::int64_t change = std::int64_t{now[c]} - previous[c];
      if (std::abs(change) > limit) ++stats.over_limit;
      if (change == limit) ++stats.at_limit_up;
      if (change == -static_cast<std::int64_t>(limit)) ++stats.at_limit_down;
      const int sign = change > 0 ? 1 : (change < 0 ? -1 : 0);
      if (sign != 0 && last_sign[c] != 0 && sign != last_sign[c]) ++stats.reversals[c];
      if (sign != 0) last_sign[c] = sign;
      // What the emulator will plan for this change: Table 4.1 on the 14-bit positions.
      ++stats.cases[static_cast<std::size_t>(
          PlanPulses(WrapToRelative(previous[c]), WrapToRelative(now[c])).difference_case)];
      stats.max_abs_position = std::max<std::int64_t>(stats.max_abs_position, std::abs(now[c]));
    }
    previous = now;
  }
  return stats;
}

class EncoderTestPatternAtLimit : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(EncoderTestPatternAtLimit, CoversTableFourOneWithinTheLimit) {
  const std::uint32_t limit = GetParam();
  const PatternStats s = Walk(limit, 4000);
  EXPECT_EQ(s.over_limit, 0U);
  EXPECT_GT(s.at_limit_up, 4U);  // one jump up per channel and cycle
  EXPECT_GT(s.at_limit_down, 4U);
  for (std::size_t kase = 0; kase < s.cases.size(); ++kase) {
    EXPECT_GT(s.cases[kase], 0U) << "Table 4.1 case " << kase << " (0 = no change) never occurs";
  }
  for (std::size_t c = 0; c < kChannels; ++c) EXPECT_GT(s.reversals[c], 2U) << "channel " << c;
  // It stays near its wraps: 3·8192 plus at most one limit.
  EXPECT_LE(s.max_abs_position, 3 * 8192 + static_cast<std::int64_t>(limit));
}

// The limits at 1, 4, 16 and 100 kHz (docs/spi-protocol.md's table; 100 kHz is io-test's
// highest --rate, so 250 is the smallest limit it meets).
INSTANTIATE_TEST_SUITE_P(Rates, EncoderTestPatternAtLimit,
                         ::testing::Values(8191U, 6250U, 1562U, 250U));

TEST(EncoderTestPattern, StartsAtRestAndIsTheSameEveryRun) {
  EncoderTestPattern a(1562);
  EncoderTestPattern b(1562);
  EXPECT_EQ(a.positions(), (std::array<std::int32_t, kChannels>{}));
  for (int k = 0; k < 1000; ++k) ASSERT_EQ(a.Next(), b.Next()) << k;
}

TEST(PwmTestValue, SweepsWhatTheReaderMeasuresExactly) {
  int min = 0;
  int max = 0;
  for (std::int64_t k = 0; k < 4095; ++k) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      const std::int32_t value = PwmTestValue(k, c);
      min = std::min(min, value);
      max = std::max(max, value);
      ASSERT_EQ(PwmReaderValue(PwmToDuty(value)), value) << k << " " << c;
    }
  }
  EXPECT_EQ(min, -2047);
  EXPECT_EQ(max, 2047);
}

/// `steps` data steps at 4 kHz with a TEST after every third, then the ECS's last frame.
const PairTally& RunPair(BoardPairCheck& pair, int steps) {
  EXPECT_TRUE(pair.Init(250'000).ok());
  for (int k = 0; k < steps; ++k) {
    EXPECT_EQ(pair.DataStep().fault(), nullptr);
    if (k % 3 == 2) {
      EXPECT_EQ(pair.TestStep({1, 2, 3, 4, 5, 6, 7, static_cast<std::uint8_t>(k)}).fault(),
                nullptr);
    }
  }
  EXPECT_EQ(pair.Finish().fault(), nullptr);
  return pair.tally();
}

TEST(BoardPairCheck, EveryMessageArrivesBothWays) {
  BoardPairCheck pair;
  const PairTally& t = RunPair(pair, 20'000);
  EXPECT_EQ(t.encoder.sent, 20'000U);
  EXPECT_EQ(t.encoder.received, 20'000U);
  EXPECT_EQ(t.encoder.missed(), 0U);
  EXPECT_EQ(t.encoder.wrong, 0U);
  EXPECT_EQ(t.pwm.sent, 20'000U);
  EXPECT_EQ(t.pwm.received, 20'000U);
  EXPECT_EQ(t.test_echo_errors, 0U);
  EXPECT_EQ(t.first_encoder_miss.frame, -1);
  EXPECT_GT(t.wraps_up, 100U);
  EXPECT_GT(t.wraps_down, 100U);
  // Data frames only in frames_sent: the twin sent 20 000, the ECS one more to read the last.
  EXPECT_EQ(pair.twin().counters().frames_sent, 20'000U);
  EXPECT_EQ(pair.twin().counters().frames_received, 20'000U);
  EXPECT_EQ(pair.ecs().counters().frames_sent, 20'001U);
  EXPECT_EQ(pair.twin().counters().init_frames_sent, 1U);
  EXPECT_EQ(pair.twin().counters().test_frames_received, 6'666U);
  EXPECT_EQ(pair.ecs().counters().test_frames_received, 6'666U);
  EXPECT_EQ(pair.twin().counters().pulse_limit_events, 0U);
  EXPECT_EQ(pair.twin().counters().counts_over_limit, 0U);
  const EncoderLineCounters reader = pair.ecs_board().encoder_lines().counters();
  EXPECT_EQ(reader.illegal_transitions + reader.too_fast_edges + reader.resyncs, 0U);
  EXPECT_GT(reader.edges, 20'000U * 100U);  // the counts came from decoding edges
}

TEST(BoardPairCheck, AStuckEmulatorLosesTheMessagesOfItsPeriods) {
  BoardPairCheck pair;
  pair.Inject({LinkFault::Kind::kStuckEmulator, 1000, 5});
  const PairTally& t = RunPair(pair, 3000);
  // The periods of steps 1000..1004 emit nothing; the next period catches up (the walk is far
  // below the limit), so exactly those five messages are read wrong.
  EXPECT_EQ(t.encoder.missed(), 5U);
  EXPECT_EQ(t.encoder.wrong, 5U);
  EXPECT_EQ(t.first_encoder_miss.frame, 1000);
  EXPECT_NE(t.first_encoder_miss.sent, t.first_encoder_miss.read);
  EXPECT_EQ(t.pwm.missed(), 0U);
}

TEST(BoardPairCheck, AStuckReaderLosesCountsForGood) {
  BoardPairCheck pair;
  pair.Inject({LinkFault::Kind::kStuckReader, 1000, 5});
  const PairTally& t = RunPair(pair, 3000);
  // The ECS frame of step 1000 decodes message 999 without its edges; the readers never get the
  // lost counts back, as a real frozen input would not, so every later message is off too.
  EXPECT_EQ(t.first_encoder_miss.frame, 999);
  EXPECT_EQ(t.encoder.received, 999U);
  EXPECT_EQ(t.encoder.missed(), 3000U - 999U);
  EXPECT_EQ(t.pwm.missed(), 0U);
}

TEST(BoardPairCheck, ACorruptedAnswerMissesOneMessage) {
  BoardPairCheck pair;
  pair.Inject({LinkFault::Kind::kCorruptCounts, 1000, 1});
  const PairTally& t = RunPair(pair, 3000);
  EXPECT_EQ(t.encoder.missed(), 1U);
  EXPECT_EQ(t.encoder.wrong, 0U);  // it did not arrive at all: the driver refused the frame
  EXPECT_EQ(t.first_encoder_miss.frame, 999);
  EXPECT_STREQ(t.first_encoder_miss.reason, "answer failed its CRC-8 check");
  EXPECT_EQ(pair.ecs().counters().frames_corrupted, 1U);
}

TEST(BoardPairCheck, StepsAllocateNothing) {
  BoardPairCheck pair;
  ASSERT_TRUE(pair.Init(250'000).ok());
  pair.Inject({LinkFault::Kind::kCorruptCounts, 500, 10});  // the error paths too
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    for (int k = 0; k < 2000; ++k) {
      (void)pair.DataStep();
      if (k % 3 == 2) (void)pair.TestStep({1, 2, 3, 4, 5, 6, 7, 8});
    }
    (void)pair.Finish();
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U) << "malloc counted: " << test::MallocIsCounted();
  EXPECT_EQ(pair.tally().encoder.missed(), 10U);
}

TEST(BoardPairCheck, TheWrongImageFailsInit) {
  BoardPairCheck pair(Image::kIcoboard, Image::kIcoboard);
  const PairInit init = pair.Init(250'000);
  EXPECT_FALSE(init.ok());
  EXPECT_FALSE(init.twin.ok);
  EXPECT_TRUE(init.ecs.ok);
  EXPECT_EQ(init.twin.message.rfind("Failed to initialise FPGA: found icoboard, the twin needs", 0),
            0U)
      << init.twin.message;
}

}  // namespace
}  // namespace hiltwin::io
