#include "hiltwin/relbot/position_pid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fakes/alloc_counter.h"

namespace hiltwin::app {
namespace {

constexpr double kPeriodS = 1e-3;

/// A pure integrator (a wheel without inertia): y' = speed_per_duty · (u + disturbance),
/// integrated exactly for a duty held over one period.
struct IntegratorPlant {
  double speed_m_per_s_per_duty = 1.0;
  double disturbance_duty = 0.0;
  double position_m = 0.0;
  void Step(double duty) {
    position_m += speed_m_per_s_per_duty * (duty + disturbance_duty) * kPeriodS;
  }
};

PidGains P(double kp) {
  PidGains g;
  g.kp_duty_per_m = kp;
  return g;
}

TEST(PositionPid, ProportionalStepResponseOfAnIntegratorIsGeometric) {
  // y_{k+1} = y_k + K T kp (r - y_k): the error shrinks by (1 - K T kp) per period, exactly.
  PositionPid pid(P(10.0), kPeriodS);
  IntegratorPlant plant;
  const double setpoint_m = 0.1;
  for (int k = 0; k < 100; ++k) plant.Step(pid.Step(setpoint_m, plant.position_m));
  const double expected_error_m = setpoint_m * std::pow(1.0 - 1.0 * kPeriodS * 10.0, 100);
  EXPECT_NEAR(setpoint_m - plant.position_m, expected_error_m, 1e-12);
  EXPECT_NEAR(expected_error_m, 0.0366, 1e-4);  // the figure the formula gives: 36.6 % left
}

TEST(PositionPid, IntegralRemovesAConstantDisturbance) {
  // Proportional control alone leaves e = -d / kp; the integral must cancel d exactly.
  PidGains g = P(20.0);
  g.ki_duty_per_m_s = 100.0;
  PositionPid pid(g, kPeriodS);
  IntegratorPlant plant;
  plant.disturbance_duty = -0.3;  // e.g. a slope the wheel has to climb
  for (int k = 0; k < 20'000; ++k) plant.Step(pid.Step(0.05, plant.position_m));
  EXPECT_NEAR(0.05 - plant.position_m, 0.0, 1e-9);
  EXPECT_NEAR(pid.integral_duty(), 0.3, 1e-9);
  EXPECT_NEAR(pid.last().output_duty, 0.3, 1e-9);

  PositionPid p_only(P(20.0), kPeriodS);
  IntegratorPlant plant_p;
  plant_p.disturbance_duty = -0.3;
  for (int k = 0; k < 20'000; ++k) plant_p.Step(p_only.Step(0.05, plant_p.position_m));
  EXPECT_NEAR(0.05 - plant_p.position_m, 0.3 / 20.0, 1e-9);  // the offset the integral removes
}

TEST(PositionPid, NoDerivativeKickOnASetpointStep) {
  PidGains g = P(50.0);
  g.ki_duty_per_m_s = 10.0;
  g.kd_duty_s_per_m = 5.0;
  g.derivative_filter_s = 0.002;
  PositionPid pid(g, kPeriodS);
  pid.Reset(0.2);
  EXPECT_EQ(pid.Step(0.2, 0.2), 0.0);
  const double u = pid.Step(0.21, 0.2);  // setpoint step of 10 mm, wheel still
  EXPECT_EQ(pid.last().d_duty, 0.0);
  EXPECT_NEAR(u, 50.0 * 0.01 + 10.0 * kPeriodS * 0.01, 1e-12);  // kp·Δr + ki·T·Δr, no kd/T spike
}

TEST(PositionPid, ResetTakesThePositionSoTheFirstStepHasNoKick) {
  PidGains g = P(0.0);
  g.kd_duty_s_per_m = 5.0;
  PositionPid fresh(g, kPeriodS);
  EXPECT_EQ(fresh.Step(1.234, 1.234), 0.0);  // primes on its first measurement
  PositionPid reset(g, kPeriodS);
  reset.Reset(-3.0);
  EXPECT_EQ(reset.Step(-3.0, -3.0), 0.0);
}

TEST(PositionPid, FilteredDerivativeOfARampConvergesGeometrically) {
  // y = v·t: D_k = -kd·v·(1 - a^k), a = Tf / (Tf + T).
  PidGains g = P(0.0);
  g.kd_duty_s_per_m = 2.0;
  g.derivative_filter_s = 0.004;
  PositionPid pid(g, kPeriodS);
  const double v_m_per_s = 0.5;
  pid.Reset(0.0);
  const double a = 0.004 / (0.004 + kPeriodS);
  for (int k = 1; k <= 20; ++k) {
    (void)pid.Step(0.0, v_m_per_s * k * kPeriodS);
    EXPECT_NEAR(pid.last().d_duty, -2.0 * v_m_per_s * (1.0 - std::pow(a, k)), 1e-12) << k;
  }
}

TEST(PositionPid, FilterShrinksTheSpikeOfOneEncoderCount) {
  const double count_m = 1.0 / 12'732.395;  // one count at the default RELbot parameters
  PidGains g = P(0.0);
  g.kd_duty_s_per_m = 2.0;
  PositionPid raw(g, kPeriodS);
  raw.Reset(0.0);
  (void)raw.Step(0.0, count_m);
  EXPECT_NEAR(raw.last().d_duty, -2.0 * count_m / kPeriodS, 1e-15);  // -0.157 duty
  g.derivative_filter_s = 0.004;
  PositionPid filtered(g, kPeriodS);
  filtered.Reset(0.0);
  (void)filtered.Step(0.0, count_m);
  EXPECT_NEAR(filtered.last().d_duty, -2.0 * count_m / (0.004 + kPeriodS), 1e-15);  // 1/5 of it
}

TEST(PositionPid, OutputSaturatesAtTheConfiguredLimit) {
  PidGains g = P(100.0);
  g.duty_limit = 0.6;
  PositionPid pid(g, kPeriodS);
  EXPECT_EQ(pid.Step(1.0, 0.0), 0.6);
  EXPECT_TRUE(pid.last().saturated);
  EXPECT_EQ(pid.Step(-1.0, 0.0), -0.6);
  EXPECT_EQ(pid.Step(0.001, 0.0), 0.1);  // inside the limit: untouched
  EXPECT_FALSE(pid.last().saturated);
}

TEST(PositionPid, ConditionalIntegrationHoldsTheIntegralWhileSaturated) {
  // A blocked wheel 1 m short of its setpoint for 5 s: without anti-windup the integral would
  // reach ki·e·t = 100 · 1 · 5 = 500 duty and need seconds to unwind after the error reverses.
  PidGains g = P(10.0);
  g.ki_duty_per_m_s = 100.0;
  PositionPid pid(g, kPeriodS);
  pid.Reset(0.0);
  for (int k = 0; k < 5000; ++k) EXPECT_EQ(pid.Step(1.0, 0.0), 1.0);
  EXPECT_EQ(pid.integral_duty(), 0.0);
  EXPECT_TRUE(pid.last().integration_held);
  // The wheel is freed and overshoots by 5 cm: the output reverses at once.
  const double u = pid.Step(1.0, 1.05);
  EXPECT_NEAR(u, 10.0 * -0.05 + 100.0 * kPeriodS * -0.05 + pid.last().d_duty, 1e-12);
  EXPECT_LT(u, -0.5);
}

TEST(PositionPid, RampIsTrackedWithoutErrorAndTheIntegralCancelsTheDerivative) {
  // With the plant's integrator the loop is type 2: a constant-speed setpoint is tracked
  // without error. At speed v the derivative on the measurement is a steady -kd·v, which the
  // integral cancels even beyond the duty limit (here it must reach v/K + kd·v = 1.5).
  PidGains g = P(100.0);
  g.ki_duty_per_m_s = 1000.0;
  g.kd_duty_s_per_m = 2.0;
  g.derivative_filter_s = 0.004;
  g.duty_limit = 1.0;
  PositionPid pid(g, kPeriodS);
  IntegratorPlant plant;
  const double v_m_per_s = 0.5;
  for (int k = 0; k < 10'000; ++k) plant.Step(pid.Step(v_m_per_s * k * kPeriodS, plant.position_m));
  const double error_m = v_m_per_s * 10'000 * kPeriodS - plant.position_m;  // plant is one step on
  EXPECT_NEAR(error_m, 0.0, 1e-9);
  EXPECT_NEAR(pid.integral_duty(), 0.5 + 2.0 * 0.5, 1e-6);
  EXPECT_NEAR(pid.last().d_duty, -2.0 * 0.5, 1e-9);
  EXPECT_NEAR(pid.last().output_duty, 0.5, 1e-6);
  EXPECT_FALSE(pid.last().saturated);
}

TEST(PositionPid, IntegralStopsGrowingOnceTheOutputSaturatesItsWay) {
  // The integral alone drives a blocked wheel: it grows only until P + I + D reaches the limit.
  PidGains g = P(0.0);
  g.ki_duty_per_m_s = 1000.0;
  g.duty_limit = 0.8;
  PositionPid pid(g, kPeriodS);
  pid.Reset(0.0);
  for (int k = 0; k < 5000; ++k) (void)pid.Step(0.01, 0.0);  // +0.01 duty per step
  // It stops within one step's increment below the limit and stays there.
  EXPECT_LE(pid.integral_duty(), 0.8);
  EXPECT_GT(pid.integral_duty(), 0.8 - 0.01 - 1e-12);
  EXPECT_TRUE(pid.last().integration_held);
  EXPECT_EQ(pid.last().output_duty, pid.integral_duty());
}

TEST(PositionPid, NonFiniteInputsStopTheMotorAndKeepTheState) {
  PidGains g = P(10.0);
  g.ki_duty_per_m_s = 100.0;
  PositionPid pid(g, kPeriodS);
  (void)pid.Step(0.01, 0.0);
  const double integral = pid.integral_duty();
  EXPECT_EQ(pid.Step(std::numeric_limits<double>::quiet_NaN(), 0.0), 0.0);
  EXPECT_EQ(pid.Step(0.0, std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(pid.integral_duty(), integral);
}

TEST(PositionPid, StepAllocatesNothing) {
  PidGains g = P(80.0);
  g.ki_duty_per_m_s = 200.0;
  g.kd_duty_s_per_m = 3.0;
  g.derivative_filter_s = 0.003;
  PositionPid pid(g, kPeriodS);
  IntegratorPlant plant;
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    for (int k = 0; k < 10'000; ++k) plant.Step(pid.Step(0.3, plant.position_m));
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U);
  EXPECT_NEAR(plant.position_m, 0.3, 1e-6);
}

}  // namespace
}  // namespace hiltwin::app
