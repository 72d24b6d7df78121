// The bench itself: timing of a transfer, the idle speed of the clocks.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

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

TEST(RtlBench, ClocksPerSecond) {
  for (const bool two : {false, true}) {
    RtlBench bench(true, two, two);
    const auto t0 = std::chrono::steady_clock::now();
    bench.RunClocks(2'000'000);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%s: %.1f M clocks/s\n", two ? "two boards, wired" : "twin alone", 2.0 / s);
    EXPECT_GE(bench.clocks(), 2'000'000U);
  }
}

}  // namespace
}  // namespace hiltwin::fpga_sim
