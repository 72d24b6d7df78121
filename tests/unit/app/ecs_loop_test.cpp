// The ECS in the real run assembly (runtime::RunSession on the virtual clock, exactly as a
// command runs it), with the RELbot twin behind its board in the same process: the loop thread
// allocates nothing, the session's run equals a hand-stepped one, and an open-loop ECS log
// replays as the input of a reference run that reproduces the twin exactly (thesis §5.2).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>

#include "fakes/alloc_counter.h"
#include "fakes/loop_allocations.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/runtime/run_session.h"
#include "in_process_hil.h"

namespace hiltwin::app::test {
namespace {

using hiltwin::test::LoopAllocations;

std::string TempLog(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string(name) + std::to_string(getpid()) + ".csv"))
      .string();
}

runtime::SessionConfig VirtualSession(const InProcessHil& rig, const std::string& log_path) {
  runtime::SessionConfig config;
  config.task_name = "RELbot ECS";
  config.io = "mock";
  config.clock = runtime::ClockKind::kVirtual;
  config.rate_hz = 1e9 / static_cast<double>(rig.ecs_period_ns());
  config.executive.period_ns = rig.ecs_period_ns();
  config.executive.max_cycles = rig.planned_cycles();
  config.qos.rules = qos::DefaultRules();
  config.qos.planned_cycles = rig.planned_cycles();
  config.log = runtime::LogConfig{log_path, 1};
  return config;
}

void ExpectSameStats(const TrackingStats& a, const TrackingStats& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.max_abs_error_left_m, b.max_abs_error_left_m);
  EXPECT_EQ(a.max_abs_error_right_m, b.max_abs_error_right_m);
  EXPECT_EQ(a.rms_error_m, b.rms_error_m);
  EXPECT_EQ(a.final_error_left_m, b.final_error_left_m);
  EXPECT_EQ(a.final_error_right_m, b.final_error_right_m);
  EXPECT_EQ(a.saturated_cycles, b.saturated_cycles);
}

TEST(EcsLoop, ClosedLoopRunsInARunSessionWithoutAllocating) {
  const SetpointProfile profile = ClosedLoopProfile();
  HilConfig config;
  config.gains = DefaultEcsGains();
  config.setpoints = &profile;
  InProcessHil rig(config);
  const std::string log_path = TempLog("hiltwin_ecs_loop_");
  runtime::RunSession session(VirtualSession(rig, log_path), rig);
  LoopAllocations allocations;
  session.SetLoopThreadHooks(&allocations);
  const runtime::RunReport report = session.Run();
  EXPECT_EQ(allocations.count, 0U) << "malloc counted: " << hiltwin::test::MallocIsCounted();
  EXPECT_EQ(report.cycles_run, rig.planned_cycles());
  EXPECT_EQ(report.cycles_run, 12'000U);
  EXPECT_EQ(report.stop_reason, lifecycle::StopReason::kFinished);
  EXPECT_TRUE(report.outputs_safe);
  ASSERT_TRUE(report.log.has_value());
  EXPECT_EQ(report.log->rows_written, 12'000U);
  const HilObservations seen = rig.observations();
  EXPECT_EQ(seen.board_time_mismatches, 0U);
  EXPECT_EQ(seen.link_errors, 0U);
  EXPECT_EQ(seen.twin_cycles, 4U * 12'000U);

  // The session's run is the hand-stepped run, to the last bit.
  InProcessHil by_hand(config);
  RunInProcess(by_hand);
  ExpectSameStats(rig.ecs().tracking(), by_hand.ecs().tracking());
  EXPECT_EQ(rig.model().Outputs().wheel_left_m, by_hand.model().Outputs().wheel_left_m);
  std::filesystem::remove(log_path);
}

/// A twin alone, driven by a duty profile the way a 1 kHz ECS plays it (ProfilePwmSource):
/// the reference run of thesis §5.2.
struct ReferenceTwin {
  explicit ReferenceTwin(const InputProfile& profile)
      : source(profile, 1000.0, 4000.0),
        twin(driver, params, Integrator::kRk4, 2.5e-4) {
    board.SetPwmSource(&source);
    EXPECT_TRUE(driver.Init(250'000).ok);
  }
  void Run(std::uint64_t cycles) {
    for (std::uint64_t j = 0; j < cycles; ++j) {
      ASSERT_TRUE(twin.task().Exchange(true).ok());
      scheduler::CycleContext context;
      context.cycle = j;
      context.period_ns = 250'000;
      ASSERT_EQ(twin.task().Step(context).code, runtime::StepStatus::Code::kOk);
    }
  }
  ProfilePwmSource source;
  RelbotParams params = DefaultRelbotParams();
  io::WheelGeometry geometry = WheelGeometryOf(params);
  io::EmulatedFpga board{io::Image::kIcoboardInverse};
  io::EmulatedSpiBus bus{board};
  io::IcoBoardInverse driver{bus};
  RelbotTwin twin;
};

TEST(EcsLoop, OpenLoopLogReplaysIntoAReferenceRunThatReproducesTheTwin) {
  const InputProfile openloop = OpenLoopProfile();
  HilConfig config;
  config.duty_profile = &openloop;
  InProcessHil rig(config);
  const std::string log_path = TempLog("hiltwin_ecs_openloop_");
  runtime::RunSession session(VirtualSession(rig, log_path), rig);
  LoopAllocations allocations;
  session.SetLoopThreadHooks(&allocations);
  const runtime::RunReport report = session.Run();
  EXPECT_EQ(allocations.count, 0U);
  ASSERT_EQ(report.cycles_run, 36'000U);
  EXPECT_EQ(rig.observations().board_time_mismatches, 0U);

  // The ECS's log, read back as a duty profile (its duty_left and duty_right columns).
  const InputProfile logged = LoadInputProfile(log_path);
  EXPECT_EQ(logged.knots().size(), 36'000U);
  ReferenceTwin reference(logged);
  reference.Run(rig.observations().twin_cycles);
  const RelbotOutputs twin = rig.model().Outputs();
  const RelbotOutputs ref = reference.twin.outputs();
  EXPECT_GT(std::abs(twin.wheel_right_m), 0.1);  // the profile really drove the robot
  EXPECT_EQ(ref.wheel_left_m, twin.wheel_left_m);
  EXPECT_EQ(ref.wheel_right_m, twin.wheel_right_m);
  EXPECT_EQ(ref.theta_rad, twin.theta_rad);

  // What the ECS measured is the twin's wheel at its sampling moment, floored to a count and
  // one twin period (250 µs) late: at most 1 count plus 0.25 ms of travel at top speed.
  const double count_m = 1.0 / io::CountsPerMetre(WheelGeometryOf(DefaultRelbotParams()));
  EXPECT_NEAR(rig.ecs().last().measured.right_m, twin.wheel_right_m,
              count_m + 0.96 * 2.5e-4 + 1e-9);
  std::filesystem::remove(log_path);
}

}  // namespace
}  // namespace hiltwin::app::test
