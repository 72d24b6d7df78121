// The RTL ECS board's quadrature decoders against the model's readers: one twin board model
// (io::EmulatedFpga) publishes its emulator periods; the model ECS board replays them into its
// QuadratureReaders, the RTL ECS board gets them as A/B levels on its input pins
// (VerilatedBoardDevice::SetEncoderSource). Both ECS boards get the same frames; every MISO byte
// must match, so the decoders count exactly the edges up to each ALL's board time, over random
// moves up to the pulse limit with wraps and reversals. This also fixes
// DeviceTiming::line_delay_clocks: the delays for which the answers match are printed.
#include <gtest/gtest.h>

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

TEST(EcsFedByTheModelTwin, DecodersCountExactlyWhatTheModelReadersCount) {
  std::string first;
  EXPECT_EQ(FeedMismatches(DeviceTiming{}.line_delay_clocks, 2000, &first), 0U) << first;
  // The window of line delays for which every answer matches (the default sits inside it).
  std::int64_t low = 0;
  std::int64_t high = 0;
  for (std::int64_t d = 300; d <= 330; ++d) {
    if (FeedMismatches(d, 200, nullptr) == 0) {
      if (low == 0) low = d;
      high = d;
    }
  }
  std::printf("answers match for line delays %lld .. %lld clocks\n", static_cast<long long>(low),
              static_cast<long long>(high));
  EXPECT_LT(low, DeviceTiming{}.line_delay_clocks);
  EXPECT_GT(high, DeviceTiming{}.line_delay_clocks);
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
