// The RTL ECS board's quadrature decoders against the model's readers: one twin board model
// (io::EmulatedFpga) publishes its emulator periods; the model ECS board replays them into its
// QuadratureReaders, the RTL ECS board gets them as A/B levels on its input pins
// (VerilatedBoardDevice::SetEncoderSource). Both ECS boards get the same frames; every MISO byte
// must match, so the decoders count exactly the edges up to each ALL's board time, over random
// moves up to the pulse limit with wraps and reversals. This also fixes
// DeviceTiming::line_delay_clocks: the delays for which the answers match are printed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "hiltwin/fpga_sim/verilated_board.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/icoboard.h"
#include "rtl_frames.h"

namespace hiltwin::fpga_sim::test {
namespace {

constexpr std::int64_t kFeedStepNs = 250'000;

std::size_t FeedMismatches(std::int64_t line_delay_clocks, int steps, std::string* first) {
  io::EmulatedFpga twin_board(io::Image::kIcoboardInverse);
  io::EmulatorToReaderLink lines(twin_board);
  io::EmulatedSpiBus twin_bus(twin_board);
  io::IcoBoardInverse twin(twin_bus);
  io::EmulatedFpga ecs_model(io::Image::kIcoboard);
  ecs_model.SetEncoderSource(&lines);
  RtlBench bench(false, true, false);
  DeviceTiming timing;
  timing.line_delay_clocks = line_delay_clocks;
  VerilatedBoardDevice ecs_rtl(bench, io::Image::kIcoboard, timing);
  ecs_rtl.SetEncoderSource(&lines);
  std::size_t differ = 0;
  std::uint8_t seq = 0;
  auto both = [&](const io::FrameBytes& mosi) {
    io::FrameBytes a{};
    io::FrameBytes b{};
    ecs_model.Exchange(mosi, a);
    ecs_rtl.Exchange(mosi, b);
    if (a != b && ++differ <= 4 && first != nullptr) {
      *first += "MOSI " + Hex(mosi) + "\n  model " + Hex(a) + "\n  RTL   " + Hex(b) + "\n";
    }
  };
  EXPECT_TRUE(twin.Init(kFeedStepNs).ok);
  both(Init(seq++, kFeedStepNs, 0, io::Image::kIcoboard));
  both(Noop(seq++));
  const auto limit = static_cast<std::int64_t>(io::MaxCountsPerStep(kFeedStepNs, twin.clock_divider()));
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<std::int64_t> small(-300, 300);
  std::uniform_int_distribution<std::int64_t> large(-limit, limit);
  std::uniform_int_distribution<int> roll(0, 9);
  std::array<std::int32_t, io::kChannels> position{};
  io::TwinInputs in;
  for (int k = 0; k < steps; ++k) {
    for (auto& p : position) p = static_cast<std::int32_t>(p + (roll(rng) < 8 ? small(rng) : large(rng)));
    EXPECT_TRUE(twin.Exchange(position, in).ok());
    both(AllEcs(seq++, {0, 0, 0, 0}));
    both(Noop(seq++));
    if (k % 7 == 0) {  // a read-back of one channel's latched count between ALLs
      both(Simple(io::EncOpcode(static_cast<std::size_t>(k) % 4), seq++, io::Image::kIcoboard));
      both(Noop(seq++));
    }
  }
  return differ;
}

/// The window's edge on one side of a delay whose answers all match: the farthest delay towards
/// `outer` (whose answers need not match) for which they still do, found by bisection. The
/// delays that match form one interval (a longer delay only moves the same edges later), so
/// 5 short runs find each edge where a scan of the 31 delays 300..330 took 31.
std::int64_t WindowEdge(std::int64_t inside, std::int64_t outer, int steps) {
  while (std::abs(outer - inside) > 1) {
    const std::int64_t middle = inside + (outer - inside) / 2;
    (FeedMismatches(middle, steps, nullptr) == 0 ? inside : outer) = middle;
  }
  return FeedMismatches(outer, steps, nullptr) == 0 ? outer : inside;
}

TEST(EcsFedByTheModelTwin, DecodersCountExactlyWhatTheModelReadersCount) {
  const std::int64_t delay = DeviceTiming{}.line_delay_clocks;
  std::string first;
  EXPECT_EQ(FeedMismatches(delay, 2000, &first), 0U) << first;
  // The window of line delays for which every answer matches, within 300..330 clocks: the
  // default must sit inside it, not on its edge.
  constexpr int kWindowSteps = 200;
  const std::int64_t low = WindowEdge(delay, 300, kWindowSteps);
  const std::int64_t high = WindowEdge(delay, 330, kWindowSteps);
  std::printf("answers match for line delays %lld .. %lld clocks\n", static_cast<long long>(low),
              static_cast<long long>(high));
  EXPECT_LT(low, delay);
  EXPECT_GT(high, delay);
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
