// The ECS's safety around a user's controller, in the real run assembly (runtime::RunSession)
// with the RELbot twin behind its board in the same process: a controller's step is the ECS's
// compute, and one that returns an error, writes NaN or asks for a duty beyond its route's
// limit is stopped with zero duty: the run ends ABORTED with a model fault naming the
// controller, the output and what was wrong. Each case with an in-process fake controller.
#include <gtest/gtest.h>
#include <time.h>

#include <cmath>
#include <string>

#include "fakes/fake_controller.h"
#include "fakes/loop_allocations.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/ecs_report.h"
#include "hiltwin/runtime/run_session.h"
#include "in_process_hil.h"

namespace hiltwin::app::test {
namespace {

using controller::ControllerFault;
using controller::ControllerStatus;
using controller::test::FakeController;

runtime::SessionConfig Session(const InProcessHil& rig, runtime::ClockKind clock,
                               std::uint64_t cycles) {
  runtime::SessionConfig config;
  config.task_name = "RELbot ECS";
  config.io = "mock";
  config.clock = clock;
  config.rate_hz = 1e9 / static_cast<double>(rig.ecs_period_ns());
  config.executive.period_ns = rig.ecs_period_ns();
  config.executive.max_cycles = cycles;
  config.qos.rules = qos::DefaultRules();
  config.qos.planned_cycles = cycles;
  return config;
}

/// A P controller on the wheels (the RELbot's ports) that turns bad after `good_steps`.
enum class Misbehave { kNever, kErrorStatus, kNaN, kBeyondLimit };

FakeController::StepFn TurnsBad(Misbehave how, int good_steps) {
  return [how, good_steps, n = 0](std::span<const double> in, std::span<double> out) mutable {
    out[0] = std::clamp(50.0 * (in[0] - in[2]), -1.0, 1.0);
    out[1] = std::clamp(50.0 * (in[1] - in[3]), -1.0, 1.0);
    if (how == Misbehave::kNever || ++n <= good_steps) return ControllerStatus::Ok();
    if (how == Misbehave::kErrorStatus) return ControllerStatus::Error("my integrator overflowed");
    (how == Misbehave::kNaN ? out[1] : out[0]) = how == Misbehave::kNaN ? std::nan("") : -1.5;
    return ControllerStatus::Ok();
  };
}

struct Outcome {
  runtime::RunReport report;
  nlohmann::ordered_json json;  ///< the ECS's report, as `hiltwin ecs` writes it
  std::uint64_t allocations = 0;
  int steps = 0;
};

Outcome RunWith(FakeController& fake, runtime::ClockKind clock, std::uint64_t cycles) {
  const SetpointProfile profile = ClosedLoopProfile();
  HilConfig config;
  config.setpoints = &profile;
  config.controller = &fake;
  fake.record_inputs = false;  // it allocates: the loop must not
  InProcessHil rig(config);
  runtime::RunSession session(Session(rig, clock, cycles), rig);
  hiltwin::test::LoopAllocations allocations;
  session.SetLoopThreadHooks(&allocations);
  Outcome out;
  out.report = session.Run();
  out.json = EcsReportJson(out.report, EcsFiguresOf(rig.ecs(), rig.ecs_driver(), nullptr));
  out.allocations = allocations.count;
  out.steps = fake.steps;
  return out;
}

void ExpectStoppedAt(const Outcome& o, std::uint64_t cycle, const std::string& reason) {
  EXPECT_EQ(o.report.stop_reason, lifecycle::StopReason::kModelFault);
  // The run did not finish: the verdict judges only the timing of the cycles run, and the
  // exit code is the model fault's (1).
  const runtime::Conclusion conclusion = runtime::ConclusionOf(o.report);
  EXPECT_FALSE(conclusion.complete);
  EXPECT_EQ(conclusion.text, "PASS for the timing of the " + std::to_string(cycle + 1) +
                                 " cycles run; the run did NOT finish: model fault at cycle " +
                                 std::to_string(cycle));
  EXPECT_EQ(runtime::ExitCodeFor(o.report), runtime::ExitCode::kInternal);
  ASSERT_TRUE(o.report.fault.has_value());
  EXPECT_EQ(o.report.fault->cycle, cycle);
  EXPECT_EQ(o.report.fault->reason, reason);
  EXPECT_TRUE(o.report.outputs_safe);
  EXPECT_EQ(o.allocations, 0U);
  EXPECT_EQ(o.steps, static_cast<int>(cycle) + 1);  // never stepped again
}

TEST(ControllerSafety, AnErrorStatusStopsTheRunNamingTheController) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      TurnsBad(Misbehave::kErrorStatus, 300));
  const Outcome o = RunWith(fake, runtime::ClockKind::kVirtual, 2000);
  ExpectStoppedAt(o, 300, "controller 'fake' (--controller fake) stopped: its step returned an "
                          "error (my integrator overflowed); the motors were stopped");
  const auto& fault = o.json["controller"]["fault"];
  EXPECT_EQ(fault["kind"], "error status");
  EXPECT_EQ(fault["reason"], "my integrator overflowed");
  EXPECT_EQ(fault["cycle"], 300);
}

TEST(ControllerSafety, ANaNOutputStopsTheRunNamingThePort) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      TurnsBad(Misbehave::kNaN, 10));
  const Outcome o = RunWith(fake, runtime::ClockKind::kVirtual, 2000);
  ExpectStoppedAt(o, 10, "controller 'fake' (--controller fake) stopped: output 'duty_right' is "
                         "not finite (NaN or infinite); the motors were stopped");
  EXPECT_EQ(o.json["controller"]["fault"]["kind"], "not finite");
  EXPECT_EQ(o.json["controller"]["fault"]["output"], "duty_right");
}

TEST(ControllerSafety, ADutyBeyondTheLimitStopsTheRunNamingThePortAndLimit) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      TurnsBad(Misbehave::kBeyondLimit, 1000));
  const Outcome o = RunWith(fake, runtime::ClockKind::kVirtual, 2000);
  ExpectStoppedAt(o, 1000, "controller 'fake' (--controller fake) stopped: output 'duty_left' "
                           "asks for a duty beyond its duty_limit 1; the motors were stopped");
  EXPECT_EQ(o.json["controller"]["fault"]["value"], -1.5);
  EXPECT_EQ(o.json["controller"]["fault"]["duty_limit"], 1.0);
}

TEST(ControllerSafety, AWellBehavedControllerRunsToTheEndAndIsNamedInTheReport) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      TurnsBad(Misbehave::kNever, 0));
  const Outcome o = RunWith(fake, runtime::ClockKind::kVirtual, 2000);
  EXPECT_EQ(o.report.stop_reason, lifecycle::StopReason::kFinished);
  EXPECT_EQ(o.allocations, 0U);
  EXPECT_EQ(o.json["controller"]["spec"], "fake");
  EXPECT_EQ(o.json["controller"]["kind"], "test");
  EXPECT_TRUE(o.json["controller"]["fault"].is_null());
  EXPECT_GT(o.json["tracking"]["max_abs_error_m"]["left"].get<double>(), 0.0);
  // The map's pairs, the left one the ECS's left wheel figures.
  const auto& pairs = o.json["tracking_pairs"];
  ASSERT_EQ(pairs.size(), 2U);
  EXPECT_EQ(pairs[0]["column"], "left_m");
  EXPECT_EQ(pairs[0]["tracks"], "wheel_left_m");
  EXPECT_EQ(pairs[0]["max_abs_error"], o.json["tracking"]["max_abs_error_m"]["left"]);
  EXPECT_EQ(pairs[1]["final_error"], o.json["tracking"]["final_error_m"]["right"]);
  EXPECT_EQ(pairs[1]["samples"], 2000);
}

/// Busy-waits `ns` on CLOCK_MONOTONIC: a controller whose step takes that long.
void Burn(std::int64_t ns) {
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  for (;;) {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if ((now.tv_sec - start.tv_sec) * 1'000'000'000 + (now.tv_nsec - start.tv_nsec) >= ns) return;
  }
}

TEST(ControllerSafety, TheControllersStepTimeIsTheEcsCompute) {
  // Wall clock: the executive measures the step (controller included, I/O excluded); every
  // cycle's compute is at least the 300 µs the controller burns, whatever the load.
  constexpr std::int64_t kBurnNs = 300'000;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      [](std::span<const double>, std::span<double> out) {
                        Burn(kBurnNs);
                        out[0] = out[1] = 0.0;
                        return ControllerStatus::Ok();
                      });
  const Outcome o = RunWith(fake, runtime::ClockKind::kRealtime, 50);
  EXPECT_EQ(o.report.compute.count, 50U);
  EXPECT_GE(o.report.compute.min_ns, kBurnNs);
  EXPECT_LT(o.report.io_time.max_ns, o.report.compute.min_ns + 10'000'000);  // sanity: measured
}

}  // namespace
}  // namespace hiltwin::app::test
