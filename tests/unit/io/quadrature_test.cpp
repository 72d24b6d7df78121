// Quadrature reliability (thesis §5.5, Table 5.2: 720,000 messages sent, 720,000 received, 0
// missed): the twin image's encoder emulator turns random position changes into A/B edges at
// their clock-accurate times; the ECS image's reader decodes them. After every period the reader
// must hold exactly the position that was sent. Run at 1, 4, 8 and 16 kHz; changes include
// wrap-arounds (all four cases of Table 4.1), direction reversals and jumps up to the pulse-rate
// limit. Under the sanitizers the message count is cut tenfold to keep CI fast.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "hiltwin/io/encoder_emulator.h"

namespace hiltwin::io {
namespace {

#if defined(HILTWIN_UNDER_SANITIZER)
constexpr int kMessages = 72'000;
#else
constexpr int kMessages = 720'000;
#endif

struct Tally {
  int sent = 0;
  int received_ok = 0;
  std::uint64_t count_errors = 0;
  std::array<int, 5> cases{};
};

Tally RunReliability(double rate_hz, std::uint64_t seed) {
  const auto step_ns = static_cast<std::int64_t>(1e9 / rate_hz + 0.5);
  const std::uint32_t divider = ClockDividerForStep(step_ns);
  const auto limit = static_cast<std::int64_t>(MaxCountsPerStep(step_ns, divider));
  EncoderEmulator emulator;
  EXPECT_TRUE(emulator.Configure(step_ns, divider));
  QuadratureReader reader;
  reader.Reset(LevelsAt(0), 0, 0);

  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> small(-100, 100);
  std::uniform_int_distribution<std::int64_t> large(-limit, limit);
  std::uniform_int_distribution<int> kind(0, 99);
  Tally tally;
  std::int64_t sent_absolute = 0;     // the twin's absolute position
  std::int64_t emitted_absolute = 0;  // the emulator's lines, unwrapped
  std::int64_t previous_change = 0;
  for (int k = 0; k < kMessages; ++k) {
    const std::int64_t t_ns = k * step_ns;
    const int roll = kind(rng);
    std::int64_t change = 0;
    if (roll < 94) {
      change = small(rng);
    } else if (roll < 99) {
      change = large(rng) / 4;
    } else {
      change = large(rng);
    }
    if (roll % 10 == 0) change = -previous_change;  // a hard direction reversal
    previous_change = change;
    sent_absolute += change;
    ++tally.sent;

    if (!emulator.StartPeriod(WrapToRelative(sent_absolute), t_ns)) ++tally.count_errors;
    tally.cases[static_cast<std::size_t>(emulator.last_case())]++;
    const PulseSegment& s = emulator.segment();
    for (std::uint32_t j = 1; j <= s.pulses; ++j) {
      const std::int64_t edge_ns = s.EdgeTimeNs(j);
      if (edge_ns > t_ns + step_ns) ++tally.count_errors;  // pulses must fit in the period
      reader.OnLevels(LevelsAt(emitted_absolute + s.direction * std::int64_t{j}), edge_ns);
    }
    emitted_absolute += s.direction * std::int64_t{s.pulses};
    if (reader.counts() == sent_absolute && reader.relative_counts() == WrapToRelative(sent_absolute)) {
      ++tally.received_ok;
    } else {
      ++tally.count_errors;
      reader.Reset(LevelsAt(emitted_absolute), sent_absolute, t_ns + step_ns);  // count each error once
    }
  }
  tally.count_errors += reader.illegal_transitions() + reader.too_fast();
  return tally;
}

class QuadratureReliability : public ::testing::TestWithParam<double> {};

TEST_P(QuadratureReliability, NoCountErrors) {
  const double rate_hz = GetParam();
  const Tally tally = RunReliability(rate_hz, static_cast<std::uint64_t>(rate_hz));
  EXPECT_EQ(tally.sent, kMessages);
  EXPECT_EQ(tally.received_ok, kMessages);
  EXPECT_EQ(tally.count_errors, 0U);
  // The run really crossed the wrap in both directions and reversed.
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kA)], kMessages / 10);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kB)], kMessages / 10);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kC)], 0);
  EXPECT_GT(tally.cases[static_cast<std::size_t>(DifferenceCase::kD)], 0);
  std::printf("rate %.0f Hz: %d messages sent, %d received correctly, %llu count errors\n", rate_hz,
              tally.sent, tally.received_ok, static_cast<unsigned long long>(tally.count_errors));
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
