#include "hiltwin/relbot/relbot_reference.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

namespace hiltwin::app {
namespace {

constexpr double kReferenceStepS = 2.5e-4;   // 4 kHz twin
constexpr double kHoldS = 1.0e-3;   // inputs from a 1 kHz controller, as in `hiltwin run`

double MaxWheelError(const std::vector<RelbotOutputs>& a, const std::vector<RelbotOutputs>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    worst = std::max({worst, std::abs(a[i].wheel_left_m - b[i].wheel_left_m),
                      std::abs(a[i].wheel_right_m - b[i].wheel_right_m)});
  }
  return worst;
}

// The acceptance check of issue 4: the twin's RK4 at 4 kHz against Boost.Odeint's adaptive
// Dormand-Prince on the same equations, over the whole built-in open-loop profile.
TEST(RelbotReference, Rk4At4kHzMatchesDopri5OverTheOpenLoopProfile) {
  const RelbotParams params;
  const InputProfile profile = OpenLoopProfile();
  const double duration_s = profile.period_s();
  const auto start = std::chrono::steady_clock::now();
  const std::vector<RelbotOutputs> reference =
      SimulateReference(params, profile, duration_s, kReferenceStepS, {kHoldS, 1e-10, 1e-10});
  const auto reference_done = std::chrono::steady_clock::now();
  RelbotModel model(params, Integrator::kRk4, kReferenceStepS);
  const std::vector<RelbotOutputs> twin = SimulateFixedStep(model, profile, duration_s, kHoldS);

  ASSERT_EQ(reference.size(), 144000U);
  ASSERT_EQ(twin.size(), reference.size());
  const double rms_m = RmsWheelPositionError(twin, reference);
  const double max_m = MaxWheelError(twin, reference);
  std::printf("RK4 4 kHz vs dopri5 over %.0f s: RMS %.3g m, max %.3g m (reference %.2f s)\n",
              duration_s, rms_m, max_m,
              std::chrono::duration<double>(reference_done - start).count());
  EXPECT_LT(rms_m, 1e-6);
  // The profile really moved the robot, so a small error is not a trivial one.
  double travelled_m = 0.0;
  for (const RelbotOutputs& o : reference) {
    travelled_m = std::max(travelled_m, std::abs(o.wheel_right_m));
  }
  EXPECT_GT(travelled_m, 1.0);
  EXPECT_NEAR(reference.back().x_m, twin.back().x_m, 1e-5);
  EXPECT_NEAR(reference.back().theta_rad, twin.back().theta_rad, 1e-5);
}

// The same comparison fails for Euler at 4 kHz: the check can tell integrators apart.
TEST(RelbotReference, EulerAt4kHzIsFarLessAccurate) {
  const RelbotParams params;
  const InputProfile profile = OpenLoopProfile();
  const double duration_s = 10.0;
  const auto reference = SimulateReference(params, profile, duration_s, kReferenceStepS, {kHoldS});
  RelbotModel euler(params, Integrator::kEuler, kReferenceStepS);
  RelbotModel rk4(params, Integrator::kRk4, kReferenceStepS);
  const double euler_rms = RmsWheelPositionError(
      SimulateFixedStep(euler, profile, duration_s, kHoldS), reference);
  const double rk4_rms =
      RmsWheelPositionError(SimulateFixedStep(rk4, profile, duration_s, kHoldS), reference);
  EXPECT_GT(euler_rms, 1e-6);
  EXPECT_GT(euler_rms, 1000.0 * rk4_rms);
}

// Halving the step divides the global error by 2^order: 2 (Euler), 4 (RK2), 16 (RK4).
TEST(RelbotReference, IntegratorsConvergeWithTheirOrder) {
  const RelbotParams params;
  const InputProfile profile = InputProfile::FromKnots(
      "ramps", {{0.0, {0.2, 0.8}}, {0.5, {1.0, -0.3}}, {1.0, {-0.5, 0.5}}});
  const double duration_s = 1.0;
  const double coarse_s = 1e-3;
  const double fine_s = 5e-4;
  const ReferenceOptions tight{coarse_s, 1e-13, 1e-13};
  const auto reference_fine = SimulateReference(params, profile, duration_s, fine_s, tight);
  // Errors at the coarse sample times only: every second fine sample.
  std::vector<RelbotOutputs> reference_coarse;
  for (std::size_t i = 1; i < reference_fine.size(); i += 2) {
    reference_coarse.push_back(reference_fine[i]);
  }
  struct Case {
    Integrator method;
    double order_ratio;
  };
  for (const Case c : {Case{Integrator::kEuler, 2.0}, Case{Integrator::kRk2, 4.0},
                       Case{Integrator::kRk4, 16.0}}) {
    RelbotModel coarse(params, c.method, coarse_s);
    RelbotModel fine(params, c.method, fine_s);
    const double e_coarse = MaxWheelError(
        SimulateFixedStep(coarse, profile, duration_s, coarse_s), reference_coarse);
    const double e_fine =
        MaxWheelError(SimulateFixedStep(fine, profile, duration_s, coarse_s), reference_fine);
    const double ratio = e_coarse / e_fine;
    EXPECT_NEAR(ratio, c.order_ratio, 0.2 * c.order_ratio)
        << IntegratorName(c.method) << ": " << e_coarse << " / " << e_fine;
  }
}

TEST(RelbotReference, ReferenceHasConverged) {
  const RelbotParams params;
  const InputProfile profile = OpenLoopProfile();
  const auto normal = SimulateReference(params, profile, 3.0, kReferenceStepS, {kHoldS, 1e-10, 1e-10});
  const auto tighter = SimulateReference(params, profile, 3.0, kReferenceStepS, {kHoldS, 1e-13, 1e-13});
  EXPECT_LT(MaxWheelError(normal, tighter), 1e-8);
}

TEST(RelbotReference, HoldMustBeAWholeNumberOfSteps) {
  const RelbotParams params;
  const InputProfile profile = OpenLoopProfile();
  EXPECT_THROW((void)SimulateReference(params, profile, 1.0, 3e-4, {kHoldS}),
               std::invalid_argument);
  RelbotModel model(params, Integrator::kRk4, 3e-4);
  EXPECT_THROW((void)SimulateFixedStep(model, profile, 1.0, kHoldS), std::invalid_argument);
  EXPECT_THROW((void)SimulateFixedStep(model, profile, -1.0, 3e-4), std::invalid_argument);
}

TEST(RelbotReference, RmsOfKnownDifferences) {
  std::vector<RelbotOutputs> a(4);
  std::vector<RelbotOutputs> b(4);
  b[0].wheel_left_m = 2.0;  // one difference of 2 among 8 wheel samples: sqrt(4/8)
  EXPECT_DOUBLE_EQ(RmsWheelPositionError(a, b), std::sqrt(0.5));
  EXPECT_EQ(RmsWheelPositionError({}, {}), 0.0);
}

}  // namespace
}  // namespace hiltwin::app
