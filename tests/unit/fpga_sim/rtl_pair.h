#pragma once
// Both boards as verilated RTL on one bench, wired pin to pin, each behind its own bus: the
// RTL counterpart of tests/unit/io/board_pair.h.

#include "hiltwin/fpga_sim/rtl_bench.h"
#include "hiltwin/fpga_sim/verilated_board.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::fpga_sim::test {

inline DeviceTiming WithPhase(std::int64_t phase_ns) {
  DeviceTiming timing;
  timing.phase_ns = phase_ns;
  return timing;
}

struct RtlBoardPair {
  /// `twin_phase_ns`: the twin board's ALLs that much after their board time.
  explicit RtlBoardPair(std::int64_t twin_phase_ns = 0)
      : twin_board(bench, io::Image::kIcoboardInverse, WithPhase(twin_phase_ns)) {}
  RtlBench bench{true, true, true};
  VerilatedBoardDevice twin_board;
  VerilatedBoardDevice ecs_board{bench, io::Image::kIcoboard};
  io::EmulatedSpiBus twin_bus{twin_board, "verilated"};
  io::EmulatedSpiBus ecs_bus{ecs_board, "verilated"};
};

}  // namespace hiltwin::fpga_sim::test
