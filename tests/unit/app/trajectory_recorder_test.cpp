// The trajectory recorder inside the real run assembly: it records every cycle's exchange time
// and wheel positions exactly (virtual clock, charged costs) and never allocates on the loop.
#include "hiltwin/runs/trajectory_recorder.h"

#include <gtest/gtest.h>

#include <memory>

#include "fakes/loop_allocations.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runs/twin_run.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

constexpr double kRateHz = 4000.0;
constexpr kernel_glue::TimeNs kPeriodNs = 250'000;

TwinRunOptions VirtualTwin(double seconds) {
  TwinRunOptions o;
  o.session.rate_hz = kRateHz;
  o.session.duration_s = seconds;
  o.session.clock = runtime::ClockKind::kVirtual;
  o.session.progress = false;
  o.controller_rate_hz = 1000.0;
  return o;
}

struct RecordedRun {
  runtime::RunReport report;
  analysis::TwinTrajectory trajectory;
  std::size_t not_recorded = 0;
  std::uint64_t allocations = 0;
  double last_left_m = 0.0;
};

RecordedRun RunRecorded(double seconds, runtime::VirtualCycleCosts costs, std::size_t capacity) {
  const TwinRunOptions o = VirtualTwin(seconds);
  const std::unique_ptr<Twin> twin = BuildTwin(o, kPeriodNs);
  runtime::SessionConfig config =
      MakeSessionConfig(o.session, TwinRole("test", o.controller_rate_hz), *twin->backend);
  config.virtual_costs = std::move(costs);
  TrajectoryRecorder recorder(*twin->task, kPeriodNs, capacity);
  runtime::RunSession session(std::move(config), recorder);
  test::LoopAllocations allocations;
  session.SetLoopThreadHooks(&allocations);
  RecordedRun run;
  run.report = session.Run();
  run.trajectory = recorder.trajectory();
  run.not_recorded = recorder.cycles_not_recorded();
  run.allocations = allocations.count;
  run.last_left_m = twin->task->outputs()[relbot_port::kWheelLeftM];
  return run;
}

TEST(TrajectoryRecorder, RecordsEveryExchangeAtItsChargedTimeWithoutAllocating) {
  runtime::VirtualCycleCosts costs;
  costs.compute_ns = {100'000};
  costs.wake_latency_ns = {30'000};
  const RecordedRun run = RunRecorded(2.0, costs, 8000);  // the profile rests for 1 s
  EXPECT_EQ(run.allocations, 0U) << "malloc counted: " << test::MallocIsCounted();
  ASSERT_EQ(run.trajectory.exchange_time_s.size(), 8000U);
  EXPECT_EQ(run.not_recorded, 0U);
  EXPECT_DOUBLE_EQ(run.trajectory.period_s, 250e-6);
  // Every cycle slept (130 us of work in 250 us) and woke 30 us late: exchange k at k T + 30 us.
  for (std::size_t k = 0; k < 8000; k += 997) {
    EXPECT_NEAR(run.trajectory.exchange_time_s[k], static_cast<double>(k) * 250e-6 + 30e-6, 1e-12)
        << "cycle " << k;
  }
  EXPECT_EQ(run.report.misses.deadline_misses, 0U);
  EXPECT_DOUBLE_EQ(run.trajectory.wheel_left_m.back(), run.last_left_m);
  EXPECT_NE(run.last_left_m, 0.0);  // the profile drove the wheel
}

TEST(TrajectoryRecorder, StopsRecordingWhenFullAndCountsWhatItLeftOut) {
  const RecordedRun run = RunRecorded(0.5, {}, 1500);
  EXPECT_EQ(run.allocations, 0U);
  EXPECT_EQ(run.trajectory.exchange_time_s.size(), 1500U);
  EXPECT_EQ(run.not_recorded, 500U);
  EXPECT_DOUBLE_EQ(run.trajectory.exchange_time_s[1499], 1499 * 250e-6);
}

}  // namespace
}  // namespace hiltwin::app
