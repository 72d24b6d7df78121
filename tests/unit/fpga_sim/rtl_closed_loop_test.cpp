// The closed-loop HiL test with both boards replaced by their RTL: the RELbot twin (RK4) ->
// IcoBoardInverse -> verilated twin board -> A/B and PWM wires -> verilated ECS board -> IcoBoard
// -> the ECS's PID, on one virtual timeline (tests/unit/app/in_process_hil.h with the boards
// plugged in). The default closedloop profile (2.5 m) must track within the thesis' 3 mm.
// The default suite runs its first 2 s (the start of the move: every count, every edge and the
// tracking bound still checked); the opt-in `long` label runs the whole 12 s profile
// (HILTWIN_RTL_LOOP_S=0, tests/unit/fpga_sim/CMakeLists.txt).
//
// Timing on the bench: the ECS board's ALL k at k·1 ms; the twin's ALL j at j·250 µs + 10 µs, so
// the twin's exchange never waits for the ECS's (8.7 µs) and its pulse periods stay a whole
// step long; the ECS then samples each twin period's edges up to 10 µs before its end (the
// boards are not synchronised in a real rig either). The PWM crosses the wires as a 24.4 kHz
// waveform measured over whole 4096-clock periods, so the twin sees a new duty one twin step
// later than the emulated pair does.
#include <gtest/gtest.h>

#include <chrono>

#include "../app/in_process_hil.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "rtl_pair.h"

#ifndef HILTWIN_RTL_LOOP_S
#define HILTWIN_RTL_LOOP_S 2.0
#define HILTWIN_RTL_LOOP_SUITE RtlClosedLoop
#endif

namespace hiltwin::fpga_sim::test {
namespace {

constexpr double kThesisBoundM = 3e-3;
constexpr std::int64_t kTwinPhaseNs = 10'000;

class RtlHilBoards final : public app::test::HilBoards {
 public:
  RtlHilBoards() : pair_(WithPhase(kTwinPhaseNs), DeviceTiming{}) {}
  io::SpiBus& twin_bus() noexcept override { return pair_.twin_bus; }
  io::SpiBus& ecs_bus() noexcept override { return pair_.ecs_bus; }
  std::int64_t twin_time_ns() const noexcept override { return pair_.twin_board.time_ns(); }
  std::int64_t ecs_time_ns() const noexcept override { return pair_.ecs_board.time_ns(); }
  std::uint64_t ecs_data_frames() const noexcept override { return pair_.ecs_board.data_frames(); }
  std::uint64_t line_errors() const noexcept override {
    const WireCounters& w = pair_.bench.wire_counters();
    return w.illegal_transitions + w.too_fast;
  }
  const RtlBoardPair& pair() const noexcept { return pair_; }

 private:
  RtlBoardPair pair_;
};

/// Cycles of a rate over the run: the configured seconds, or the whole profile when 0.
std::uint64_t CyclesOf(const app::SetpointProfile& profile, double rate_hz) {
  const double seconds = HILTWIN_RTL_LOOP_S > 0.0 ? HILTWIN_RTL_LOOP_S : profile.length_s();
  return static_cast<std::uint64_t>(seconds * rate_hz + 0.5);
}

TEST(HILTWIN_RTL_LOOP_SUITE, TracksTheTwoAndAHalfMetreMoveWithinThreeMillimetres) {
  static const app::SetpointProfile profile = app::ClosedLoopProfile();
  app::test::HilConfig config;
  config.ecs_rate_hz = 1000.0;
  config.twin_rate_hz = 4000.0;
  config.gains = app::DefaultEcsGains();
  config.setpoints = &profile;
  config.duration_s = HILTWIN_RTL_LOOP_S;
  auto boards = std::make_unique<RtlHilBoards>();
  const RtlHilBoards& rtl = *boards;
  app::test::InProcessHil rig(config, std::move(boards));
  const auto t0 = std::chrono::steady_clock::now();
  app::test::RunInProcess(rig);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const app::TrackingStats& stats = rig.ecs().tracking();
  const app::test::HilObservations seen = rig.observations();
  EXPECT_EQ(seen.ecs_cycles, CyclesOf(profile, config.ecs_rate_hz));
  EXPECT_EQ(seen.twin_cycles, CyclesOf(profile, config.twin_rate_hz));
  EXPECT_EQ(seen.board_time_mismatches, 0U);
  EXPECT_EQ(seen.link_errors, 0U);
  EXPECT_EQ(seen.line_errors, 0U);
  EXPECT_LT(stats.max_abs_error_left_m, kThesisBoundM);
  EXPECT_LT(stats.max_abs_error_right_m, kThesisBoundM);
  EXPECT_LT(seen.max_abs_true_error_left_m, kThesisBoundM);
  EXPECT_LT(seen.max_abs_true_error_right_m, kThesisBoundM);
  EXPECT_EQ(stats.saturated_cycles, 0U);
  EXPECT_LE(rtl.pair().twin_board.max_late_ns(), 0);
  EXPECT_LE(rtl.pair().ecs_board.max_late_ns(), 0);
  std::printf("RTL closed loop: max |error| left %.3f mm, right %.3f mm, RMS %.3f mm, true max "
              "%.3f / %.3f mm, final %.4f / %.4f mm, max duty %.3f, settled (1 count) at %.2f s; "
              "%llu A/B edges; %.1f s board time in %.1f s wall (%.1f M clocks/s)\n",
              stats.max_abs_error_left_m * 1e3, stats.max_abs_error_right_m * 1e3,
              stats.rms_error_m * 1e3, seen.max_abs_true_error_left_m * 1e3,
              seen.max_abs_true_error_right_m * 1e3, stats.final_error_left_m * 1e3,
              stats.final_error_right_m * 1e3, stats.max_abs_duty, seen.last_error_above_one_count_s,
              static_cast<unsigned long long>(rtl.pair().bench.wire_counters().edges),
              static_cast<double>(seen.ecs_cycles) / config.ecs_rate_hz, wall_s,
              static_cast<double>(rtl.pair().bench.clocks()) / wall_s / 1e6);
}

}  // namespace
}  // namespace hiltwin::fpga_sim::test
