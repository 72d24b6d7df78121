// Thesis Table 5.2 through the RTL (the 720,000-message test of tests/unit/io/quadrature_test.cpp):
// twin driver -> verilated twin board (encoder emulator) -> A/B wires -> verilated ECS board
// (quadrature decoders) -> ECS driver, on one 100 MHz timeline with SPI at 31.25 MHz. Random
// position changes up to the pulse limit, wrap-arounds in both directions, reversals; one period
// later the ECS must read exactly what was sent, and the wires must never show an edge a real
// reader would miscount.
//
// Timing: one timeline serialises the two boards' transfers, so the ECS cannot sample at the very
// clock the twin takes its next message, as the C++ reference does (there the ECS reads at t_k
// the edges up to t_k, and the next period's edges come strictly after). Instead the twin's INIT
// step is 10 µs (D = 4, S = 250: its pulses take 10 µs at most) and its messages come every
// 20 µs (50 kHz); the ECS samples 11 µs after each message, when the twin's period has ended and
// the lines are quiet. So each message must arrive exactly, in the same cycle. The full run is
// 720,000 messages (14.4 s of board time); the default suite runs a tenth of it.
#include <gtest/gtest.h>

#include <chrono>

#include "hiltwin/io/encoder_emulator.h"
#include "fakes/encoder_change_stream.h"
#include "hiltwin/io/icoboard.h"
#include "rtl_pair.h"

#ifndef HILTWIN_RTL_MESSAGES
#define HILTWIN_RTL_MESSAGES 72'000
#define HILTWIN_RTL_SUITE RtlQuadrature
#endif

namespace hiltwin::fpga_sim::test {
namespace {

#if defined(HILTWIN_UNDER_SANITIZER)
constexpr int kMessages = HILTWIN_RTL_MESSAGES / 10;  // the verilated boards are instrumented too
#else
constexpr int kMessages = HILTWIN_RTL_MESSAGES;
#endif
constexpr double kRateHz = 50'000.0;          // messages
constexpr std::int64_t kTwinStepNs = 10'000;    // INIT step: the emulator's period
constexpr std::int64_t kEcsSampleAfterNs = 11'000;
constexpr std::size_t kRandomChannels = 4;

using ChangeStream = ::hiltwin::test::EncoderChangeStream;

TEST(HILTWIN_RTL_SUITE, NoCountErrorsThroughTheRtlBoards) {
  const auto step_ns = static_cast<std::int64_t>(1e9 / kRateHz + 0.5);
  const auto limit = static_cast<std::int64_t>(
      io::MaxCountsPerStep(kTwinStepNs, io::ClockDividerForStep(kTwinStepNs)));
  ASSERT_EQ(limit, 250);
  DeviceTiming twin_timing;
  twin_timing.all_interval_ns = step_ns;
  DeviceTiming ecs_timing;
  ecs_timing.phase_ns = kEcsSampleAfterNs;
  RtlBoardPair boards(twin_timing, ecs_timing);
  io::IcoBoardInverse twin(boards.twin_bus);
  io::IcoBoard ecs(boards.ecs_bus);
  ASSERT_TRUE(twin.Init(kTwinStepNs).ok);
  ASSERT_TRUE(ecs.Init(step_ns).ok);
  std::vector<ChangeStream> streams;
  for (std::size_t c = 0; c < kRandomChannels; ++c) streams.emplace_back(1000 + c, limit);
  std::array<std::int32_t, io::kChannels> sent{};
  io::TwinInputs twin_in;
  io::EcsInputs ecs_in;
  int received_ok = 0;
  std::uint64_t count_errors = 0;
  std::uint64_t wraps = 0;
  std::string first_error;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < kMessages; ++k) {
    for (std::size_t c = 0; c < kRandomChannels; ++c) {
      const std::int32_t before = io::WrapToRelative(sent[c]);
      sent[c] = static_cast<std::int32_t>(sent[c] + streams[c].Next());
      const std::int32_t after = io::WrapToRelative(sent[c]);
      if ((before > 4096 && after < -4096) || (before < -4096 && after > 4096)) ++wraps;
    }
    const io::ExchangeStatus twin_status = twin.Exchange(sent, twin_in);
    if (!twin_status.ok() || twin_status.pulse_limit) ++count_errors;
    const io::ExchangeStatus status = ecs.Exchange({0, 0, 0, 0}, ecs_in);
    if (!status.ok()) ++count_errors;
    bool all = status.ok();
    for (std::size_t c = 0; c < io::kChannels; ++c) {
      all = all && ecs_in.absolute_counts[c] == sent[c] &&
            ecs_in.counts[c] == io::WrapToRelative(sent[c]);
    }
    if (all) {
      ++received_ok;
    } else if (++count_errors == 1) {
      first_error = "message " + std::to_string(k) + ": sent " + std::to_string(sent[0]) +
                    " read " + std::to_string(ecs_in.absolute_counts[0]);
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const WireCounters& wires = boards.bench.wire_counters();
  EXPECT_EQ(received_ok, kMessages) << first_error;
  EXPECT_EQ(count_errors, 0U) << first_error;
  EXPECT_EQ(wires.illegal_transitions, 0U);
  EXPECT_EQ(wires.too_fast, 0U);
  EXPECT_GT(wires.edges, 100ULL * static_cast<std::uint64_t>(kMessages));
  EXPECT_GT(wraps, 0U);
  EXPECT_LE(boards.twin_board.max_late_ns(), 0);
  EXPECT_LE(boards.ecs_board.max_late_ns(), 0);
  std::printf("%d messages at %.0f Hz: %d received correctly, %llu count errors, %llu A/B edges, "
              "%llu wraps; %.3f s board time in %.1f s (%.1f M clocks/s, two boards)\n",
              kMessages, kRateHz, received_ok, static_cast<unsigned long long>(count_errors),
              static_cast<unsigned long long>(wires.edges), static_cast<unsigned long long>(wraps),
              kMessages / kRateHz, wall_s, static_cast<double>(boards.bench.clocks()) / wall_s / 1e6);
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
