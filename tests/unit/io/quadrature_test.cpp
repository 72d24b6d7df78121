// Quadrature reliability (thesis §5.5, Table 5.2: 720,000 messages sent, 720,000 received, 0
// missed), through the real board path: the twin's driver sends random positions to the twin
// board, whose encoder emulator spreads the pulses over the next period; the ECS board's
// quadrature readers decode those A/B edges at their clock-accurate times and the ECS driver
// reads the counts back. One period later the ECS must hold exactly the position that was sent.
// Run at 1, 4, 8 and 16 kHz on two channels with independent streams; changes include
// wrap-arounds (all four cases of Table 4.1), direction reversals and jumps up to the pulse-rate
// limit. Under the sanitizers the message count is cut tenfold to keep CI fast.
#include <gtest/gtest.h>

#include <array>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "fakes/encoder_change_stream.h"
#include "hiltwin/io/icoboard.h"
#include "board_pair.h"

namespace hiltwin::io {
namespace {

#if defined(HILTWIN_UNDER_SANITIZER)
constexpr int kMessages = 72'000;
#else
constexpr int kMessages = 720'000;
#endif
constexpr std::size_t kRandomChannels = 2;

struct Tally {
  int sent = 0;
  int received_ok = 0;
  std::uint64_t count_errors = 0;
  std::uint64_t edges = 0;  ///< A/B edges the ECS readers decoded
  std::array<int, 5> cases{};
};

using ChangeStream = ::hiltwin::test::EncoderChangeStream;

Tally RunReliability(double rate_hz, std::uint64_t seed) {
  const auto step_ns = static_cast<std::int64_t>(1e9 / rate_hz + 0.5);
  const auto limit = static_cast<std::int64_t>(MaxCountsPerStep(step_ns, ClockDividerForStep(step_ns)));
  // Both boards on one virtual timeline: the k-th ALL frame of each happens at k·step.
  BoardPair boards;
  IcoBoardInverse& twin = boards.twin;
  IcoBoard& ecs = boards.ecs;
  EmulatedFpga& twin_board = boards.twin_board;
  EmulatedFpga& ecs_board = boards.ecs_board;
  EXPECT_TRUE(twin.Init(step_ns).ok);
  EXPECT_TRUE(ecs.Init(step_ns).ok);

  std::array<ChangeStream, kRandomChannels> streams = {ChangeStream(seed, limit),
                                                        ChangeStream(seed + 1, limit)};
  std::array<std::int32_t, kChannels> sent{};      // the twin's absolute positions
  std::array<std::int32_t, kChannels> previous{};  // what the ECS must read one period later
  TwinInputs twin_in;
  EcsInputs ecs_in;
  Tally tally;
  for (int k = 0; k <= kMessages; ++k) {
    if (k < kMessages) {
      for (std::size_t c = 0; c < kRandomChannels; ++c) {
        sent[c] = static_cast<std::int32_t>(sent[c] + streams[c].Next());
      }
      const ExchangeStatus status = twin.Exchange(sent, twin_in);
      if (!status.ok() || status.pulse_limit) ++tally.count_errors;
      ++tally.sent;
      tally.cases[static_cast<std::size_t>(twin_board.encoder(0).last_case())]++;
    }
    // The ECS samples at the same moment: the previous period's pulses are all out.
    if (!ecs.Exchange({0, 0, 0, 0}, ecs_in).ok()) ++tally.count_errors;
    if (k > 0) {
      bool all = true;
      for (std::size_t c = 0; c < kChannels; ++c) {
        all = all && ecs_in.absolute_counts[c] == previous[c] &&
              ecs_in.counts[c] == WrapToRelative(previous[c]);
      }
      if (all) {
        ++tally.received_ok;
      } else {
        ++tally.count_errors;
      }
    }
    previous = sent;
  }
  const EncoderLineCounters reader = ecs_board.encoder_lines().counters();
  tally.count_errors += reader.illegal_transitions + reader.too_fast_edges + reader.resyncs;
  tally.edges = reader.edges;
  return tally;
}

class QuadratureReliability : public ::testing::TestWithParam<double> {};

TEST_P(QuadratureReliability, NoCountErrorsThroughTheBoards) {
  const double rate_hz = GetParam();
  const Tally tally = RunReliability(rate_hz, static_cast<std::uint64_t>(rate_hz));
  EXPECT_EQ(tally.sent, kMessages);
  EXPECT_EQ(tally.received_ok, kMessages);
  EXPECT_EQ(tally.count_errors, 0U);
  EXPECT_GT(tally.edges, 100ULL * static_cast<std::uint64_t>(kMessages));  // the counts came from decoding edges
  // The run really crossed the wrap in both directions and reversed.
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kA)], kMessages / 10);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kB)], kMessages / 10);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kC)], 0);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kD)], 0);
  std::printf("rate %.0f Hz: %d messages sent, %d received correctly, %llu count errors, %llu edges "
              "decoded\n", rate_hz, tally.sent, tally.received_ok,
              static_cast<unsigned long long>(tally.count_errors),
              static_cast<unsigned long long>(tally.edges));
}

INSTANTIATE_TEST_SUITE_P(TableFiveTwo, QuadratureReliability,
                         ::testing::Values(1'000.0, 4'000.0, 8'000.0, 16'000.0),
                         [](const ::testing::TestParamInfo<double>& param_info) {
                           return std::to_string(static_cast<int>(param_info.param / 1000)) + "kHz";
                         });

TEST(QuadratureReliability, ChangesBeyondTheLimitAreReportedNotLost) {
  const std::int64_t step_ns = 62'500;  // 16 kHz
  const std::uint32_t divider = ClockDividerForStep(step_ns);
  const auto limit = static_cast<std::int64_t>(MaxCountsPerStep(step_ns, divider));
  EncoderEmulator emulator;
  ASSERT_TRUE(emulator.Configure(step_ns, divider));
  QuadratureReader reader;
  reader.Reset(LevelsAt(0), 0, 0);
  const std::int64_t target = 3 * limit + 17;  // needs four periods at the limit
  std::int64_t emitted = 0;
  int periods = 0;
  while (reader.counts() != target && periods < 10) {
    emulator.StartPeriod(WrapToRelative(target), periods * step_ns);
    const PulseSegment& s = emulator.segment();
    for (std::uint32_t j = 1; j <= s.pulses; ++j) {
      reader.OnLevels(LevelsAt(emitted + s.direction * std::int64_t{j}), s.EdgeTimeNs(j));
    }
    emitted += s.direction * std::int64_t{s.pulses};
    ++periods;
  }
  EXPECT_EQ(reader.counts(), target);
  EXPECT_EQ(periods, 4);
  EXPECT_EQ(emulator.limit_events(), 3U);
  EXPECT_EQ(reader.illegal_transitions() + reader.too_fast(), 0U);
}

}  // namespace
}  // namespace hiltwin::io
