// The RELbot as a plant: the same numbers through the plant interface as from the model
// directly, its shipped plant map equal to the built-in one, and --plant's errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fakes/test_paths.h"
#include "hiltwin/plant/plant_registry.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/twin_build.h"

namespace hiltwin::app {
namespace {

using ::testing::HasSubstr;

TEST(RelbotPlant, StepsExactlyAsTheModelDoes) {
  const RelbotParams params = DefaultRelbotParams();
  RelbotPlant plant(params, Integrator::kRk4);
  RelbotModel model(params, Integrator::kRk4, 2.5e-4);
  std::array<double, 5> y{};
  plant.Start(2.5e-4, y);
  EXPECT_EQ(y, (std::array<double, 5>{}));
  for (int k = 0; k < 4000; ++k) {
    const double left = 0.8 * std::sin(k * 1e-3);
    const double right = 0.5;
    const std::array<double, 2> u{left, right};
    ASSERT_TRUE(plant.Step(u, y).ok());
    model.Step(left, right);
  }
  const RelbotOutputs direct = model.Outputs();
  EXPECT_EQ(y[relbot_port::kWheelLeftM], direct.wheel_left_m);  // bit for bit
  EXPECT_EQ(y[relbot_port::kWheelRightM], direct.wheel_right_m);
  EXPECT_EQ(y[relbot_port::kXM], direct.x_m);
  EXPECT_EQ(y[relbot_port::kYM], direct.y_m);
  EXPECT_EQ(y[relbot_port::kThetaRad], direct.theta_rad);
  plant.Reset(y);
  EXPECT_EQ(y, (std::array<double, 5>{}));
}

TEST(RelbotPlant, DescribesItsPortsWithUnits) {
  const RelbotPlant plant(DefaultRelbotParams(), Integrator::kRk2);
  const plant::PlantInfo& info = plant.Info();
  ASSERT_EQ(info.inputs.size(), 2U);
  EXPECT_EQ(info.inputs[relbot_port::kDutyLeft].name, "duty_left");
  ASSERT_EQ(info.outputs.size(), 5U);
  EXPECT_EQ(info.outputs[relbot_port::kThetaRad].name, "theta_rad");
  EXPECT_EQ(info.outputs[relbot_port::kThetaRad].unit, "rad");
  EXPECT_EQ(info.details.at(0), (std::pair<std::string, std::string>{"integrator", "rk2"}));
}

TEST(RelbotPlant, AStepTheIntegratorCannotHoldIsAPlantError) {
  RelbotPlant plant(DefaultRelbotParams(), Integrator::kEuler);
  std::array<double, 5> y{};
  EXPECT_THROW(plant.Start(0.05, y), plant::PlantError);
}

TEST(RelbotPlant, TheShippedMapIsTheBuiltInOne) {
  const RelbotParams params = LoadRelbotParams(HILTWIN_RELBOT_TOML);
  const RelbotPlant plant(params, Integrator::kRk4);
  const plant::BoundPlantMap shipped =
      plant::BindPlantMap(plant::LoadPlantMap(HILTWIN_RELBOT_MAP_TOML), plant);
  const plant::BoundPlantMap built_in = plant::BindPlantMap(RelbotDefaultMap(params), plant);
  ASSERT_EQ(shipped.pwm.size(), built_in.pwm.size());
  for (std::size_t i = 0; i < shipped.pwm.size(); ++i) {
    EXPECT_EQ(shipped.pwm[i].channel_index, built_in.pwm[i].channel_index);
    EXPECT_EQ(shipped.pwm[i].input_index, built_in.pwm[i].input_index);
    EXPECT_EQ(shipped.pwm[i].gain, built_in.pwm[i].gain);
  }
  ASSERT_EQ(shipped.encoders.size(), built_in.encoders.size());
  for (std::size_t i = 0; i < shipped.encoders.size(); ++i) {
    EXPECT_EQ(shipped.encoders[i].channel_index, built_in.encoders[i].channel_index);
    EXPECT_EQ(shipped.encoders[i].output_index, built_in.encoders[i].output_index);
    EXPECT_NEAR(shipped.encoders[i].counts_per_unit, built_in.encoders[i].counts_per_unit,
                1e-12 * built_in.encoders[i].counts_per_unit);
  }
  EXPECT_EQ(shipped.encoder_columns, built_in.encoder_columns);
  EXPECT_EQ(shipped.joint_names, built_in.joint_names);
  EXPECT_EQ(shipped.pose, built_in.pose);
  // Appendix G: channel 2 is the left wheel, channel 1 the right.
  EXPECT_EQ(built_in.pwm[0].channel_index, 1U);
  EXPECT_EQ(built_in.encoder_columns, (std::vector<std::string>{"enc_left", "enc_right"}));
}

std::string PlantUsageError(const TwinRunOptions& o) {
  try {
    static_cast<void>(MakeTwinPlant(o));
  } catch (const CommandError& e) {
    EXPECT_EQ(e.code(), ExitCode::kUsage);
    return e.what();
  }
  return "no error";
}

TEST(TwinPlant, ThePlantFlagsErrorsSayWhatExists) {
  TwinRunOptions o;
  o.plant = "nope";
  EXPECT_THAT(PlantUsageError(o), AllOf(HasSubstr("--plant nope: no such plant"),
                                        HasSubstr("relbot: "), HasSubstr("fmu:PATH.fmu")));
  o.plant = "relbot";
  o.integrator = "rk5";
  EXPECT_THAT(PlantUsageError(o), AllOf(HasSubstr("--plant relbot"), HasSubstr("rk5")));
  o.integrator.clear();
  o.plant_map_path = "/nonexistent/map.toml";
  EXPECT_THAT(PlantUsageError(o), AllOf(HasSubstr("--plant-map"), HasSubstr("/nonexistent")));
}

TEST(TwinPlant, TheRelbotIsRegisteredWithItsOwnMap) {
  TwinRunOptions o;
  const TwinPlant made = MakeTwinPlant(o);
  EXPECT_EQ(made.plant->Info().name, "relbot");
  EXPECT_EQ(made.map.source, "the built-in map of relbot");
  ASSERT_NE(plant::FindPlant("relbot"), nullptr);
}

}  // namespace
}  // namespace hiltwin::app
