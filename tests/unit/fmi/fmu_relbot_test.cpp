// relbot.fmu (tests/fmus/relbot_model.c, the FMU hiltwin_bench_fmi_loop measures as a plant-sized
// step) against the built-in RELbot model it copies: the same ports, the same trajectory.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "hiltwin/fmi/fmu_plant.h"
#include "hiltwin/relbot/relbot_model.h"
#include "test_fmus.h"

namespace hiltwin::fmi {
namespace {

constexpr double kTwinStepS = 1.0 / 4000.0;  // the twin's rate

TEST(FmuRelbot, PortsAreTheBuiltInRelbotsPorts) {
  const auto plant = OpenFmu(test::TestFmu("relbot"));
  const plant::PlantInfo& info = plant->Info();
  ASSERT_EQ(info.inputs.size(), 2U);
  EXPECT_EQ(info.inputs[0].name, "duty_left");
  EXPECT_EQ(info.inputs[1].name, "duty_right");
  const std::array<const char*, 5> outputs{"wheel_left_m", "wheel_right_m", "x_m", "y_m",
                                           "theta_rad"};
  ASSERT_EQ(info.outputs.size(), outputs.size());
  for (std::size_t i = 0; i < outputs.size(); ++i) EXPECT_EQ(info.outputs[i].name, outputs[i]);
}

// Duties that drive straight, turn both ways, reverse, saturate and carry a NaN (motor off).
std::array<double, 2> RelbotDutiesAt(int k) {
  switch ((k / 1000) % 6) {
    case 0: return {0.5, 0.5};
    case 1: return {0.5, 0.25};
    case 2: return {-0.75, 0.125};
    case 3: return {1.5, -2.0};
    case 4: return {std::numeric_limits<double>::quiet_NaN(), 0.5};
    default: return {0.0, 0.0};
  }
}

TEST(FmuRelbot, FollowsTheBuiltInModelsTrajectory) {
  const auto plant = OpenFmu(test::TestFmu("relbot"));
  std::array<double, 5> y{-1, -1, -1, -1, -1};
  plant->Start(kTwinStepS, y);
  EXPECT_EQ(y, (std::array<double, 5>{}));
  app::RelbotModel model(app::RelbotParams{}, app::Integrator::kRk4, kTwinStepS);
  double largest_difference = 0.0;
  for (int k = 0; k < 12000; ++k) {
    const std::array<double, 2> duties = RelbotDutiesAt(k);
    ASSERT_TRUE(plant->Step(duties, y).ok()) << "step " << k;
    model.Step(duties[0], duties[1]);
    const app::RelbotOutputs expected = model.Outputs();
    const std::array<double, 5> want{expected.wheel_left_m, expected.wheel_right_m,
                                     expected.x_m, expected.y_m, expected.theta_rad};
    for (std::size_t i = 0; i < y.size(); ++i) {
      // Rounding only: Eigen orders some sums differently (60 s of the twin differ by 4e-15).
      ASSERT_NEAR(y[i], want[i], 1e-12) << "output " << i << " at step " << k;
      largest_difference = std::max(largest_difference, std::abs(y[i] - want[i]));
    }
  }
  EXPECT_GT(std::abs(y[4]), 0.1);  // it did turn
  EXPECT_LT(largest_difference, 1e-12);
}

}  // namespace
}  // namespace hiltwin::fmi
