// The RTL's pins against the C++ reference, edge for edge: the twin image's A/B outputs against
// io::EncoderEmulator's PulseSegment (EdgeTimeNs for every edge, LevelsAt for the levels after
// it) through thesis Table 4.1's four cases and at the top speed (N = S with D = 4: an edge every
// 4 clocks); the ECS image's PWM generator high for 2m clocks of every 4096 with its direction.
#include <gtest/gtest.h>

#include <map>

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/fpga_sim/verilated_board.h"
#include "hiltwin/io/encoder_emulator.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

constexpr std::uint32_t kPinsStepNs = 200'000;  // 20,000 clocks: D = 4, S = 5,000

/// Per ALL, the targets of the four channels (relative counts).
const std::vector<std::array<std::int32_t, 4>> kTargets = {
    {3000, -3000, 4000, -4000},     // A, B, A, B
    {1000, -1000, 8000, -8000},     // B, A, A, B
    {-4000, 4000, -8000, 8000},     // B (5000 = S: top speed), A (top speed), D (+384), C (-384)
    {-8000, 8191, -8192, 8191},     // B, A, B, A
    {8000, -8192, 8191, -3193},     // C (-384), C (-1 across the wrap), C (-1), D (+5000: top speed)
    {3000, -3192, 4000, -3191},     // B (top speed), A (top speed), B, A
};

struct ChannelEdge {
  std::int64_t clock;
  bool a;
  bool b;
};

std::array<std::vector<ChannelEdge>, 4> SplitByChannel(const std::vector<OutputEdge>& edges) {
  std::array<std::vector<ChannelEdge>, 4> out;
  std::uint8_t a = 0;
  std::uint8_t b = 0;
  for (const OutputEdge& e : edges) {
    if (e.slot != Slot::kTwin || (e.signal != Signal::kEncA && e.signal != Signal::kEncB)) continue;
    const std::uint8_t before_a = a;
    const std::uint8_t before_b = b;
    (e.signal == Signal::kEncA ? a : b) = e.value;
    for (std::size_t c = 0; c < 4; ++c) {
      if ((((unsigned{before_a} ^ unsigned{a}) | (unsigned{before_b} ^ unsigned{b})) >> c & 1U) != 0) {
        out[c].push_back({static_cast<std::int64_t>(e.clock), (unsigned{a} >> c & 1U) != 0,
                          (unsigned{b} >> c & 1U) != 0});
      }
    }
  }
  return out;
}

TEST(Pins, EncoderEdgesMatchThePulseSegmentsEdgeForEdge) {
  RtlBench bench(true, false, false);
  VerilatedBoardDevice device(bench, io::Image::kIcoboardInverse);
  const std::uint32_t divider = io::ClockDividerForStep(kPinsStepNs);
  ASSERT_EQ(divider, 4U);
  io::FrameBytes miso{};
  std::uint8_t seq = 0;
  device.Exchange(Init(seq++, kPinsStepNs, divider, io::Image::kIcoboardInverse), miso);
  device.Exchange(Noop(seq++), miso);
  std::array<io::EncoderEmulator, 4> model;
  for (auto& m : model) ASSERT_TRUE(m.Configure(kPinsStepNs, divider));
  bench.StartRecording();
  // Expected edges in model time (ns from the origin) and the position after each.
  std::array<std::vector<std::pair<std::int64_t, std::int64_t>>, 4> expected;
  std::array<std::int64_t, 4> position{};
  std::array<int, 5> cases{};
  for (std::size_t k = 0; k <= kTargets.size(); ++k) {
    const std::array<std::int32_t, 4> targets = k < kTargets.size() ? kTargets[k] : kTargets.back();
    device.Exchange(AllTwin(seq++, targets), miso);
    device.Exchange(Noop(seq++), miso);
    ASSERT_EQ(miso[10] & io::kStatusPulseLimit, 0) << "ALL " << k;
    for (std::size_t c = 0; c < 4; ++c) {
      ASSERT_TRUE(model[c].StartPeriod(targets[c], static_cast<std::int64_t>(k) * kPinsStepNs));
      ++cases[static_cast<std::size_t>(model[c].last_case())];
      const io::PulseSegment& s = model[c].segment();
      for (std::uint32_t j = 1; j <= s.pulses; ++j) {
        position[c] += s.direction;
        expected[c].emplace_back(s.EdgeTimeNs(j), position[c]);
      }
    }
  }
  for (const std::size_t kase : {1U, 2U, 3U, 4U}) EXPECT_GT(cases[kase], 1) << "Table 4.1 case " << kase;
  const auto rtl = SplitByChannel(bench.edges());
  const std::int64_t origin_clock = bench.Origin() / kClockPs;
  // The RTL acts on an ALL a fixed latency after its board time (the transfer, the synchroniser).
  const std::int64_t latency = rtl[0].at(0).clock - origin_clock - expected[0].at(0).first / 10;
  EXPECT_GT(latency, 309);  // the 96 bits take 308.8 clocks at 31.25 MHz
  EXPECT_LT(latency, 330);
  std::size_t compared = 0;
  for (std::size_t c = 0; c < 4; ++c) {
    ASSERT_EQ(rtl[c].size(), expected[c].size()) << "channel " << c;
    for (std::size_t i = 0; i < rtl[c].size(); ++i) {
      const io::QuadratureLevels want = io::LevelsAt(expected[c][i].second);
      ASSERT_EQ(rtl[c][i].clock - origin_clock - latency, expected[c][i].first / 10)
          << "channel " << c << " edge " << i;
      ASSERT_EQ(rtl[c][i].a, want.a) << "channel " << c << " edge " << i;
      ASSERT_EQ(rtl[c][i].b, want.b) << "channel " << c << " edge " << i;
      if (i > 0) {
        EXPECT_GE(rtl[c][i].clock - rtl[c][i - 1].clock, 4);
      }
      ++compared;
    }
  }
  std::printf("%zu A/B edges compared, latency %lld clocks after board time\n", compared,
              static_cast<long long>(latency));
}

/// Edges recorded on the twin's channel `c` (either line) since recording started.
std::size_t EdgesOnChannel(const RtlBench& bench, std::size_t c) {
  return SplitByChannel(bench.edges())[c].size();
}

/// The twin's ENC c read-back: where its emulator's current period ends.
std::int32_t EncReadBack(VerilatedBoardDevice& device, std::size_t c, std::uint8_t& seq) {
  io::FrameBytes miso{};
  device.Exchange(Simple(io::EncOpcode(c), seq++, io::Image::kIcoboardInverse), miso);
  device.Exchange(Noop(seq++), miso);
  io::Frame answer;
  EXPECT_EQ(io::Decode(miso, io::Direction::kAnswer, io::Image::kIcoboardInverse, answer),
            io::FrameError::kOk)
      << Hex(miso);
  return answer.enc[c].counts;
}

TEST(Pins, AHalfTurnIsCappedAt8191AndFlaggedEvenWhenThePeriodHoldsIt) {
  // 1 kHz: D = 12, S = 8,333 sub-ticks, room for 8,192 edges; but a move of exactly half the
  // 14-bit range (0 -> -8192) is ambiguous in direction, so the board emits 8,191 with
  // PULSE_LIMIT (spi-protocol.md, "Pulse-rate limit") and the last count in the next period.
  constexpr std::uint32_t kHalfTurnStepNs = 1'000'000;
  RtlBench bench(true, false, false);
  VerilatedBoardDevice device(bench, io::Image::kIcoboardInverse);
  const std::uint32_t divider = io::ClockDividerForStep(kHalfTurnStepNs);
  ASSERT_GE(io::SubticksPerStep(kHalfTurnStepNs, divider), 8192U);
  io::FrameBytes miso{};
  std::uint8_t seq = 0;
  device.Exchange(Init(seq++, kHalfTurnStepNs, divider, io::Image::kIcoboardInverse), miso);
  device.Exchange(Noop(seq++), miso);
  bench.StartRecording();
  device.Exchange(AllTwin(seq++, {-8192, 8191, 0, 0}), miso);
  device.Exchange(Noop(seq++), miso);
  EXPECT_NE(miso[10] & io::kStatusPulseLimit, 0) << "ALL answer " << Hex(miso);
  EXPECT_EQ(EncReadBack(device, 0, seq), -8191);
  EXPECT_EQ(EncReadBack(device, 1, seq), 8191);  // 8191 up fits: no cap
  // The period's edges are all out one step after the ALL.
  bench.RunUntil(bench.now_ps() + std::int64_t{kHalfTurnStepNs} * 1000);
  EXPECT_EQ(EdgesOnChannel(bench, 0), 8191U);
  EXPECT_EQ(EdgesOnChannel(bench, 1), 8191U);
  device.Exchange(AllTwin(seq++, {-8192, 8191, 0, 0}), miso);  // the carried-over count
  device.Exchange(Noop(seq++), miso);
  EXPECT_EQ(miso[10] & io::kStatusPulseLimit, 0) << "ALL answer " << Hex(miso);
  EXPECT_EQ(EncReadBack(device, 0, seq), -8192);
  bench.RunUntil(bench.now_ps() + std::int64_t{kHalfTurnStepNs} * 1000);
  EXPECT_EQ(EdgesOnChannel(bench, 0), 8192U);  // one more, at the end of the period
  EXPECT_EQ(EdgesOnChannel(bench, 1), 8191U);
}

TEST(Pins, PwmGeneratorIsHighFor2mClocksOfEvery4096) {
  RtlBench bench(false, true, false);
  VerilatedBoardDevice device(bench, io::Image::kIcoboard);
  io::FrameBytes miso{};
  std::uint8_t seq = 0;
  device.Exchange(Init(seq++, 1'000'000, 0, io::Image::kIcoboard), miso);
  device.Exchange(Noop(seq++), miso);
  for (const std::array<std::int32_t, 4> values :
       {std::array<std::int32_t, 4>{0, 1, 1023, -2048}, {2047, -1, -700, 512}, {-2047, 2, 0, 2048 - 1}}) {
    device.Exchange(AllEcs(seq++, values), miso);
    device.Exchange(Noop(seq++), miso);
    bench.RunClocks(3 * 4096);  // the generator takes a new value at its counter's wrap
    bench.ClearEdges();
    bench.StartRecording();
    bench.RunClocks(5 * 4096);
    bench.StopRecording();
    for (std::size_t c = 0; c < 4; ++c) {
      const std::int32_t m = values[c] < 0 ? -values[c] : values[c];
      std::vector<std::int64_t> rises;
      std::vector<std::int64_t> falls;
      int previous = -1;  // the channel's level at the last recorded change of the bus
      for (const OutputEdge& e : bench.edges()) {
        if (e.signal != Signal::kPwm) continue;
        const int level = static_cast<int>((unsigned{e.value} >> c) & 1U);
        if (previous >= 0 && level != previous) {
          (level == 1 ? rises : falls).push_back(static_cast<std::int64_t>(e.clock));
        }
        previous = level;
      }
      const bool negative = (unsigned{bench.Output(Slot::kEcs, Signal::kPwmDir)} >> c & 1U) != 0;
      EXPECT_EQ(negative, values[c] < 0 && m != 0) << "channel " << c << " value " << values[c];
      if (m == 0) {
        EXPECT_TRUE(rises.empty()) << "channel " << c;
        EXPECT_EQ(unsigned{bench.Output(Slot::kEcs, Signal::kPwm)} >> c & 1U, 0U);
        continue;
      }
      if (m == 2048) {  // always high
        EXPECT_TRUE(falls.empty()) << "channel " << c;
        EXPECT_EQ(unsigned{bench.Output(Slot::kEcs, Signal::kPwm)} >> c & 1U, 1U);
        continue;
      }
      ASSERT_GE(rises.size(), 4U) << "channel " << c << " value " << values[c] << ", " << bench.edges().size() << " edges, ALL answer " << Hex(miso);
      for (std::size_t i = 1; i < rises.size(); ++i) EXPECT_EQ(rises[i] - rises[i - 1], 4096);
      for (const std::int64_t r : rises) {
        const auto fall = std::lower_bound(falls.begin(), falls.end(), r);
        if (fall == falls.end()) continue;
        EXPECT_EQ(*fall - r, 2 * m) << "channel " << c << " value " << values[c];
      }
    }
  }
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
