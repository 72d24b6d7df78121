// The ECS board's quadrature readers fed by replaying the twin emulator's A/B edges
// (encoder_lines.h): counts come from decoding edges at their times, edges cancelled by an early
// sample are never seen, a frozen input or too-fast edges are miscounted and counted as reader
// errors, and lost history or a restarted twin is a counted resync.
#include "hiltwin/io/encoder_lines.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"
#include "board_pair.h"

namespace hiltwin::io {
namespace {

constexpr std::int64_t kLinesStepNs = 1'000'000;  // 1 kHz twin

using Targets = std::array<std::int32_t, kChannels>;

/// Four emulator channels sampled together, as on the twin board.
class Emulators {
 public:
  explicit Emulators(std::int64_t step_ns = kLinesStepNs) {
    for (auto& e : emulators_) e.Configure(step_ns, ClockDividerForStep(step_ns));
  }
  std::array<PulseSegment, kChannels> Sample(const Targets& targets, std::int64_t t_ns) {
    std::array<PulseSegment, kChannels> segments{};
    for (std::size_t c = 0; c < kChannels; ++c) {
      emulators_[c].StartPeriod(targets[c], t_ns);
      segments[c] = emulators_[c].segment();
    }
    return segments;
  }
  void Reset() {
    for (auto& e : emulators_) e.Reset();
  }

 private:
  std::array<EncoderEmulator, kChannels> emulators_{};
};

/// Lines from a script, with a settable "known until" (a wire twin in the middle of a sample).
class ScriptedLines final : public EncoderLineSource {
 public:
  void Add(const std::array<PulseSegment, kChannels>& channels) {
    periods.push_back(EncoderPeriod{periods.size() + 1, channels});
  }
  LineView Lines(std::int64_t /*t_ns*/) noexcept override { return {periods.size(), known_until}; }
  bool Period(std::uint64_t index, EncoderPeriod& out) noexcept override {
    if (index == 0 || index > periods.size()) return false;
    out = periods[index - 1];
    return true;
  }
  std::vector<EncoderPeriod> periods;
  std::int64_t known_until = std::numeric_limits<std::int64_t>::max();
};

std::uint64_t Errors(const EncoderLineReader& r) {
  const EncoderLineCounters n = r.counters();
  return n.illegal_transitions + n.too_fast_edges + n.resyncs;
}

TEST(EncoderLineReader, CountsAreDecodedEdgesUpToTheReadTime) {
  Emulators twin;
  ScriptedLines lines;
  lines.Add(twin.Sample({0, 0, 0, 0}, 0));  // INIT
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  // The largest change one period emits both ways (-8192 from 0 would be half a turn: capped
  // at 8191, EncoderEmulator.AHalfTurnIsCappedAt8191AndFlaggedWhateverTheSubticks).
  lines.Add(twin.Sample({1000, -1000, 8191, -8191}, kLinesStepNs));
  const PulseSegment& ch0 = lines.periods.back().channels[0];
  for (const std::int64_t t : {kLinesStepNs, kLinesStepNs + 1, kLinesStepNs + 250'000, kLinesStepNs + 777'777, 2 * kLinesStepNs}) {
    reader.Update(lines, t, false);
    const auto edges = static_cast<std::int32_t>(ch0.EdgesBy(t));
    EXPECT_EQ(reader.relative_counts(0), edges) << t;
    EXPECT_EQ(reader.relative_counts(1), -static_cast<std::int32_t>(lines.periods.back().channels[1].EdgesBy(t)));
  }
  EXPECT_EQ(reader.relative_counts(0), 1000);
  EXPECT_EQ(reader.relative_counts(1), -1000);
  EXPECT_EQ(reader.relative_counts(2), 8191);
  EXPECT_EQ(reader.relative_counts(3), -8191);
  EXPECT_EQ(reader.reader(2).counts(), 8191);  // the reader counted every edge, one at a time
  EXPECT_EQ(reader.counters().edges, 1000U + 1000U + 8191U + 8191U);
  EXPECT_EQ(Errors(reader), 0U);
}

TEST(EncoderLineReader, AnEarlySampleCancelsTheRestOfThePeriodWithoutErrors) {
  Emulators twin;
  ScriptedLines lines;
  lines.Add(twin.Sample({0, 0, 0, 0}, 0));
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  lines.Add(twin.Sample({1000, 1000, 1000, 1000}, 0));
  // Wall-clock jitter: the next sample comes half-way; the emulator starts from what it emitted.
  lines.Add(twin.Sample({-500, 3000, 1000, 0}, kLinesStepNs / 2));
  reader.Update(lines, 3 * kLinesStepNs, false);
  EXPECT_EQ(reader.relative_counts(0), -500);
  EXPECT_EQ(reader.relative_counts(1), 3000);
  EXPECT_EQ(reader.relative_counts(2), 1000);
  EXPECT_EQ(reader.relative_counts(3), 0);
  EXPECT_EQ(Errors(reader), 0U);
  // Exactly the edges emitted: period 2 up to the early sample, then all of period 3.
  std::uint64_t emitted = 0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    emitted += lines.periods[1].channels[c].EdgesBy(kLinesStepNs / 2) + lines.periods[2].channels[c].pulses;
  }
  EXPECT_EQ(reader.counters().edges, emitted);
}

TEST(EncoderLineReader, EdgesAfterAWireTwinsSampleInProgressWaitForItsPeriod) {
  Emulators twin;
  ScriptedLines lines;
  lines.Add(twin.Sample({0, 0, 0, 0}, 0));
  lines.Add(twin.Sample({1000, 0, 0, 0}, 0));
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  lines.known_until = 300'000;  // the twin began a sample then; its period is not published yet
  reader.Update(lines, kLinesStepNs, false);
  EXPECT_EQ(reader.relative_counts(0), static_cast<std::int32_t>(lines.periods[1].channels[0].EdgesBy(300'000)));
  lines.Add(twin.Sample({0, 0, 0, 0}, 300'000));  // it turns back at 300 us
  lines.known_until = std::numeric_limits<std::int64_t>::max();
  reader.Update(lines, 2 * kLinesStepNs, false);
  EXPECT_EQ(reader.relative_counts(0), 0);
  EXPECT_EQ(Errors(reader), 0U);
}

TEST(EncoderLineReader, AFrozenInputMiscountsAndCountsAnIllegalTransition) {
  Emulators twin;
  ScriptedLines lines;
  lines.Add(twin.Sample({0, 0, 0, 0}, 0));
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  lines.Add(twin.Sample({6, 0, 0, 0}, 0));
  reader.Update(lines, kLinesStepNs, /*stuck=*/true);  // six edges pass unseen
  EXPECT_EQ(reader.relative_counts(0), 0);
  lines.Add(twin.Sample({7, 0, 0, 0}, kLinesStepNs));
  reader.Update(lines, 2 * kLinesStepNs, false);  // released: 0 -> 7 ≡ 3 (mod 4) reads as one down
  EXPECT_EQ(reader.relative_counts(0), -1);
  lines.Add(twin.Sample({9, 0, 0, 0}, 2 * kLinesStepNs));
  reader.Update(lines, 3 * kLinesStepNs, false);  // legal again: -1 + 2
  EXPECT_EQ(reader.relative_counts(0), 1);
  EXPECT_EQ(reader.counters().illegal_transitions, 0U);

  // Frozen while the lines move one count, released for the next: the reader sees them jump two
  // states (9 -> 11), both lines at once, which no decoder can count.
  lines.Add(twin.Sample({10, 0, 0, 0}, 3 * kLinesStepNs));
  reader.Update(lines, 4 * kLinesStepNs, true);
  lines.Add(twin.Sample({11, 0, 0, 0}, 4 * kLinesStepNs));
  reader.Update(lines, 5 * kLinesStepNs, false);
  EXPECT_EQ(reader.counters().illegal_transitions, 1U);
  EXPECT_EQ(reader.relative_counts(0), 1);  // the two counts are lost
}

TEST(EncoderLineReader, EdgesCloserThanTheSynchroniserAreCountedTooFast) {
  ScriptedLines lines;
  std::array<PulseSegment, kChannels> still{};
  lines.Add(still);
  std::array<PulseSegment, kChannels> fast{};
  fast[0] = PulseSegment{0, 100, +1, 0, 100, 1};  // divider 1: an edge every 10 ns
  lines.Add(fast);
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  reader.Update(lines, kLinesStepNs, false);
  EXPECT_EQ(reader.relative_counts(0), 100);
  EXPECT_EQ(reader.counters().too_fast_edges, 99U);  // every edge but the first
}

TEST(EncoderLineReader, LostHistoryAndATwinRestartAreResyncs) {
  Emulators twin;
  EncoderLineHistory lines;
  lines.OnPeriod(twin.Sample({0, 0, 0, 0}, 0));
  EncoderLineReader reader;
  reader.Update(lines, 0, false);
  EXPECT_EQ(reader.counters().resyncs, 0U);  // loading the lines at INIT is not an error
  // The ECS does not read for more periods than the ring holds.
  std::int32_t position = 0;
  for (std::uint64_t k = 1; k <= kEncoderLineHistory + 10; ++k) {
    position += 10;
    lines.OnPeriod(twin.Sample({position, -position, 0, 0}, static_cast<std::int64_t>(k) * kLinesStepNs));
  }
  reader.Update(lines, static_cast<std::int64_t>(kEncoderLineHistory + 11) * kLinesStepNs, false);
  EXPECT_EQ(reader.counters().resyncs, 1U);
  EXPECT_EQ(reader.relative_counts(0), position);
  EXPECT_EQ(reader.relative_counts(1), -position);
  EXPECT_EQ(reader.reader(0).counts(), position);  // the count moved with the lines

  // The twin re-runs INIT: its emulator starts again from 0.
  twin.Reset();
  const std::int64_t t = static_cast<std::int64_t>(kEncoderLineHistory + 20) * kLinesStepNs;
  lines.OnPeriod(twin.Sample({0, 0, 0, 0}, t));
  lines.OnPeriod(twin.Sample({50, 0, 0, 0}, t + kLinesStepNs));
  reader.Update(lines, t + 2 * kLinesStepNs, false);
  EXPECT_EQ(reader.counters().resyncs, 2U);
  EXPECT_EQ(reader.relative_counts(0), 50);
  EXPECT_EQ(reader.counters().illegal_transitions + reader.counters().too_fast_edges, 0U);
}

TEST(EmulatedFpga, TheEcsBoardReadsTheTwinsPulsesMidPeriod) {
  // Twin at 1 kHz, ECS at 4 kHz on one virtual timeline: the ECS samples the twin's pulses while
  // they are being emitted, through its readers.
  BoardPair boards;
  IcoBoardInverse& twin = boards.twin;
  IcoBoard& ecs = boards.ecs;
  EmulatedFpga& twin_board = boards.twin_board;
  EmulatedFpga& ecs_board = boards.ecs_board;
  ASSERT_TRUE(twin.Init(kLinesStepNs).ok);
  ASSERT_TRUE(ecs.Init(kLinesStepNs / 4).ok);
  TwinInputs twin_in;
  EcsInputs ecs_in;
  ASSERT_TRUE(twin.Exchange({400, -400, 0, 0}, twin_in).ok());  // period [0, 1 ms): 0 -> 400
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(ecs.Exchange({0, 0, 0, 0}, ecs_in).ok());  // at k · 250 us
    const std::int64_t t = k * kLinesStepNs / 4;
    EXPECT_EQ(ecs_in.counts[0], twin_board.encoder(0).PositionAt(t)) << k;
    EXPECT_EQ(ecs_in.counts[1], twin_board.encoder(1).PositionAt(t)) << k;
  }
  EXPECT_EQ(ecs_in.counts[0], 300);  // at 750 us, 3/4 of the way
  EXPECT_EQ(ecs_board.encoder_lines().reader(0).counts(), 300);
  EXPECT_EQ(ecs_board.encoder_lines().counters().edges, 600U);

  // A frozen ECS input (fault hook): the readers miss the next edges; the count is wrong after.
  ecs_board.faults().stick_encoder = true;
  ASSERT_TRUE(twin.Exchange({402, -400, 0, 0}, twin_in).ok());  // at 1 ms: 400 -> 402
  ASSERT_TRUE(ecs.Exchange({0, 0, 0, 0}, ecs_in).ok());          // at 1 ms: edges 301..400 unseen
  ASSERT_TRUE(ecs.Exchange({0, 0, 0, 0}, ecs_in).ok());          // 1.25 ms (next edges at 1.5, 2 ms)
  ecs_board.faults().stick_encoder = false;
  for (int k = 0; k < 6; ++k) ASSERT_TRUE(ecs.Exchange({0, 0, 0, 0}, ecs_in).ok());
  EXPECT_EQ(twin_board.encoder(0).PositionAt(3 * kLinesStepNs), 402);
  EXPECT_EQ(ecs_in.counts[0], 302);   // edges 301..400 were missed; 401 and 402 counted
  EXPECT_EQ(ecs_in.counts[1], -300);  // likewise: the rest of channel 1's pulses came while frozen
}

}  // namespace
}  // namespace hiltwin::io
