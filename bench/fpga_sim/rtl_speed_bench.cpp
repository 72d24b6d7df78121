// How fast the gateware co-simulates (docs/fpga-cosim.md, "Speed"; figures in BENCHMARKS.md).
// 1. Raw: 100 MHz clocks per wall second of the verilated twin board alone and of the wired pair
//    (both boards evaluated on every edge), no SPI.
// 2. Against the peer: a 4 kHz twin's exchanges (INIT, then ALL with a moving encoder target
//    every 250 µs of board time) through the IcoBoardInverse driver, once on the verilated board
//    (SPI at 31.25 MHz, every clock simulated) and once on io::EmulatedFpga (the C++ model the
//    mock backend uses). Printed as board seconds per wall second and the ratio.
#include <chrono>
#include <cstdint>
#include <cstdio>

#include "bench_stats.h"
#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/fpga_sim/verilated_board.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::int64_t kStepNs = 250'000;  // 4 kHz twin

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

double RawClocksPerSecond(bool pair) {
  hiltwin::fpga_sim::RtlBench bench(true, pair, pair);
  constexpr std::uint64_t kClocks = 4'000'000;
  const auto t0 = Clock::now();
  bench.RunClocks(kClocks);
  return static_cast<double>(kClocks) / Seconds(t0);
}

/// Board seconds per wall second of `exchanges` twin exchanges on `device`.
double BoardSecondsPerWallSecond(hiltwin::io::SpiDevice& device, int exchanges) {
  hiltwin::io::EmulatedSpiBus bus(device, "bench");
  hiltwin::io::IcoBoardInverse driver(bus);
  if (!driver.Init(kStepNs).ok) {
    std::fprintf(stderr, "INIT refused\n");
    return 0.0;
  }
  hiltwin::io::TwinInputs in;
  std::array<std::int32_t, hiltwin::io::kChannels> counts{};
  const auto t0 = Clock::now();
  for (int k = 0; k < exchanges; ++k) {
    for (std::size_t c = 0; c < counts.size(); ++c) counts[c] += static_cast<std::int32_t>(c + 1) * 7;
    (void)driver.Exchange(counts, in);
  }
  return static_cast<double>(exchanges) * static_cast<double>(kStepNs) * 1e-9 / Seconds(t0);
}

}  // namespace

int main() {
  using hiltwin::bench::Median;
  std::vector<double> one;
  std::vector<double> pair;
  for (int r = 0; r < 3; ++r) {
    one.push_back(RawClocksPerSecond(false));
    pair.push_back(RawClocksPerSecond(true));
  }
  std::printf("raw, twin board alone:    %.1f M clocks/s (median of 3)\n", Median(one) / 1e6);
  std::printf("raw, wired pair:          %.1f M clocks/s (median of 3)\n", Median(pair) / 1e6);

  hiltwin::fpga_sim::RtlBench bench(true, false, false);
  hiltwin::fpga_sim::VerilatedBoardDevice rtl(bench, hiltwin::io::Image::kIcoboardInverse);
  const double rtl_rate = BoardSecondsPerWallSecond(rtl, 400);  // 0.1 s of board time
  hiltwin::io::EmulatedFpga model(hiltwin::io::Image::kIcoboardInverse);
  const double model_rate = BoardSecondsPerWallSecond(model, 4'000'000);  // 1000 s
  std::printf("4 kHz twin exchanges, RTL (verilated):  %.4f board s per wall s\n", rtl_rate);
  std::printf("4 kHz twin exchanges, C++ board model:  %.1f board s per wall s (peer)\n",
              model_rate);
  std::printf("ratio model/RTL: %.0fx\n", rtl_rate > 0.0 ? model_rate / rtl_rate : 0.0);
  return 0;
}
