// Delay estimation: known shifts (whole and fractional samples, both signs) are recovered.
#include "hiltwin/assess/delay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hiltwin::analysis {
namespace {

// A position-like curve: a ramp with smooth wiggles, like a wheel driven by a varying duty.
double WigglyRamp(double t_s) {
  return 0.3 * t_s + 0.2 * std::sin(2.1 * t_s) + 0.05 * std::sin(7.3 * t_s + 0.4) +
         0.02 * std::cos(13.7 * t_s);
}

struct Case {
  double delay_s;
  double step_s;
};

class DelayRecovery : public ::testing::TestWithParam<Case> {};

TEST_P(DelayRecovery, FindsTheShift) {
  const Case c = GetParam();
  const std::size_t n = 8000;
  std::vector<double> sim(n);
  std::vector<double> exp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * c.step_s;
    sim[i] = WigglyRamp(t);
    exp[i] = WigglyRamp(t - c.delay_s);  // the experiment lags by delay_s
  }
  const DelayEstimate d = EstimateDelay(sim, exp, c.step_s, 0.5);
  EXPECT_NEAR(d.delay_s, c.delay_s, 0.02 * c.step_s) << "delay " << c.delay_s;
  EXPECT_FALSE(d.at_search_limit);
}

INSTANTIATE_TEST_SUITE_P(Shifts, DelayRecovery,
                         ::testing::Values(Case{0.0, 1e-3}, Case{0.002, 1e-3},
                                           Case{0.0023, 1e-3}, Case{-0.0047, 1e-3},
                                           Case{0.002, 2.5e-4}, Case{0.0371, 1e-3}));

TEST(Delay, IdenticalCurvesHaveNoDelay) {
  std::vector<double> y(1000);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = WigglyRamp(0.01 * static_cast<double>(i));
  const DelayEstimate d = EstimateDelay(y, y, 0.01, 1.0);
  EXPECT_NEAR(d.delay_s, 0.0, 1e-9);
  EXPECT_NEAR(d.spread_at_delay, 0.0, 1e-12);
}

TEST(Delay, ReportsTheSearchLimit) {
  const std::size_t n = 4000;
  std::vector<double> sim(n);
  std::vector<double> exp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * 1e-3;
    sim[i] = WigglyRamp(t);
    exp[i] = WigglyRamp(t - 0.05);
  }
  const DelayEstimate d = EstimateDelay(sim, exp, 1e-3, 0.01);  // 10 ms range, 50 ms delay
  EXPECT_TRUE(d.at_search_limit);
  EXPECT_EQ(d.max_lag_samples, 10u);
}

TEST(Delay, LargeOffsetDoesNotSpoilPrecision) {
  // Positions far from zero (a robot 1000 m down the track) must not blur the estimate.
  const std::size_t n = 6000;
  std::vector<double> sim(n);
  std::vector<double> exp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * 1e-3;
    sim[i] = 1000.0 + WigglyRamp(t);
    exp[i] = 1000.0 + WigglyRamp(t - 0.0026);
  }
  EXPECT_NEAR(EstimateDelay(sim, exp, 1e-3, 0.1).delay_s, 0.0026, 2e-5);
}

TEST(Delay, ConstantOffsetIsNotMistakenForADelay) {
  const std::size_t n = 5000;
  std::vector<double> sim(n);
  std::vector<double> exp(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * 1e-3;
    sim[i] = WigglyRamp(t) + 0.05;  // offset, no shift
    exp[i] = WigglyRamp(t);
  }
  EXPECT_NEAR(EstimateDelay(sim, exp, 1e-3, 0.5).delay_s, 0.0, 1e-6);
  for (std::size_t i = 0; i < n; ++i) exp[i] = WigglyRamp(static_cast<double>(i) * 1e-3 - 0.0042);
  EXPECT_NEAR(EstimateDelay(sim, exp, 1e-3, 0.5).delay_s, 0.0042, 2e-5);
}

TEST(Delay, NoShiftReportsExactlyZero) {
  // Offset curves without a shift: rounding in the parabola's three spreads used to leave a
  // "delay" of ~1e-17 s (printed as 6.2e-17 s); the estimate must say 0.
  for (const double offset : {0.004, 0.05, 1000.0}) {
    for (const double step_s : {2.5e-4, 1e-3, 1e-2}) {
      std::vector<double> sim(2000);
      std::vector<double> exp(2000);
      for (std::size_t i = 0; i < exp.size(); ++i) {
        exp[i] = WigglyRamp(static_cast<double>(i) * step_s);
        sim[i] = exp[i] + offset;
      }
      const DelayEstimate d = EstimateDelay(sim, exp, step_s, 200 * step_s);
      EXPECT_EQ(d.delay_samples, 0.0) << "offset " << offset << ", step " << step_s;
      EXPECT_EQ(d.delay_s, 0.0) << "offset " << offset << ", step " << step_s;
    }
  }
}

}  // namespace
}  // namespace hiltwin::analysis
