// Which board channel is which wheel (thesis appendix G: board channel 1 = index 0 = right
// wheel, channel 2 = index 1 = left wheel), proven through the whole board path: an ECS driver
// writes PWM on one channel of its board; the ECS board's PWM generator drives the twin board's
// PWM reader; the RELbot twin task reads it through its IcoBoardInverse driver, steps the RELbot and sends
// the wheel positions; the twin board's encoder emulator pulses them to the ECS board's
// quadrature readers, and the ECS driver reads the counts back. With the frames of
// docs/relbot-model.md (X forward, Y left, θ counter-clockwise) a lone right wheel turns the
// robot left and a lone left wheel turns it right. A swapped mapping anywhere fails these tests.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/relbot/relbot_channels.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/relbot_twin.h"

namespace hiltwin::app {
namespace {

constexpr std::int64_t kStepNs = 250'000;  // 4 kHz, the thesis's preferred twin rate
constexpr std::uint64_t kChannelCycles = 1'600;   // 0.4 s: less than a quarter turn, so signs are clear
constexpr std::int32_t kPwm = 1400;        // duty 1400/2048 = 0.68 on the one driven channel

/// An ECS board and a twin board wired to each other, each with its own driver; the twin's
/// driver serves the twin task. Both boards count time in data frames since INIT (no clock).
struct HilRig {
  HilRig()
      : params(DefaultRelbotParams()),
        relbot(twin, params, Integrator::kRk4, static_cast<double>(kStepNs) * 1e-9) {
    ecs_board.SetEncoderSource(&lines);
    twin_board.SetPwmSource(&pwm_wires);
    EXPECT_TRUE(ecs.Init(kStepNs).ok);
    EXPECT_TRUE(twin.Init(kStepNs).ok);
  }

  /// One cycle at board time k·step: the ECS writes its PWM (and reads the counts the twin's
  /// emulator finished pulsing by now), then the twin exchanges and steps.
  void Cycle(const std::array<std::int32_t, io::kChannels>& pwm, std::uint64_t k) {
    ASSERT_TRUE(ecs.Exchange(pwm, ecs_in).ok());
    ASSERT_TRUE(relbot.task().Exchange(true).ok());
    const scheduler::CycleContext context{k, 0, kStepNs, static_cast<std::int64_t>(k) * kStepNs};
    ASSERT_TRUE(relbot.task().Step(context).code == runtime::StepStatus::Code::kOk);
  }

  io::EmulatedFpga ecs_board{io::Image::kIcoboard};
  io::EmulatedFpga twin_board{io::Image::kIcoboardInverse};
  io::EmulatorToReaderLink lines{twin_board};
  io::GeneratorToReaderLink pwm_wires{ecs_board};
  io::EmulatedSpiBus ecs_bus{ecs_board};
  io::EmulatedSpiBus twin_bus{twin_board};
  io::IcoBoard ecs{ecs_bus};
  io::IcoBoardInverse twin{twin_bus};
  RelbotParams params;
  RelbotTwin relbot;
  io::EcsInputs ecs_in{};
};

/// What one asymmetric run ended with.
struct DriveResult {
  Duty duty_read;                                  ///< what the twin's model was given, last cycle
  RelbotOutputs halfway;                           ///< outputs after kChannelCycles / 2
  RelbotOutputs end;                               ///< outputs after kChannelCycles
  std::array<std::int32_t, io::kChannels> sent{};  ///< counts the twin sent last, by index
  std::array<std::int64_t, io::kChannels> ecs_read{};  ///< what the ECS decoded from them
};

/// Runs kChannelCycles with PWM `kPwm` on board index `driven` only, then lets the ECS read the last
/// positions the twin sent (two more ECS frames: the emulator pulses each position over the
/// period after it was sent, and the twin's last exchange went out after the last cycle).
DriveResult DriveOneChannel(std::size_t driven) {
  HilRig rig;
  std::array<std::int32_t, io::kChannels> pwm{};
  pwm[driven] = kPwm;
  DriveResult drive;
  for (std::uint64_t k = 0; k < kChannelCycles; ++k) {
    rig.Cycle(pwm, k);
    if (k + 1 == kChannelCycles / 2) drive.halfway = rig.relbot.outputs();
  }
  drive.duty_read = rig.relbot.duty();
  drive.end = rig.relbot.outputs();
  EXPECT_TRUE(rig.relbot.task().Exchange(true).ok());  // the last step's positions go out
  drive.sent = rig.relbot.task().encoder_sent();
  for (int frame = 0; frame < 2; ++frame) EXPECT_TRUE(rig.ecs.Exchange(pwm, rig.ecs_in).ok());
  drive.ecs_read = rig.ecs_in.absolute_counts;
  EXPECT_EQ(rig.ecs_board.encoder_lines().counters().illegal_transitions, 0U);
  EXPECT_EQ(rig.ecs_board.encoder_lines().counters().too_fast_edges, 0U);
  return drive;
}

/// A robot pivoting about one nearly still wheel: θ = (s_r − s_l) / b, and the centre of mass
/// (on the axle, b/2 from the pivot) at x = (b/2) sin|θ|, y = (b/2)(1 − cos θ) with the sign of θ.
/// The tolerances leave room for the tyres' side slip and the castor's drag.
void ExpectPivotTurn(const RelbotOutputs& out) {
  const double half_track_m = DefaultRelbotParams().track_width_m / 2.0;
  const double theta = (out.wheel_right_m - out.wheel_left_m) / (2.0 * half_track_m);
  EXPECT_NEAR(out.theta_rad, theta, 0.02 * std::abs(theta));
  EXPECT_GT(std::abs(out.theta_rad), 0.5);
  EXPECT_LT(std::abs(out.theta_rad), 1.5);  // less than a quarter turn: the signs of x, y hold
  EXPECT_NEAR(out.x_m, half_track_m * std::sin(std::abs(out.theta_rad)), 0.005);
  EXPECT_NEAR(out.y_m, std::copysign(half_track_m * (1.0 - std::cos(out.theta_rad)), out.theta_rad),
              0.005);
  EXPECT_GT(out.x_m, 0.05);  // moved forward
}

std::int64_t Counts(double metres) {
  return io::MetresToCounts(metres, WheelGeometryOf(DefaultRelbotParams()));
}

TEST(WheelChannels, PwmOnBoardChannelOneDrivesTheRightWheelAndTurnsLeft) {
  const DriveResult d = DriveOneChannel(0);
  // The reader measures 1400 exactly (2800 of 4096 clocks high, halved): duty 1400/2048.
  EXPECT_EQ(d.duty_read.right, 1400.0 / 2048.0);
  EXPECT_EQ(d.duty_read.left, 0.0);
  // The right wheel drives and keeps going; the unpowered left wheel's motor brakes it, so it
  // stays within a few millimetres while the right one covers about 0.2 m.
  EXPECT_GT(d.halfway.wheel_right_m, 0.05);
  EXPECT_GT(d.end.wheel_right_m, d.halfway.wheel_right_m + 0.08);
  EXPECT_LT(std::abs(d.end.wheel_left_m), 0.01 * d.end.wheel_right_m);
  // Right wheel faster: counter-clockwise (θ > 0), forward and to the left (y > 0).
  ExpectPivotTurn(d.end);
  EXPECT_GT(d.end.theta_rad, 0.5);
  EXPECT_GT(d.end.y_m, 0.03);
  // Index 0 carries the right wheel's counts, index 1 the left's, and the ECS decodes them.
  EXPECT_EQ(d.sent[kRightChannel], Counts(d.end.wheel_right_m));
  EXPECT_EQ(d.sent[kLeftChannel], Counts(d.end.wheel_left_m));
  EXPECT_GT(d.sent[0], 2'000);  // about 12 732 counts/m
  EXPECT_EQ(d.ecs_read[0], d.sent[0]);
  EXPECT_EQ(d.ecs_read[1], d.sent[1]);
  EXPECT_LT(std::abs(d.ecs_read[1]), d.ecs_read[0] / 50);
  EXPECT_EQ(d.ecs_read[2], 0);
  EXPECT_EQ(d.ecs_read[3], 0);
}

TEST(WheelChannels, PwmOnBoardChannelTwoDrivesTheLeftWheelAndTurnsRight) {
  const DriveResult d = DriveOneChannel(1);
  EXPECT_EQ(d.duty_read.left, 1400.0 / 2048.0);
  EXPECT_EQ(d.duty_read.right, 0.0);
  EXPECT_GT(d.halfway.wheel_left_m, 0.05);
  EXPECT_GT(d.end.wheel_left_m, d.halfway.wheel_left_m + 0.08);
  EXPECT_LT(std::abs(d.end.wheel_right_m), 0.01 * d.end.wheel_left_m);
  // Left wheel faster: clockwise (θ < 0), forward and to the right (y < 0).
  ExpectPivotTurn(d.end);
  EXPECT_LT(d.end.theta_rad, -0.5);
  EXPECT_LT(d.end.y_m, -0.03);
  EXPECT_EQ(d.sent[kLeftChannel], Counts(d.end.wheel_left_m));
  EXPECT_EQ(d.sent[kRightChannel], Counts(d.end.wheel_right_m));
  EXPECT_GT(d.sent[1], 2'000);
  EXPECT_EQ(d.ecs_read[1], d.sent[1]);
  EXPECT_EQ(d.ecs_read[0], d.sent[0]);
  EXPECT_LT(std::abs(d.ecs_read[0]), d.ecs_read[1] / 50);
}

TEST(WheelChannels, TheMappingIsAppendixG) {
  // Board channel n is index n - 1: channel 1 (appendix G's `channel1`, `enc1`) is the right
  // wheel, channel 2 (`channel2`, `enc2`) the left.
  EXPECT_EQ(kRightChannel, 0U);
  EXPECT_EQ(kLeftChannel, 1U);
}

}  // namespace
}  // namespace hiltwin::app
