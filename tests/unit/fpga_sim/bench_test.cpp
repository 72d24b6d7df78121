// The bench itself: the timing of a transfer. (Its speed is a benchmark: bench/fpga_sim.)
#include <gtest/gtest.h>

#include "hiltwin/fpga_sim/rtl_bench.h"

namespace hiltwin::fpga_sim {
namespace {

TEST(RtlBench, ATransferTakes193HalfPeriodsOfSclk) {
  RtlBench bench(true, false, false);
  const std::int64_t start = bench.now_ps();
  io::FrameBytes mosi{};
  io::FrameBytes miso{};
  bench.Transfer(Slot::kTwin, mosi, miso);
  EXPECT_EQ(bench.now_ps() - start, 193 * 16'000);
}

}  // namespace
}  // namespace hiltwin::fpga_sim
