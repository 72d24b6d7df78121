// The generic twin task: a fake plant behind an emulated icoboard_inverse board, so every value
// the task routes, scales and logs can be computed by hand.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "fake_plant.h"
#include "fakes/alloc_counter.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/plant/plant_twin_task.h"

namespace hiltwin::plant {
namespace {

using test::FakePlant;

constexpr std::int64_t kPeriodNs = 1'000'000;  // 1 kHz

/// The duties a controller would write, held constant.
class ConstantPwm final : public io::PwmSignalSource {
 public:
  explicit ConstantPwm(std::array<double, io::kChannels> duty) : duty_(duty) {}
  void DutyAt(std::int64_t, std::array<double, io::kChannels>& out) noexcept override {
    out = duty_;
  }

 private:
  std::array<double, io::kChannels> duty_;
};

// Channel 3 drives "u" with gain 4; channel 2 follows "x" at 1000 counts per metre; channel 1
// follows "x" again, reversed, as a joint of radius 0.5 m.
constexpr const char* kMap = R"(
[[pwm]]
channel = 3
input = "u"
gain = 4.0
[[encoder]]
channel = 2
output = "x"
unit = "m"
counts_per_unit = 1000
[[encoder]]
channel = 1
output = "x"
unit = "m"
counts_per_unit = 1000
reverse = true
column = "enc_mirror"
joint = "drum_joint"
wheel_radius_m = 0.5
[inputs]
bias = 0.25
[telemetry]
pose = ["x", "v", "x"]
)";

struct Rig {
  explicit Rig(double initial = 0.0, std::array<double, io::kChannels> duty = {0, 0, 0.5, 0})
      : pwm(duty), plant({{"u", "1"}, {"bias", "1"}}, {{"x", "m"}, {"v", "m/s"}}) {
    board.SetPwmSource(&pwm);
    EXPECT_TRUE(driver.Init(kPeriodNs).ok);
    plant.initial = initial;
    plant.slope = 0.001;  // 1 mm per step on top of gain * u
    std::vector<double> y0(2, 0.0);
    plant.Start(1e-3, y0);
    task.emplace(driver, plant, BindPlantMap(ParsePlantMap(kMap, "map.toml"), plant), 1e-3, y0);
  }
  runtime::StepStatus Cycle(std::uint64_t k) {
    EXPECT_TRUE(task->Exchange(true).ok());
    scheduler::CycleContext context;
    context.cycle = k;
    context.period_ns = kPeriodNs;
    return task->Step(context);
  }

  ConstantPwm pwm;
  io::EmulatedFpga board{io::Image::kIcoboardInverse};
  io::EmulatedSpiBus bus{board};
  io::IcoBoardInverse driver{bus};
  FakePlant plant;
  std::optional<PlantTwinTask> task;
};

TEST(PlantTwinTask, RoutesDutyThroughTheGainAndOutputsIntoCounts) {
  Rig rig;
  for (std::uint64_t k = 0; k < 10; ++k) ASSERT_EQ(rig.Cycle(k).code, runtime::StepStatus::Code::kOk);
  // The board reads duty 0.5 exactly (an 11-bit reader value of 1024): u = 4 * 0.5.
  EXPECT_EQ(rig.task->inputs()[0], 2.0);
  EXPECT_EQ(rig.task->inputs()[1], 0.25);  // [inputs] bias, held
  const double x = 1.0 * 2.0 + 0.001 * 10;  // gain * u + slope * steps
  EXPECT_DOUBLE_EQ(rig.task->outputs()[0], x);
  EXPECT_EQ(rig.task->encoder_next()[1], static_cast<std::int32_t>(std::floor(x * 1000.0)));
  EXPECT_EQ(rig.task->encoder_next()[0], static_cast<std::int32_t>(std::floor(-x * 1000.0)));
  EXPECT_EQ(rig.task->steps(), 10U);
  EXPECT_DOUBLE_EQ(rig.task->LogTimeS(), 0.010);
}

TEST(PlantTwinTask, EncodersCountFromThePlantsInitialOutputs) {
  Rig rig(/*initial=*/0.1, {0, 0, 0, 0});
  EXPECT_EQ(rig.task->encoder_next()[1], 0);  // 0.1 m at start is count 0, as on a real encoder
  ASSERT_EQ(rig.Cycle(0).code, runtime::StepStatus::Code::kOk);
  const double travel_m = 0.001;  // one step of slope
  EXPECT_EQ(rig.task->encoder_next()[1],
            io::ValueToCounts(0.1 + travel_m, 1000.0) - io::ValueToCounts(0.1, 1000.0));
}

TEST(PlantTwinTask, LogsThePlantsPortNamesThenTheEncoderColumns) {
  Rig rig;
  ASSERT_EQ(rig.Cycle(0).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(rig.task->LogColumns(),
            (std::vector<std::string>{"u", "bias", "x", "v", "enc2", "enc_mirror"}));
  std::array<double, 6> row{};
  rig.task->FillLogRow(row);
  const double x = 2.0 + 0.001;
  EXPECT_EQ(row[0], 2.0);
  EXPECT_EQ(row[1], 0.25);
  EXPECT_DOUBLE_EQ(row[2], x);
  EXPECT_EQ(row[4], std::floor(x * 1000.0));
  EXPECT_EQ(row[5], std::floor(-x * 1000.0));
}

TEST(PlantTwinTask, PublishesThePoseAndJointsTheMapNames) {
  Rig rig;
  ASSERT_EQ(rig.Cycle(0).code, runtime::StepStatus::Code::kOk);
  const runtime::TelemetryShape shape = rig.task->TelemetryShapeOf();
  EXPECT_EQ(shape.role, "twin");
  EXPECT_TRUE(shape.has_pose);
  EXPECT_EQ(shape.joint_names, std::vector<std::string>{"drum_joint"});
  runtime::TaskTelemetry t;
  rig.task->FillTelemetry(t);
  const double x = 2.0 + 0.001;
  EXPECT_DOUBLE_EQ(t.x_m, x);
  EXPECT_DOUBLE_EQ(t.y_m, 0.25 + 0.001);  // "v" follows the second input, bias
  ASSERT_EQ(t.joint_count, 1);
  EXPECT_DOUBLE_EQ(t.joint_position_m[0], x);
  EXPECT_DOUBLE_EQ(t.joint_position_rad[0], x / 0.5);
}

TEST(PlantTwinTask, FaultsFinishesAndNonFiniteOutputsBecomeStepStatuses) {
  Rig faulty;
  faulty.plant.fault_at = 3;
  EXPECT_EQ(faulty.Cycle(0).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(faulty.Cycle(1).code, runtime::StepStatus::Code::kOk);
  const runtime::StepStatus fault = faulty.Cycle(2);
  EXPECT_EQ(fault.code, runtime::StepStatus::Code::kModelFault);
  EXPECT_STREQ(fault.reason, "the fake plant failed");
  Rig finishing;
  finishing.plant.finish_at = 2;
  EXPECT_EQ(finishing.Cycle(0).code, runtime::StepStatus::Code::kOk);
  EXPECT_EQ(finishing.Cycle(1).code, runtime::StepStatus::Code::kFinished);
  Rig nan;
  nan.plant.nan_at = 1;
  const runtime::StepStatus diverged = nan.Cycle(0);
  EXPECT_EQ(diverged.code, runtime::StepStatus::Code::kModelFault);
  EXPECT_THAT(diverged.reason, ::testing::HasSubstr("non-finite"));
  EXPECT_EQ(nan.task->encoder_next()[1], 0);  // no count computed from a NaN
}

// Every non-finite value (either infinity, quiet and signalling NaNs of either sign, any
// payload) in any output, routed to an encoder or not, is a model fault; the finite extremes
// of an output no encoder follows (its largest, smallest, denormal, signed zero) are not.
TEST(PlantTwinTask, EveryNonFiniteOutputAndNoFiniteOneIsAFault) {
  using Limits = std::numeric_limits<double>;
  const double payload_nan = std::bit_cast<double>(std::uint64_t{0x7ff0'0000'0000'0001});
  const double negative_nan = std::bit_cast<double>(std::uint64_t{0xfff8'0000'0000'0000});
  for (const std::size_t index : {std::size_t{0}, std::size_t{1}}) {
    for (const double bad : {Limits::infinity(), -Limits::infinity(), Limits::quiet_NaN(),
                             Limits::signaling_NaN(), payload_nan, negative_nan}) {
      Rig rig;
      rig.plant.nan_at = 2;
      rig.plant.nan_index = index;
      rig.plant.nan_value = bad;
      EXPECT_EQ(rig.Cycle(0).code, runtime::StepStatus::Code::kOk);
      const runtime::StepStatus status = rig.Cycle(1);
      EXPECT_EQ(status.code, runtime::StepStatus::Code::kModelFault) << index << " " << bad;
      EXPECT_THAT(status.reason, ::testing::HasSubstr("non-finite")) << index << " " << bad;
    }
  }
  for (const double fine : {Limits::max(), -Limits::max(), Limits::min(), Limits::denorm_min(),
                            -Limits::denorm_min(), -0.0, 1e300}) {
    Rig rig;
    rig.plant.nan_at = 1;
    rig.plant.nan_index = 1;  // "v": no encoder follows it, so no count can be out of range
    rig.plant.nan_value = fine;
    EXPECT_EQ(rig.Cycle(0).code, runtime::StepStatus::Code::kOk) << fine;
  }
}

// The board represents a change of less than half an encoder turn (8192 counts) per period;
// more aliases into a change the other way. 10 m per step at 1000 counts per metre is a model
// fault naming the channel, not counts the ECS misreads (it ran and passed before).
TEST(PlantTwinTask, AChangeOfHalfAnEncoderTurnInOnePeriodIsAModelFault) {
  Rig fast(/*initial=*/0.0, {0, 0, 0, 0});
  fast.plant.slope = 10.0;
  const runtime::StepStatus status = fast.Cycle(0);
  EXPECT_EQ(status.code, runtime::StepStatus::Code::kModelFault);
  EXPECT_STREQ(status.reason,
               "encoder channel 2: the plant's output moved by half an encoder turn (8192 counts) "
               "or more in one period, which the board cannot represent: lower the map's "
               "counts_per_unit or raise --rate");
  Rig slow(/*initial=*/0.0, {0, 0, 0, 0});
  slow.plant.slope = 8.0;  // 8000 counts per step: just inside
  EXPECT_EQ(slow.Cycle(0).code, runtime::StepStatus::Code::kOk);
}

// Counts of a finite output that leave what the twin holds (here 1e300 m at 1000 counts per
// metre) are a model fault: they were clamped, and the encoder read 0 all run.
TEST(PlantTwinTask, CountsBeyondWhatTheTwinHoldsAreAModelFault) {
  Rig far(/*initial=*/1e300, {0, 0, 0, 0});
  const runtime::StepStatus status = far.Cycle(0);
  EXPECT_EQ(status.code, runtime::StepStatus::Code::kModelFault);
  EXPECT_STREQ(status.reason,
               "encoder channel 2: the plant's output times counts_per_unit is beyond +-2^62 "
               "counts (or not finite), which no encoder counts: check the map's scale and the "
               "plant's output");
}

TEST(PlantTwinTask, SafeExchangesRepeatTheLastCountsSent) {
  Rig rig;
  for (std::uint64_t k = 0; k < 5; ++k) ASSERT_EQ(rig.Cycle(k).code, runtime::StepStatus::Code::kOk);
  ASSERT_TRUE(rig.task->Exchange(true).ok());
  const auto sent = rig.task->encoder_sent();
  scheduler::CycleContext context;
  ASSERT_EQ(rig.task->Step(context).code, runtime::StepStatus::Code::kOk);
  ASSERT_TRUE(rig.task->Exchange(false).ok());  // paused: the new step's counts stay home
  EXPECT_EQ(rig.task->encoder_sent(), sent);
  EXPECT_NE(rig.task->encoder_next(), sent);
}

TEST(PlantTwinTask, TheCyclePathAllocatesNothing) {
  Rig rig;
  std::array<double, 6> row{};
  runtime::TaskTelemetry telemetry;
  hiltwin::test::ScopedAllocationCount count;
  for (std::uint64_t k = 0; k < 20'000; ++k) {
    static_cast<void>(rig.Cycle(k));
    rig.task->FillLogRow(row);
    rig.task->FillTelemetry(telemetry);
  }
  EXPECT_EQ(count.count(), 0U);
}

}  // namespace
}  // namespace hiltwin::plant
