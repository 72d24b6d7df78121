// The generic controller task against one emulated ECS board with nothing behind it (every
// count read is 0), with fake controllers: the routes, the time, the tracking figures, and
// each way a controller is stopped (error status, non-finite output, duty beyond its limit).
#include "hiltwin/controller/controller_task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "fakes/fake_controller.h"
#include "fakes/alloc_counter.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"

namespace hiltwin::controller {
namespace {

using test::FakeController;

constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr double kCountsPerM = 50.0 * 64.0 / (2.0 * std::numbers::pi * 0.04);

struct LoneBoard {
  LoneBoard() { EXPECT_TRUE(driver.Init(kPeriodNs).ok); }
  io::EmulatedFpga board{io::Image::kIcoboard};
  io::EmulatedSpiBus bus{board};
  io::IcoBoard driver{bus};
};

/// left_m = 1 mm per second of task time, right_m constant.
class Ramp final : public SetpointColumns {
 public:
  [[nodiscard]] std::array<double, 2> At(double time_s) const noexcept override {
    return {1e-3 * time_s, -0.5};
  }
};

scheduler::CycleContext Cycle(std::uint64_t k) {
  scheduler::CycleContext context;
  context.cycle = k;
  context.period_ns = kPeriodNs;
  context.release_ns = static_cast<std::int64_t>(k) * kPeriodNs;
  context.model_time_ns = context.release_ns;
  return context;
}

/// The RELbot's wiring, but the right motor at half gain, reversed, limited to 0.8.
constexpr const char* kMap = R"(
[[encoder]]
channel = 2
input = "wheel_left_m"
unit = "m"
counts_per_rev = 64
gear_ratio = 50
wheel_radius_m = 0.04
[[encoder]]
channel = 1
input = "wheel_right_m"
unit = "m"
counts_per_unit = 1000
[[setpoint]]
column = "left_m"
input = "setpoint_left_m"
tracks = "wheel_left_m"
on_encoder_grid = true
[[setpoint]]
column = "right_m"
input = "setpoint_right_m"
tracks = "wheel_right_m"
[[pwm]]
channel = 2
output = "duty_left"
[[pwm]]
channel = 1
output = "duty_right"
gain = 0.5
reverse = true
duty_limit = 0.8
)";

BoundControllerMap Bind(const Controller& controller) {
  return BindControllerMap(ParseControllerMap(kMap, "map.toml"), controller);
}

/// Duty left = the (gridded) left setpoint input ×1000; duty right output = `right`.
FakeController::StepFn Echo(double right) {
  return [right](std::span<const double> in, std::span<double> out) {
    out[0] = in[0] * 1000.0;
    out[1] = right;
    return ControllerStatus::Ok();
  };
}

TEST(ControllerTask, SetpointsGoInOnTheGridAndOutputsOutWithGainAndDirection) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(1.2));
  {
    ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
    EXPECT_EQ(fake.started_step_s, 1e-3);
    for (std::uint64_t k = 0; k < 300; ++k) {
      ASSERT_TRUE(task.Exchange(true).ok());
      ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
    }
    // t = 0.299 s: left 0.299 mm = 3.807 counts, on the grid 4 counts; right as is.
    EXPECT_EQ(task.time_s(), static_cast<double>(299'000'000) * 1e-9);
    EXPECT_EQ(fake.last_in[0], 4.0 / kCountsPerM);
    EXPECT_EQ(fake.last_in[1], -0.5);
    EXPECT_EQ(fake.last_in[2], 0.0);  // no wheel moves behind a lone board
    ASSERT_TRUE(task.Exchange(true).ok());
    EXPECT_EQ(rig.board.pwm_output()[1], io::DutyToPwm(4000.0 / kCountsPerM));  // channel 2
    EXPECT_EQ(rig.board.pwm_output()[0], io::DutyToPwm(-0.6));  // 1.2 · 0.5, reversed
    // Tracking: setpoint (not gridded) − wheel (0), per pair.
    const std::vector<TrackingPair> pairs = task.tracking();
    ASSERT_EQ(pairs.size(), 2U);
    EXPECT_EQ(pairs[0].column, "left_m");
    EXPECT_EQ(pairs[0].tracked, "wheel_left_m");
    EXPECT_EQ(pairs[0].samples, 300U);
    EXPECT_EQ(pairs[0].max_abs_error, 1e-3 * (static_cast<double>(299'000'000) * 1e-9));
    EXPECT_EQ(pairs[1].final_error, -0.5);
    EXPECT_EQ(pairs[1].rms_error, 0.5);
    EXPECT_EQ(task.max_abs_duty(), 0.6);
    EXPECT_EQ(task.saturated_cycles(), 0U);
    EXPECT_EQ(task.fault().kind, ControllerFault::Kind::kNone);
    EXPECT_EQ(fake.finishes, 0);
  }
  EXPECT_EQ(fake.finishes, 1);  // the task ends the controller
}

TEST(ControllerTask, AnOutputAtItsDutyLimitCountsAsSaturated) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(1.6));
  ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  for (std::uint64_t k = 0; k < 10; ++k) {
    ASSERT_TRUE(task.Exchange(true).ok());
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
  }
  EXPECT_EQ(task.saturated_cycles(), 10U);  // 1.6 · 0.5 = 0.8, the right route's limit
  EXPECT_EQ(task.max_abs_duty(), 0.8);
}

TEST(ControllerTask, APauseHoldsTheSetpointProfile) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(0));
  ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  for (std::uint64_t k = 0; k < 10; ++k) {
    ASSERT_TRUE(task.Exchange(k < 3 || k >= 8).ok());  // cycles 3..7 paused: safe outputs
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
  }
  EXPECT_EQ(task.time_s(), static_cast<double>(4'000'000) * 1e-9);  // cycle 9 − 5 held
}

/// Runs `fake` until its first fault; returns the fault's reason and checks safe outputs.
std::string FirstFault(FakeController& fake, ControllerFault& fault, std::uint64_t& cycle) {
  LoneBoard rig;
  const Ramp ramp;
  ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  for (std::uint64_t k = 0; k < 100; ++k) {
    EXPECT_TRUE(task.Exchange(true).ok());
    const runtime::StepStatus status = task.Step(Cycle(k));
    if (status.code == runtime::StepStatus::Code::kOk) continue;
    EXPECT_EQ(status.code, runtime::StepStatus::Code::kModelFault);
    // Safe outputs from the next exchange on, and the controller stays stopped.
    EXPECT_TRUE(task.Exchange(true).ok());
    EXPECT_EQ(rig.board.pwm_output()[0], 0);
    EXPECT_EQ(rig.board.pwm_output()[1], 0);
    const int steps = fake.steps;
    EXPECT_EQ(task.Step(Cycle(k + 1)).reason, status.reason);
    EXPECT_EQ(fake.steps, steps);
    fault = task.fault();
    cycle = k;
    return status.reason;
  }
  return "";
}

TEST(ControllerTask, AnErrorStatusStopsTheControllerNamingIt) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      [n = 0](std::span<const double>, std::span<double> out) mutable {
                        out[0] = out[1] = 0.1;
                        return ++n < 5 ? ControllerStatus::Ok()
                                       : ControllerStatus::Error("the gains file was empty");
                      });
  ControllerFault fault;
  std::uint64_t cycle = 0;
  EXPECT_EQ(FirstFault(fake, fault, cycle),
            "controller 'fake' (--controller fake) stopped: its step returned an error (the "
            "gains file was empty); the motors were stopped");
  EXPECT_EQ(cycle, 4U);
  EXPECT_EQ(fault.kind, ControllerFault::Kind::kErrorStatus);
  EXPECT_EQ(fault.cycle, 4U);
  EXPECT_EQ(fault.reason, "the gains file was empty");
  EXPECT_EQ(fault.output, "");
}

TEST(ControllerTask, ANonFiniteOutputStopsTheControllerNamingThePort) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(),
                      [n = 0](std::span<const double>, std::span<double> out) mutable {
                        out[0] = 0.1;
                        out[1] = ++n < 3 ? 0.1 : std::nan("");
                        return ControllerStatus::Ok();
                      });
  ControllerFault fault;
  std::uint64_t cycle = 0;
  EXPECT_EQ(FirstFault(fake, fault, cycle),
            "controller 'fake' (--controller fake) stopped: output 'duty_right' is not finite "
            "(NaN or infinite); the motors were stopped");
  EXPECT_EQ(cycle, 2U);
  EXPECT_EQ(fault.kind, ControllerFault::Kind::kNotFinite);
  EXPECT_EQ(fault.output, "duty_right");
  EXPECT_TRUE(std::isnan(fault.value));
}

TEST(ControllerTask, ADutyBeyondItsLimitStopsTheControllerNamingThePortAndLimit) {
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(-1.7));
  ControllerFault fault;
  std::uint64_t cycle = 0;
  EXPECT_EQ(FirstFault(fake, fault, cycle),
            "controller 'fake' (--controller fake) stopped: output 'duty_right' asks for a duty "
            "beyond its duty_limit 0.8; the motors were stopped");
  EXPECT_EQ(cycle, 0U);
  EXPECT_EQ(fault.kind, ControllerFault::Kind::kBeyondLimit);
  EXPECT_EQ(fault.value, 0.85);  // -1.7 · 0.5, reversed
  EXPECT_EQ(fault.duty_limit, 0.8);
}

TEST(ControllerTask, TheCyclePathAllocatesNothing) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(0.3));
  fake.record_inputs = false;
  ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  ASSERT_TRUE(task.Exchange(true).ok());  // the driver's first frame outside the count
  ASSERT_EQ(task.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  std::array<double, 6> row{};
  const hiltwin::test::ScopedAllocationCount count;
  for (std::uint64_t k = 1; k < 200; ++k) {
    static_cast<void>(task.Exchange(k % 50 != 0));
    static_cast<void>(task.Step(Cycle(k)));
    task.FillLogRow(row);
  }
  EXPECT_EQ(count.count(), 0U);
  EXPECT_EQ(fake.steps, 200);
}

TEST(ControllerTask, AControllerWithAFixedStepRunsOnlyAtIt) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs());
  fake.FixStep(0.002);
  try {
    const ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
    FAIL() << "no error";
  } catch (const ControllerError& e) {
    EXPECT_EQ(std::string(e.what()),
              "controller 'fake' (--controller fake) runs only at its own step of 0.002 s, but "
              "the ECS's period is 0.001 s: run the ECS at --rate 500, or regenerate the "
              "controller for this step");
  }
  EXPECT_EQ(fake.starts, 0);
  fake.FixStep(0.001);
  const ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  EXPECT_EQ(fake.starts, 1);
}

TEST(ControllerTask, TheLogHasTheControllersInputsThenOutputs) {
  LoneBoard rig;
  const Ramp ramp;
  FakeController fake(FakeController::RelbotInputs(), FakeController::RelbotOutputs(), Echo(0.3));
  ControllerTask task(rig.driver, fake, Bind(fake), ramp, kPeriodNs);
  EXPECT_EQ(task.LogColumns(),
            (std::vector<std::string>{"setpoint_left_m", "setpoint_right_m", "wheel_left_m",
                                      "wheel_right_m", "duty_left", "duty_right"}));
  ASSERT_TRUE(task.Exchange(true).ok());
  ASSERT_EQ(task.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  std::array<double, 6> row{};
  task.FillLogRow(row);
  EXPECT_EQ(row, (std::array<double, 6>{0.0, -0.5, 0.0, 0.0, 0.0, 0.3}));
}

}  // namespace
}  // namespace hiltwin::controller
