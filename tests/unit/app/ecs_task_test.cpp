// EcsTask against one emulated ECS board (no twin behind it: the encoder lines stay still, so
// every count read is 0 and each test knows exactly what the task must send).
#include "hiltwin/relbot/ecs_task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {
namespace {

constexpr std::int64_t kPeriodNs = 1'000'000;

struct LoneBoard {
  LoneBoard() { EXPECT_TRUE(driver.Init(kPeriodNs).ok); }
  io::EmulatedFpga board{io::Image::kIcoboard};
  io::EmulatedSpiBus bus{board};
  io::IcoBoard driver{bus};
  io::WheelGeometry geometry = WheelGeometryOf(DefaultRelbotParams());
};

scheduler::CycleContext Cycle(std::uint64_t k, std::int64_t period_ns = kPeriodNs) {
  scheduler::CycleContext context;
  context.cycle = k;
  context.period_ns = period_ns;
  context.release_ns = static_cast<std::int64_t>(k) * period_ns;
  context.model_time_ns = context.release_ns;
  return context;
}

PidGains POnly(double kp) {
  PidGains gains;
  gains.kp_duty_per_m = kp;
  return gains;
}

TEST(EcsTask, OpenLoopPutsTheProfileOnTheWireAtTheCycleItIsSampledFor) {
  LoneBoard rig;
  // Left ramps 0 -> 1 and right 0 -> -1 over one second: duty = ±t.
  const InputProfile ramp = ParseCsvProfile("time,left,right\n0,0,0\n1,1,-1\n", "ramp.csv");
  EcsTask task(rig.driver, ramp, rig.geometry, kPeriodNs);
  EXPECT_EQ(task.mode(), EcsMode::kOpenLoop);
  for (std::uint64_t k = 0; k < 500; ++k) {
    ASSERT_TRUE(task.Exchange(true).ok());
    // On the wire from t_k: the profile at t_k (cycle 0: nothing computed yet, zero).
    const std::int32_t expected = io::DutyToPwm(static_cast<double>(k) * 1e-3);
    ASSERT_EQ(rig.board.pwm_output()[kLeftChannel], expected) << k;
    ASSERT_EQ(rig.board.pwm_output()[kRightChannel], -expected) << k;
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
    ASSERT_EQ(task.last().duty_sent.left, io::PwmToDuty(expected)) << k;
    // The task's time is cycle x period from the integer count, never accumulated.
    ASSERT_EQ(task.LogTimeS(), static_cast<double>(k * 1'000'000) * 1e-9) << k;
  }
  EXPECT_EQ(task.last().duty_next.left, io::PwmToDuty(io::DutyToPwm(0.5)));
  EXPECT_EQ(task.tracking().samples, 0U);  // no tracking in open loop
}

TEST(EcsTask, SafeOutputsSendZeroDuty) {
  LoneBoard rig;
  const InputProfile full = ParseCsvProfile("time,left,right\n0,1,1\n1,1,1\n", "full.csv");
  EcsTask task(rig.driver, full, rig.geometry, kPeriodNs);
  ASSERT_TRUE(task.Exchange(true).ok());
  ASSERT_EQ(task.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  ASSERT_TRUE(task.Exchange(true).ok());
  EXPECT_EQ(rig.board.pwm_output()[kLeftChannel], io::kPwmValueMax);
  ASSERT_TRUE(task.Exchange(false).ok());
  EXPECT_EQ(rig.board.pwm_output()[kLeftChannel], 0);
  EXPECT_EQ(rig.board.pwm_output()[kRightChannel], 0);
  ASSERT_EQ(task.Step(Cycle(1)).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(task.last().duty_sent.left, 0.0);  // the log says what was really on the wire
}

TEST(EcsTask, APauseStopsTheProfilesClockInsteadOfSkippingPartOfIt) {
  LoneBoard rig;
  const InputProfile ramp = ParseCsvProfile("time,left,right\n0,0,0\n1,1,-1\n", "ramp.csv");
  EcsTask task(rig.driver, ramp, rig.geometry, kPeriodNs);
  for (std::uint64_t k = 0; k < 10; ++k) {
    ASSERT_TRUE(task.Exchange(true).ok());
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
  }
  for (int paused = 0; paused < 5; ++paused) ASSERT_TRUE(task.Exchange(false).ok());  // 10..14
  ASSERT_TRUE(task.Exchange(true).ok());
  ASSERT_EQ(task.Step(Cycle(15)).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(task.LogTimeS(), 10e-3);  // the 11th step of the profile, not the 16th
  EXPECT_EQ(task.last().duty_next.left, io::PwmToDuty(io::DutyToPwm(11e-3)));
}

TEST(EcsTask, ClosedLoopDrivesEachWheelOnItsOwnChannel) {
  LoneBoard rig;
  const SetpointProfile setpoints =
      ParseCsvSetpoints("time,left_m,right_m\n0,0.01,-0.01\n1,0.01,-0.01\n", "sp.csv");
  EcsTask task(rig.driver, setpoints, POnly(10.0), rig.geometry, kPeriodNs);
  ASSERT_TRUE(task.Exchange(true).ok());
  ASSERT_EQ(task.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  ASSERT_TRUE(task.Exchange(true).ok());
  // The setpoint is taken on the encoder grid: 0.01 m is 127.3 counts, so 127 counts.
  const double counts_per_m = io::CountsPerMetre(rig.geometry);
  const double on_grid_m = 127.0 / counts_per_m;
  EXPECT_EQ(std::lround(0.01 * counts_per_m), 127);
  EXPECT_EQ(rig.board.pwm_output()[kLeftChannel], io::DutyToPwm(10.0 * on_grid_m));
  EXPECT_EQ(rig.board.pwm_output()[kRightChannel], io::DutyToPwm(-10.0 * on_grid_m));
  EXPECT_EQ(rig.board.pwm_output()[kLeftChannel], 204);
  EXPECT_EQ(rig.board.pwm_output()[2], 0);       // channels 3 and 4 are not the RELbot's
  EXPECT_EQ(task.last().setpoint.left_m, 0.01);  // logged as the profile gives it
}

// The telemetry record carries the profile's setpoint (as logged, not the PID's grid value)
// in closed loop, and none in open loop; the wheels stay the measured travel.
TEST(EcsTask, TelemetryCarriesTheSetpointInClosedLoopOnly) {
  LoneBoard rig;
  const SetpointProfile setpoints =
      ParseCsvSetpoints("time,left_m,right_m\n0,0,0\n1,0.5,-1\n", "sp.csv");
  EcsTask closed(rig.driver, setpoints, POnly(10.0), rig.geometry, kPeriodNs);
  for (std::uint64_t k = 0; k <= 250; ++k) {
    ASSERT_TRUE(closed.Exchange(true).ok());
    ASSERT_EQ(closed.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
  }
  runtime::TaskTelemetry t;
  closed.FillTelemetry(t);
  EXPECT_TRUE(t.has_setpoint);
  EXPECT_EQ(t.joint_setpoint_m[0], setpoints.At(0.25).left_m);
  EXPECT_EQ(t.joint_setpoint_m[1], setpoints.At(0.25).right_m);
  EXPECT_EQ(t.joint_setpoint_m[0], closed.last().setpoint.left_m);
  EXPECT_EQ(t.joint_position_m[0], 0.0);  // measured: nothing moves the wheels here
  const InputProfile duties = OpenLoopProfile();
  EcsTask open(rig.driver, duties, rig.geometry, kPeriodNs);
  ASSERT_TRUE(open.Exchange(true).ok());
  ASSERT_EQ(open.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  runtime::TaskTelemetry u;
  open.FillTelemetry(u);
  EXPECT_FALSE(u.has_setpoint);
  EXPECT_EQ(u.joint_count, 2U);
}

TEST(EcsTask, TrackingStatsCoverEveryStep) {
  LoneBoard rig;
  // The wheels never move (nothing behind the board): the error is the setpoint itself.
  const SetpointProfile setpoints =
      ParseCsvSetpoints("time,left_m,right_m\n0,0,0\n0.1,0.002,-0.001\n", "sp.csv");
  EcsTask task(rig.driver, setpoints, POnly(1000.0), rig.geometry, kPeriodNs);
  double sum_sq = 0.0;
  for (std::uint64_t k = 0; k < 200; ++k) {
    ASSERT_TRUE(task.Exchange(true).ok());
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
    const WheelPositions sp = setpoints.At(static_cast<double>(k) * 1e-3);
    sum_sq += sp.left_m * sp.left_m + sp.right_m * sp.right_m;
  }
  const TrackingStats stats = task.tracking();
  EXPECT_EQ(stats.samples, 200U);
  EXPECT_EQ(stats.max_abs_error_left_m, 0.002);
  EXPECT_EQ(stats.max_abs_error_right_m, 0.001);
  EXPECT_EQ(stats.final_error_left_m, 0.002);  // the profile holds its last setpoint
  EXPECT_EQ(stats.final_error_right_m, -0.001);
  EXPECT_NEAR(stats.rms_error_m, std::sqrt(sum_sq / 400.0), 1e-15);
  EXPECT_GT(stats.rms_error_left_m, stats.rms_error_right_m);
  // kp · error > 1 duty once the left setpoint's grid value passes 1 mm: at 50 ms the setpoint
  // is 1 mm = 12.7 counts, taken as 13 (1.02 mm); at 49 ms 12 counts (0.94 mm).
  EXPECT_EQ(stats.saturated_cycles, 150U);
  EXPECT_EQ(stats.max_abs_duty, 1.0);
}

TEST(EcsTask, ThePidsSaturationIsAtItsOwnLimitNotTheMaps) {
  // --gains may limit the PID below the controller map's duty_limit (1): the PID's own
  // saturation counts, as it did before controllers were pluggable.
  LoneBoard rig;
  const SetpointProfile setpoints =
      ParseCsvSetpoints("time,left_m,right_m\n0,0,0\n0.1,0.002,-0.001\n", "sp.csv");
  PidGains gains = POnly(1000.0);
  gains.duty_limit = 0.5;
  EcsTask task(rig.driver, setpoints, gains, rig.geometry, kPeriodNs);
  // The oracle: the same PIDs on the same inputs (the wheels never move; the setpoints on the
  // encoder grid).
  PositionPid left(gains, 1e-3);
  PositionPid right(gains, 1e-3);
  const double counts_per_m = io::CountsPerMetre(rig.geometry);
  const auto grid = [counts_per_m](double m) {
    return static_cast<double>(std::llround(m * counts_per_m)) / counts_per_m;
  };
  std::uint64_t saturated = 0;
  for (std::uint64_t k = 0; k < 200; ++k) {
    ASSERT_TRUE(task.Exchange(true).ok());
    ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
    const WheelPositions sp = setpoints.At(static_cast<double>(k) * 1e-3);
    static_cast<void>(left.Step(grid(sp.left_m), 0.0));
    static_cast<void>(right.Step(grid(sp.right_m), 0.0));
    saturated += left.last().saturated || right.last().saturated ? 1U : 0U;
  }
  EXPECT_EQ(task.tracking().saturated_cycles, saturated);
  EXPECT_GT(saturated, 150U);  // more than at the limit 1 (TrackingStatsCoverEveryStep)
  EXPECT_EQ(task.tracking().max_abs_duty, 0.5);
}

TEST(EcsTask, TheFirstReadingIsTheOriginOfTheSetpoints) {
  // A real robot's encoders power up anywhere: the ECS measures travel from the reading of its
  // first step, and a frame that never arrived is no reading. A twin board moves the lines
  // while the task exchanges without stepping.
  io::EmulatedFpga twin_board{io::Image::kIcoboardInverse};
  io::EmulatedFpga ecs_board{io::Image::kIcoboard};
  io::EmulatorToReaderLink lines{twin_board};
  ecs_board.SetEncoderSource(&lines);
  io::EmulatedSpiBus twin_bus{twin_board};
  io::EmulatedSpiBus ecs_bus{ecs_board};
  io::IcoBoardInverse twin{twin_bus};
  io::IcoBoard ecs{ecs_bus};
  ASSERT_TRUE(twin.Init(250'000).ok);
  ASSERT_TRUE(ecs.Init(kPeriodNs).ok);
  io::TwinInputs twin_in;
  std::int32_t position = 0;
  std::uint64_t twin_frames = 0;
  auto twin_until = [&](std::uint64_t ecs_frame, std::int32_t counts_per_frame) {
    for (; twin_frames < 4 * ecs_frame; ++twin_frames) {
      position += counts_per_frame;
      ASSERT_TRUE(twin.Exchange({0, position, 0, 0}, twin_in).ok());  // channel 2: left
    }
  };
  const SetpointProfile setpoints = ClosedLoopProfile();
  EcsTask task(ecs, setpoints, DefaultEcsGains(), WheelGeometryOf(DefaultRelbotParams()),
               kPeriodNs);
  ecs_board.faults().drop_answers = 1;
  EXPECT_FALSE(task.Exchange(true).ok());  // frame 0 lost: the counts are not a reading
  ASSERT_EQ(task.Step(Cycle(0)).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(task.last().counts[0], 0);
  // The twin moves 40 counts per ECS period; the ECS steps next at cycle 5, having read
  // 5 x 40 = 200 counts (the twin's periods up to 5 ms are complete on the lines by then).
  for (std::uint64_t k = 1; k <= 10; ++k) {
    twin_until(k, 10);
    ASSERT_TRUE(task.Exchange(true).ok());
    if (k == 5) {
      EXPECT_EQ(task.inputs().absolute_counts[kLeftChannel], 200);
      ASSERT_EQ(task.Step(Cycle(k)).code, runtime::StepStatus::Code::kOk);
      EXPECT_EQ(task.last().counts[0], 0);  // the origin
    }
  }
  EXPECT_EQ(task.inputs().absolute_counts[kLeftChannel], 400);
  ASSERT_EQ(task.Step(Cycle(10)).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(task.last().counts[0], 200);
  EXPECT_EQ(task.last().counts[1], 0);  // the right wheel never moved
  EXPECT_EQ(task.last().measured.left_m,
            io::CountsToMetres(200, WheelGeometryOf(DefaultRelbotParams())));
}

TEST(EcsTask, ASessionPeriodOtherThanTheTasksIsAFault) {
  LoneBoard rig;
  const SetpointProfile setpoints = ClosedLoopProfile();
  EcsTask task(rig.driver, setpoints, DefaultEcsGains(), rig.geometry, kPeriodNs);
  const runtime::StepStatus status = task.Step(Cycle(0, 2 * kPeriodNs));
  EXPECT_EQ(status.code, runtime::StepStatus::Code::kModelFault);
  EXPECT_NE(std::string(status.reason).find("period"), std::string::npos);
}

TEST(EcsTask, BadConfigurationIsRefusedAtConstruction) {
  LoneBoard rig;
  const SetpointProfile setpoints = ClosedLoopProfile();
  EXPECT_THROW(EcsTask(rig.driver, setpoints, DefaultEcsGains(), rig.geometry, 0),
               std::invalid_argument);
  PidGains negative = DefaultEcsGains();
  negative.kp_duty_per_m = -1.0;
  EXPECT_THROW(EcsTask(rig.driver, setpoints, negative, rig.geometry, kPeriodNs), ConfigError);
}

TEST(EcsTask, LogColumnsAndLengthPerMode) {
  LoneBoard rig;
  const SetpointProfile setpoints = ClosedLoopProfile();
  const InputProfile duties = OpenLoopProfile();
  EcsTask closed(rig.driver, setpoints, DefaultEcsGains(), rig.geometry, kPeriodNs);
  EcsTask open(rig.driver, duties, rig.geometry, kPeriodNs);
  EXPECT_EQ(closed.LogColumns(),
            (std::vector<std::string>{"setpoint_left_m", "setpoint_right_m", "wheel_left_m",
                                      "wheel_right_m", "error_left_m", "error_right_m", "duty_left",
                                      "duty_right", "enc_left", "enc_right"}));
  EXPECT_EQ(open.LogColumns(),
            (std::vector<std::string>{"duty_left", "duty_right", "wheel_left_m", "wheel_right_m",
                                      "enc_left", "enc_right"}));
  EXPECT_EQ(closed.length_s(), 12.0);
  EXPECT_EQ(open.length_s(), 36.0);

  ASSERT_TRUE(closed.Exchange(true).ok());
  ASSERT_EQ(closed.Step(Cycle(2000)).code, runtime::StepStatus::Code::kOk);  // mid-move
  std::vector<double> row(closed.LogColumns().size(), -1.0);
  closed.FillLogRow(row);
  const WheelPositions sp = setpoints.At(2.0);
  EXPECT_EQ(row[0], sp.left_m);
  EXPECT_EQ(row[2], 0.0);        // the wheel has not moved
  EXPECT_EQ(row[4], sp.left_m);  // error
  EXPECT_EQ(row[8], 0.0);        // counts since the first step
}

}  // namespace
}  // namespace hiltwin::app
