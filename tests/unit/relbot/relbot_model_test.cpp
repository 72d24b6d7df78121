#include "hiltwin/relbot/relbot_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>

#include "fakes/alloc_counter.h"

namespace hiltwin::app {
namespace {

namespace s = relbot_state;

constexpr double kStepS = 2.5e-4;  // 4 kHz, the thesis's chosen update rate (§6.5.2)

void Drive(RelbotModel& model, double left, double right, double duration_s) {
  const auto steps = static_cast<long>(std::llround(duration_s / model.step_s()));
  for (long k = 0; k < steps; ++k) model.Step(left, right);
}

// Straight-line steady state of one drivetrain, from the parameters alone:
//   N k_t (d V - k_e N w) / R - N^2 b_m w - r F_castor(r w) / 2 = 0,
// each wheel carrying half the castor's resistance. Solved by bisection (F is monotonic).
double SteadyWheelSpeedRadPerS(const RelbotParams& p, double duty) {
  const double n = p.gear_ratio_motor_rev_per_wheel_rev;
  const auto residual = [&](double w) {
    const double v = p.wheel_radius_m * w;
    const double castor_n = p.castor_viscous_friction_n_s_per_m * v +
                            p.castor_coulomb_friction_n * v /
                                std::sqrt(v * v + p.castor_smoothing_speed_m_per_s *
                                                      p.castor_smoothing_speed_m_per_s);
    return n * p.motor_torque_constant_n_m_per_a *
               (duty * p.supply_voltage_v - p.motor_back_emf_constant_v_s_per_rad * n * w) /
               p.motor_resistance_ohm -
           n * n * p.motor_viscous_friction_n_m_s_per_rad * w -
           p.wheel_radius_m * castor_n / 2.0;
  };
  double lo = 0.0;
  double hi = duty * p.supply_voltage_v / (p.motor_back_emf_constant_v_s_per_rad * n);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (residual(mid) > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(RelbotDerivative, AtRestFullDutyAcceleratesWheelsByStallTorqueOverEquivalentInertia) {
  const RelbotParams p;
  const double n = p.gear_ratio_motor_rev_per_wheel_rev;
  const double j_eq = n * n * p.motor_rotor_inertia_kg_m2 + p.wheel_inertia_kg_m2 +
                      p.wheel_mass_kg * p.wheel_radius_m * p.wheel_radius_m;
  EXPECT_DOUBLE_EQ(EquivalentWheelInertiaKgM2(p), j_eq);
  RelbotState dxdt;
  RelbotDerivative(MakeRelbotCoefficients(p), RelbotState::Zero(), 1.0, -0.5, dxdt);
  const double stall_torque_n_m = n * p.motor_torque_constant_n_m_per_a * p.supply_voltage_v /
                                  p.motor_resistance_ohm;
  EXPECT_NEAR(dxdt[s::kWheelSpeedLeftRadPerS], stall_torque_n_m / j_eq, 1e-9);
  EXPECT_NEAR(dxdt[s::kWheelSpeedRightRadPerS], -0.5 * stall_torque_n_m / j_eq, 1e-9);
  for (int i = 2; i < kRelbotStateSize; ++i) EXPECT_EQ(dxdt[i], 0.0) << "state " << i;
}

TEST(RelbotDerivative, SpringDeflectionPushesBodyAndHoldsWheelBack) {
  const RelbotParams p;
  RelbotState x = RelbotState::Zero();
  x[s::kSpringDeflectionLeftM] = 1e-4;
  RelbotState dxdt;
  RelbotDerivative(MakeRelbotCoefficients(p), x, 0.0, 0.0, dxdt);
  const double force_n = p.contact_stiffness_n_per_m * 1e-4;
  EXPECT_NEAR(dxdt[s::kBodyVelocityXMPerS], force_n / p.body_mass_kg, 1e-12);
  // The left wheel pushes at body Y = +track/2: the body yaws clockwise (negative).
  EXPECT_NEAR(dxdt[s::kYawRateRadPerS],
              -0.5 * p.track_width_m * force_n / p.body_yaw_inertia_kg_m2, 1e-12);
  EXPECT_NEAR(dxdt[s::kWheelSpeedLeftRadPerS],
              -p.wheel_radius_m * force_n / EquivalentWheelInertiaKgM2(p), 1e-12);
}

TEST(RelbotModel, StartsAtRestAndResetReturnsThere) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  EXPECT_TRUE(model.state().isZero());
  Drive(model, 0.5, 0.3, 0.5);
  EXPECT_FALSE(model.state().isZero());
  EXPECT_EQ(model.steps(), 2000U);
  EXPECT_DOUBLE_EQ(model.time_s(), 0.5);
  model.Reset();
  EXPECT_TRUE(model.state().isZero());
  EXPECT_EQ(model.steps(), 0U);
}

TEST(RelbotModel, PositiveDutyDrivesForward) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(model, 0.5, 0.5, 1.0);
  const RelbotOutputs out = model.Outputs();
  EXPECT_GT(out.wheel_left_m, 0.1);
  EXPECT_GT(out.x_m, 0.1);
}

TEST(RelbotModel, EqualDutyDrivesStraight) {
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    RelbotModel model(RelbotParams{}, method, kStepS);
    Drive(model, 0.7, 0.7, 2.0);
    Drive(model, -0.3, -0.3, 1.0);
    const RelbotOutputs out = model.Outputs();
    EXPECT_EQ(out.wheel_left_m, out.wheel_right_m) << IntegratorName(method);
    EXPECT_NEAR(out.y_m, 0.0, 1e-12);
    EXPECT_NEAR(out.theta_rad, 0.0, 1e-12);
    // Body and wheels travel together up to the spring's deflection.
    EXPECT_NEAR(out.x_m, out.wheel_left_m, 1e-3);
    EXPECT_GT(out.x_m, 0.5);
  }
}

TEST(RelbotModel, OppositeDutyTurnsInPlace) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(model, -0.5, 0.5, 3.0);
  const RelbotOutputs out = model.Outputs();
  // Right wheel forward, left backward: counter-clockwise, theta grows. About 0.43 m/s per
  // wheel on a 0.17 m track is about 5 rad/s.
  EXPECT_GT(out.theta_rad, 10.0);
  EXPECT_NEAR(out.wheel_left_m, -out.wheel_right_m, 0.01 * out.wheel_right_m);
  // Only the castor's drag moves the centre of mass, by well under a millimetre.
  EXPECT_NEAR(out.x_m, 0.0, 1e-3);
  EXPECT_NEAR(out.y_m, 0.0, 1e-3);
  const double yaw_rate = model.state()[s::kYawRateRadPerS];
  const RelbotParams p;
  EXPECT_NEAR(yaw_rate,
              (model.state()[s::kWheelSpeedRightRadPerS] - model.state()[s::kWheelSpeedLeftRadPerS]) *
                  p.wheel_radius_m / p.track_width_m,
              1e-3 * yaw_rate);
}

TEST(RelbotModel, MirroredDutiesGiveMirroredMotion) {
  RelbotModel a(RelbotParams{}, Integrator::kRk4, kStepS);
  RelbotModel b(RelbotParams{}, Integrator::kRk4, kStepS);
  for (int k = 0; k < 8000; ++k) {
    const double u1 = 0.8 * std::sin(1e-3 * k);
    const double u2 = 0.3 + 0.2 * std::cos(3e-3 * k);
    a.Step(u1, u2);
    b.Step(u2, u1);
  }
  const RelbotOutputs oa = a.Outputs();
  const RelbotOutputs ob = b.Outputs();
  EXPECT_GT(std::abs(oa.theta_rad), 0.1);  // it did turn, so the check is not trivial
  EXPECT_NEAR(oa.wheel_left_m, ob.wheel_right_m, 1e-12);
  EXPECT_NEAR(oa.wheel_right_m, ob.wheel_left_m, 1e-12);
  EXPECT_NEAR(oa.x_m, ob.x_m, 1e-12);
  EXPECT_NEAR(oa.y_m, -ob.y_m, 1e-12);
  EXPECT_NEAR(oa.theta_rad, -ob.theta_rad, 1e-12);
}

TEST(RelbotModel, FasterLeftWheelTurnsRight) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(model, 0.8, 0.4, 1.0);
  EXPECT_LT(model.Outputs().theta_rad, -0.1);
  EXPECT_LT(model.Outputs().y_m, 0.0);
}

TEST(RelbotModel, SteadyWheelSpeedMatchesClosedFormWithoutCoulombFriction) {
  RelbotParams p;
  p.castor_coulomb_friction_n = 0.0;
  const double duty = 0.6;
  const double n = p.gear_ratio_motor_rev_per_wheel_rev;
  // N k_t d V / R = (N^2 k_t k_e / R + N^2 b_m + r^2 c_castor / 2) w
  const double expected =
      n * p.motor_torque_constant_n_m_per_a * duty * p.supply_voltage_v / p.motor_resistance_ohm /
      (n * n * p.motor_torque_constant_n_m_per_a * p.motor_back_emf_constant_v_s_per_rad /
           p.motor_resistance_ohm +
       n * n * p.motor_viscous_friction_n_m_s_per_rad +
       p.wheel_radius_m * p.wheel_radius_m * p.castor_viscous_friction_n_s_per_m / 2.0);
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    RelbotModel model(p, method, kStepS);
    Drive(model, duty, duty, 3.0);  // slowest mode: about 60 ms (|lambda| = 16 1/s)
    EXPECT_NEAR(model.state()[s::kWheelSpeedLeftRadPerS], expected, 1e-7 * expected)
        << IntegratorName(method);
    EXPECT_NEAR(model.state()[s::kBodyVelocityXMPerS], p.wheel_radius_m * expected,
                1e-7 * expected);
  }
}

TEST(RelbotModel, SteadyWheelSpeedMatchesAnalyticWithDefaultFriction) {
  const RelbotParams p;
  for (const double duty : {-0.8, 0.05, 0.5, 1.0}) {
    RelbotModel model(p, Integrator::kRk4, kStepS);
    Drive(model, duty, duty, 3.0);
    const double expected = duty > 0 ? SteadyWheelSpeedRadPerS(p, duty)
                                     : -SteadyWheelSpeedRadPerS(p, -duty);
    EXPECT_NEAR(model.state()[s::kWheelSpeedLeftRadPerS], expected, 1e-7 * std::abs(expected))
        << "duty " << duty;
  }
  // The default set is meant to reach about 0.9 m/s at full duty.
  EXPECT_NEAR(SteadyWheelSpeedRadPerS(p, 1.0) * p.wheel_radius_m, 0.88, 0.02);
}

TEST(RelbotModel, DutyIsSaturatedAndNanSwitchesTheMotorOff) {
  EXPECT_EQ(SaturateDuty(3.0), 1.0);
  EXPECT_EQ(SaturateDuty(-7.0), -1.0);
  EXPECT_EQ(SaturateDuty(0.25), 0.25);
  EXPECT_EQ(SaturateDuty(std::numeric_limits<double>::quiet_NaN()), 0.0);
  RelbotModel a(RelbotParams{}, Integrator::kRk4, kStepS);
  RelbotModel b(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(a, 3.0, -7.0, 0.2);
  Drive(b, 1.0, -1.0, 0.2);
  EXPECT_EQ(a.state(), b.state());
  RelbotModel c(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(c, std::numeric_limits<double>::quiet_NaN(), 0.0, 0.2);
  EXPECT_TRUE(c.state().isZero());
}

TEST(RelbotModel, StateIsFiniteTurnsFalseOnANonFiniteState) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  Drive(model, 1.0, 0.5, 0.1);
  EXPECT_TRUE(model.StateIsFinite());
  RelbotState broken = model.state();
  broken[s::kBodyVelocityXMPerS] = std::numeric_limits<double>::quiet_NaN();
  model.set_state(broken);
  EXPECT_FALSE(model.StateIsFinite());
  model.Step(1.0, 0.5);
  EXPECT_FALSE(model.StateIsFinite());
}

TEST(RelbotModel, StateIsFiniteFindsInfAndNanInEveryStateAndOnlyThere) {
  RelbotModel model(RelbotParams{}, Integrator::kRk4, kStepS);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kMax = std::numeric_limits<double>::max();
  // Finite extremes whose sum overflows are still finite, negative zeros too.
  model.set_state(RelbotState::Constant(kMax));
  EXPECT_TRUE(model.StateIsFinite());
  model.set_state(RelbotState::Constant(-kMax));
  EXPECT_TRUE(model.StateIsFinite());
  model.set_state(RelbotState::Constant(-0.0));
  EXPECT_TRUE(model.StateIsFinite());
  model.set_state(RelbotState::Constant(std::numeric_limits<double>::denorm_min()));
  EXPECT_TRUE(model.StateIsFinite());
  for (int i = 0; i < kRelbotStateSize; ++i) {
    for (const double bad : {kInf, -kInf, std::numeric_limits<double>::quiet_NaN()}) {
      RelbotState x = RelbotState::Constant(kMax);
      x[i] = bad;
      model.set_state(x);
      EXPECT_FALSE(model.StateIsFinite()) << "state " << i << " = " << bad;
    }
  }
}

// RelbotModel::Step inlines the equations, holds the drive over the step and reuses the
// heading's cosine and sine while the heading is unchanged: it must step bit for bit as the
// generic integrators do with RelbotDerivative. Straight driving (the heading stays exactly
// 0, every stage reuses), turning (a new heading each stage), saturated and NaN duties, a
// replaced state and a reset.
TEST(RelbotModel, StepsBitForBitAsTheGenericIntegratorWithTheDerivative) {
  const RelbotParams params;
  const RelbotCoefficients c = MakeRelbotCoefficients(params);
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    RelbotModel model(params, method, kStepS);
    RelbotState x = RelbotState::Zero();
    const auto step_both = [&](double left, double right) {
      model.Step(left, right);
      const double l = SaturateDuty(left);
      const double r = SaturateDuty(right);
      const auto f = [&c, l, r](const RelbotState& state, RelbotState& dxdt) noexcept {
        RelbotDerivative(c, state, l, r, dxdt);
      };
      IntegrateStep(method, f, x, kStepS);
    };
    constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
    for (int k = 0; k < 4000; ++k) {
      const double t = k * kStepS;
      const double left = t < 0.3 ? 0.7 : (t < 0.6 ? 0.8 : -0.4 + 2.0 * std::sin(9.0 * t));
      const double right = t < 0.3 ? 0.7 : (t < 0.6 ? -0.5 : (k % 977 == 0 ? kNan : 0.3));
      step_both(left, right);
      ASSERT_EQ(model.state(), x) << IntegratorName(method) << " step " << k;
      if (t < 0.3) {
        ASSERT_EQ(x[s::kHeadingRad], 0.0);  // driving straight
      }
    }
    EXPECT_GT(std::abs(x[s::kHeadingRad]), 0.1);  // it did turn
    RelbotState moved = x;
    moved[s::kHeadingRad] = -2.5;  // a heading the model has not met
    model.set_state(moved);
    x = moved;
    for (int k = 0; k < 100; ++k) step_both(0.2, 0.9);
    EXPECT_EQ(model.state(), x) << IntegratorName(method);
    model.Reset();
    x.setZero();
    for (int k = 0; k < 100; ++k) step_both(0.5, 0.5);
    EXPECT_EQ(model.state(), x) << IntegratorName(method);
  }
}

// Integrates the equations directly (no constructor check) and says whether the state grew
// without bound within `duration_s` at full duty.
bool Diverges(Integrator method, double step_s, double duration_s) {
  const RelbotCoefficients c = MakeRelbotCoefficients(RelbotParams{});
  const auto f = [&c](const RelbotState& x, RelbotState& dxdt) noexcept {
    RelbotDerivative(c, x, 1.0, 0.5, dxdt);
  };
  RelbotState x = RelbotState::Zero();
  for (double t = 0.0; t < duration_s; t += step_s) {
    IntegrateStep(method, f, x, step_s);
    if (!x.allFinite() || x.head<2>().norm() > 1e6) return true;
  }
  return false;
}

TEST(RelbotModel, TheStableStepBoundIsTightAndTooLongAStepIsRefusedWithTheRate) {
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    const double max_step_s = RelbotMaxStableStepS(RelbotParams{}, method);
    ASSERT_GT(max_step_s, kStepS) << IntegratorName(method);  // 4 kHz is comfortably stable
    // Just inside the bound the model stays finite; just outside it the equations blow up.
    EXPECT_FALSE(Diverges(method, 0.97 * max_step_s, 36.0)) << IntegratorName(method);
    EXPECT_TRUE(Diverges(method, 1.1 * max_step_s, 36.0)) << IntegratorName(method);
    EXPECT_NO_THROW(RelbotModel(RelbotParams{}, method, 0.97 * max_step_s));
    try {
      RelbotModel model(RelbotParams{}, method, 1.1 * max_step_s);
      FAIL() << "an unstable step was accepted for " << IntegratorName(method);
    } catch (const ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find("update rate of at least"), std::string::npos)
          << error.what();
    }
  }
  // Higher order buys a longer stable step.
  EXPECT_LT(RelbotMaxStableStepS(RelbotParams{}, Integrator::kEuler),
            RelbotMaxStableStepS(RelbotParams{}, Integrator::kRk4));
}

TEST(Integrator, MaxStableStepMatchesTheClosedFormForEuler) {
  // Euler is stable for |1 + h·lambda| <= 1, i.e. h <= -2 Re(lambda) / |lambda|^2.
  const std::complex<double> mode{-160.0, 122.0};
  const std::complex<double> modes[] = {mode, {0.0, 0.0}, {-5.0, 0.0}};
  EXPECT_NEAR(MaxStableStepS(Integrator::kEuler, modes), 2.0 * 160.0 / std::norm(mode), 1e-9);
  // A real mode: RK4 is stable up to |h·lambda| = 2.785 (its real-axis stability boundary).
  const std::complex<double> real_mode[] = {{-1000.0, 0.0}};
  EXPECT_NEAR(MaxStableStepS(Integrator::kRk4, real_mode), 2.785e-3, 1e-6);
}

TEST(RelbotModel, StepAllocatesNothing) {
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    RelbotModel model(RelbotParams{}, method, kStepS);
    std::uint64_t allocations = 0;
    {
      test::ScopedAllocationCount count;
      for (int k = 0; k < 4000; ++k) model.Step(0.5, -0.2);
      const RelbotOutputs out = model.Outputs();
      EXPECT_TRUE(model.StateIsFinite());
      EXPECT_NE(out.wheel_left_m, 0.0);
      allocations = count.count();
    }
    EXPECT_EQ(allocations, 0U) << IntegratorName(method);
  }
}

TEST(RelbotModel, ConstructorRejectsBadStepAndParameters) {
  for (const double step_s : {0.0, -1e-3, 0.5, std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(RelbotModel(RelbotParams{}, Integrator::kRk4, step_s), ConfigError) << step_s;
  }
  RelbotParams p;
  p.body_mass_kg = -1.0;
  try {
    RelbotModel model(p);
    FAIL() << "negative mass accepted";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("body.mass_kg"), std::string::npos) << error.what();
  }
}

TEST(Integrator, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(ParseIntegrator("euler"), Integrator::kEuler);
  EXPECT_EQ(ParseIntegrator("rk2"), Integrator::kRk2);
  EXPECT_EQ(ParseIntegrator("rk4"), Integrator::kRk4);
  EXPECT_EQ(ParseIntegrator("RK4"), Integrator::kRk4);
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    EXPECT_EQ(ParseIntegrator(IntegratorName(method)), method);
  }
  try {
    (void)ParseIntegrator("rk45");
    FAIL() << "rk45 accepted";
  } catch (const ConfigError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("rk45"), std::string::npos);
    EXPECT_NE(message.find("euler, rk2, rk4"), std::string::npos);
  }
  EXPECT_EQ(StagesPerStep(Integrator::kRk2), 2);
}

// Integrators on dx/dt = -x, where the exact one-step factor is exp(-h): each method's
// factor is the truncated Taylor series of its order.
TEST(Integrator, OneStepMatchesTaylorSeriesOfItsOrder) {
  using V = Eigen::Matrix<double, 1, 1>;
  const auto f = [](const V& x, V& dxdt) noexcept { dxdt = -x; };
  const double h = 0.1;
  V x = V::Constant(1.0);
  EulerStep(f, x, h);
  EXPECT_DOUBLE_EQ(x[0], 1 - h);
  x.setConstant(1.0);
  Rk2Step(f, x, h);
  EXPECT_DOUBLE_EQ(x[0], 1 - h + h * h / 2);
  x.setConstant(1.0);
  Rk4Step(f, x, h);
  EXPECT_DOUBLE_EQ(x[0], 1 - h + h * h / 2 - h * h * h / 6 + h * h * h * h / 24);
}

}  // namespace
}  // namespace hiltwin::app
