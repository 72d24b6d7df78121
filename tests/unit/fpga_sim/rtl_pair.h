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
  RtlBoardPair(const DeviceTiming& twin_timing, const DeviceTiming& ecs_timing)
      : twin_board(bench, io::Image::kIcoboardInverse, twin_timing),
        ecs_board(bench, io::Image::kIcoboard, ecs_timing) {}
  RtlBench bench{true, true, true};
  VerilatedBoardDevice twin_board;
  VerilatedBoardDevice ecs_board;
  io::EmulatedSpiBus twin_bus{twin_board, "verilated"};
  io::EmulatedSpiBus ecs_bus{ecs_board, "verilated"};
};

}  // namespace hiltwin::fpga_sim::test
