// The time-domain score against the thesis's worked numbers (§5.6.2, §7.4.2), its
// invariants, and the performance domain on responses with known metrics.
#include "hiltwin/assess/credibility.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace hiltwin::analysis {
namespace {

// An experiment curve of range exactly `range` and a simulation whose difference from it is
// ±e_t alternately, so RMS(y_e − y_s) = e_t exactly (n even).
void MakePair(double range, double e_t, std::size_t n, std::vector<double>& y_sim,
              std::vector<double>& y_exp) {
  y_sim.resize(n);
  y_exp.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) / static_cast<double>(n - 1);
    y_exp[i] = range * 0.5 * (1.0 - std::cos(std::numbers::pi * x));  // 0 .. range
    y_sim[i] = y_exp[i] + ((i % 2 == 0) ? e_t : -e_t);
  }
}

TEST(Credibility, NormalisationFactorOfThesisPassingScoreIs075) {
  // Thesis §5.6.2: K_e = 0.6 / sqrt(1 - 0.6^2) = 0.75.
  EXPECT_NEAR(NormalisationFactor(0.6), 0.75, 1e-15);
}

TEST(Credibility, ThesisSection562HardwarePlatformScore) {
  // eps_t = 0.1854 m, e_t = 9.101e-4 m -> eta = 0.999978 = 100 %.
  const double eta = CredibilityScore(9.101e-4, 0.1854, 0.6);
  EXPECT_NEAR(eta, 0.999978, 1e-6);
  EXPECT_EQ(std::lround(eta * 100.0), 100);
}

TEST(Credibility, ThesisSection742RelbotScore) {
  // eps_t = 0.1311 m, e_t = 0.0244 m -> eta = 0.9706 = 97 %.
  const double eta = CredibilityScore(0.0244, 0.1311, 0.6);
  EXPECT_NEAR(eta, 0.9706, 5e-5);
  EXPECT_EQ(std::lround(eta * 100.0), 97);
}

TEST(Credibility, ThesisNumbersThroughTheTimeDomainFormulas) {
  // Curves built so that Kp*(max - min) and the RMS error are the thesis's measurements.
  const CredibilityParams params;  // Kp = 0.05, eta_pass = 0.6
  std::vector<double> y_sim;
  std::vector<double> y_exp;
  MakePair(0.1854 / 0.05, 9.101e-4, 2000, y_sim, y_exp);
  const TimeDomainScore platform = ScoreTimeDomain(y_sim, y_exp, params);
  EXPECT_NEAR(platform.eps_t, 0.1854, 1e-12);
  EXPECT_NEAR(platform.e_t, 9.101e-4, 1e-12);
  EXPECT_NEAR(platform.k_e, 0.75, 1e-15);
  EXPECT_NEAR(platform.eta, 0.999978, 1e-6);
  EXPECT_EQ(platform.samples, 2000u);

  MakePair(0.1311 / 0.05, 0.0244, 2000, y_sim, y_exp);
  const TimeDomainScore relbot = ScoreTimeDomain(y_sim, y_exp, params);
  EXPECT_NEAR(relbot.eps_t, 0.1311, 1e-12);
  EXPECT_NEAR(relbot.e_t, 0.0244, 1e-12);
  EXPECT_NEAR(relbot.eta, 0.9706, 5e-5);
}

TEST(Credibility, ThesisSection39ScaleEnds) {
  // §3.9: 0.00 when the RMS error is 150 times the threshold, 1.00 when 0.075 times it.
  EXPECT_LT(CredibilityScore(150.0, 1.0, 0.6), 0.005);
  EXPECT_GT(CredibilityScore(0.075, 1.0, 0.6), 0.995);
}

TEST(Credibility, ScoreEqualsPassingScoreWhenErrorEqualsThreshold) {
  for (const double eta_pass : {0.1, 0.5, 0.6, 0.9, 0.99}) {
    for (const double eps : {1e-6, 0.1854, 3.0, 1e4}) {
      EXPECT_NEAR(CredibilityScore(eps, eps, eta_pass), eta_pass, 1e-12)
          << "eta_pass " << eta_pass << " eps " << eps;
    }
  }
}

TEST(Credibility, IdenticalCurvesScoreOne) {
  std::vector<double> y_sim;
  std::vector<double> y_exp;
  MakePair(2.0, 0.0, 100, y_sim, y_exp);
  const TimeDomainScore s = ScoreTimeDomain(y_sim, y_exp, CredibilityParams{});
  EXPECT_EQ(s.e_t, 0.0);
  EXPECT_EQ(s.eta, 1.0);
}

TEST(Credibility, ScoreFallsAsErrorGrows) {
  double previous = 1.0;
  for (double e = 1e-4; e < 100.0; e *= 1.7) {
    const double eta = CredibilityScore(e, 0.1, 0.6);
    EXPECT_LT(eta, previous) << "e " << e;
    EXPECT_GT(eta, 0.0);
    previous = eta;
  }
}

TEST(Credibility, KnownOffsetGivesKnownError) {
  std::vector<double> y_exp(500);
  std::vector<double> y_sim(500);
  for (std::size_t i = 0; i < y_exp.size(); ++i) {
    y_exp[i] = std::sin(0.05 * static_cast<double>(i));
    y_sim[i] = y_exp[i] - 0.0123;
  }
  const TimeDomainScore s = ScoreTimeDomain(y_sim, y_exp, CredibilityParams{0.05, 0.6});
  EXPECT_NEAR(s.e_t, 0.0123, 1e-12);
  const auto [lo, hi] = std::minmax_element(y_exp.begin(), y_exp.end());
  EXPECT_NEAR(s.eps_t, 0.05 * (*hi - *lo), 1e-15);
  EXPECT_NEAR(s.eta, 0.75 * s.eps_t / std::hypot(0.75 * s.eps_t, 0.0123), 1e-15);
}

TEST(Credibility, RejectsWhatHasNoScore) {
  EXPECT_THROW((void)NormalisationFactor(0.0), std::invalid_argument);
  EXPECT_THROW((void)NormalisationFactor(1.0), std::invalid_argument);
  EXPECT_THROW((void)CredibilityScore(0.1, 0.0, 0.6), std::invalid_argument);
  EXPECT_THROW((void)CredibilityScore(-0.1, 1.0, 0.6), std::invalid_argument);
  const std::vector<double> flat(10, 3.0);
  const std::vector<double> other(10, 2.0);
  EXPECT_THROW((void)ScoreTimeDomain(other, flat, CredibilityParams{}), std::invalid_argument);
  EXPECT_THROW((void)ScoreTimeDomain(std::vector<double>(9, 1.0), flat, CredibilityParams{}),
               std::invalid_argument);
}

std::vector<double> Times(std::size_t n, double step_s) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) * step_s;
  return t;
}

TEST(StepMetrics, FirstOrderResponseMatchesClosedForm) {
  const double tau_s = 0.2;
  const std::vector<double> t = Times(40001, 1e-4);  // 20 tau
  std::vector<double> y(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) y[i] = 2.0 * (1.0 - std::exp(-t[i] / tau_s));
  const StepMetrics m = ComputeStepMetrics(t, y, 2.0);
  ASSERT_TRUE(m.rise_time_s && m.settling_time_s && m.overshoot_pct && m.steady_state_error);
  EXPECT_NEAR(*m.rise_time_s, tau_s * std::log(9.0), 2e-4);
  EXPECT_NEAR(*m.settling_time_s, tau_s * std::log(50.0), 2e-4);
  EXPECT_NEAR(*m.overshoot_pct, 0.0, 1e-4);  // final value: mean of the last 5 %
  EXPECT_FALSE(m.peak_time_s.has_value());  // no overshoot beyond the 2 % band
  EXPECT_NEAR(*m.steady_state_error, 0.0, 1e-6);
}

TEST(StepMetrics, SecondOrderOvershootAndPeakTimeMatchClosedForm) {
  const double zeta = 0.3;
  const double wn = 10.0;
  const double wd = wn * std::sqrt(1.0 - zeta * zeta);
  const std::vector<double> t = Times(50001, 1e-4);  // 5 s: settled to 3e-7
  std::vector<double> y(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    y[i] = 1.0 - std::exp(-zeta * wn * t[i]) *
                     (std::cos(wd * t[i]) + zeta / std::sqrt(1.0 - zeta * zeta) * std::sin(wd * t[i]));
  }
  const StepMetrics m = ComputeStepMetrics(t, y, std::nullopt);
  ASSERT_TRUE(m.overshoot_pct && m.peak_time_s && m.settling_time_s);
  EXPECT_NEAR(*m.overshoot_pct, 100.0 * std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta)),
              0.01);
  EXPECT_NEAR(*m.peak_time_s, std::numbers::pi / wd, 1.5e-4);
  EXPECT_FALSE(m.steady_state_error.has_value());
  // 2 % settling of this response lies near 4/(zeta*wn) = 1.33 s (envelope estimate).
  EXPECT_GT(*m.settling_time_s, 0.8);
  EXPECT_LT(*m.settling_time_s, 1.4);
}

TEST(Performance, IdenticalResponsesScoreOneAndFivePercentSlowerScoresPass) {
  const std::vector<double> t = Times(20001, 1e-4);
  std::vector<double> exp(t.size());
  std::vector<double> same(t.size());
  std::vector<double> slower(t.size());
  const double tau_s = 0.1;
  for (std::size_t i = 0; i < t.size(); ++i) {
    exp[i] = 1.0 - std::exp(-t[i] / tau_s);
    same[i] = exp[i];
    slower[i] = 1.0 - std::exp(-t[i] / (1.05 * tau_s));
  }
  const auto identical = ScorePerformance(t, same, exp, std::nullopt, CredibilityParams{});
  ASSERT_TRUE(identical.has_value());
  EXPECT_DOUBLE_EQ(identical->eta, 1.0);
  const auto slow = ScorePerformance(t, slower, exp, std::nullopt, CredibilityParams{});
  ASSERT_TRUE(slow.has_value());
  // Rise time is 5 % longer: its error equals its threshold Kp*|rise_exp|, so eta = eta_pass.
  const MetricScore& rise = slow->metrics.at(0);
  ASSERT_EQ(rise.name, "rise_time_s");
  EXPECT_NEAR(rise.eta, 0.6, 0.01);
  EXPECT_LT(slow->eta, 1.0);
}

TEST(Performance, NoStepInExperimentGivesNothing) {
  const std::vector<double> t = Times(100, 0.01);
  const std::vector<double> flat(t.size(), 1.0);
  std::vector<double> ramp(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) ramp[i] = t[i];
  EXPECT_FALSE(ScorePerformance(t, ramp, flat, std::nullopt, CredibilityParams{}).has_value());
}

TEST(Performance, MetricMissingInOneCurveScoresZero) {
  const std::vector<double> t = Times(1000, 0.01);
  std::vector<double> exp(t.size());
  std::vector<double> never_settles(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    exp[i] = 1.0 - std::exp(-t[i]);
    never_settles[i] = 0.0;  // no step at all: no rise time
  }
  const auto s = ScorePerformance(t, never_settles, exp, std::nullopt, CredibilityParams{});
  ASSERT_TRUE(s.has_value());
  EXPECT_TRUE(s->metrics.at(0).scored);
  EXPECT_EQ(s->metrics.at(0).eta, 0.0);
}

const MetricScore& Metric(const PerformanceScore& s, const std::string& name) {
  for (const MetricScore& m : s.metrics) {
    if (m.name == name) return m;
  }
  throw std::out_of_range(name);
}

TEST(Credibility, OvershootFloorGivesAFiniteScoreWhenTheExperimentHasNone) {
  // Experiment: a ramp to 1 that stays there (overshoot exactly 0 %, so Kp*|0| = 0); the
  // simulation peaks at 1.005 (0.5 %) and settles back to 1. Threshold = the 1-point floor.
  const std::vector<double> t = Times(401, 0.25);
  std::vector<double> exp(t.size(), 1.0);
  std::vector<double> sim(t.size(), 1.0);
  for (std::size_t i = 0; i <= 8; ++i) {
    exp[i] = static_cast<double>(i) / 8.0;
    sim[i] = 1.005 * static_cast<double>(i) / 8.0;
  }
  for (std::size_t i = 9; i < 12; ++i) sim[i] = 1.005 - 0.005 * static_cast<double>(i - 8) / 4.0;
  const auto s = ScorePerformance(t, sim, exp, std::nullopt, CredibilityParams{});
  ASSERT_TRUE(s.has_value());
  const MetricScore& overshoot = Metric(*s, "overshoot_pct");
  ASSERT_TRUE(overshoot.scored && overshoot.exp && overshoot.sim);
  EXPECT_EQ(*overshoot.exp, 0.0);
  EXPECT_NEAR(*overshoot.sim, 0.5, 1e-9);
  EXPECT_EQ(overshoot.threshold, 1.0);
  // eta = K_e*eps / sqrt((K_e*eps)^2 + e^2) with K_e = 0.6/sqrt(1 - 0.36) = 0.75, eps = 1, e = 0.5.
  EXPECT_NEAR(overshoot.eta, 0.75 / std::sqrt(0.75 * 0.75 + 0.5 * 0.5), 1e-9);
}

TEST(Credibility, TimeMetricFloorIsOneSampleStep) {
  // Experiment jumps in one 0.25 s step: rise time 0.8 steps = 0.2 s, so Kp*0.2 = 0.01 s is
  // below the floor of one step. The simulation ramps over three steps: rise time 0.6 s.
  const double step_s = 0.25;
  const std::vector<double> t = Times(401, step_s);
  std::vector<double> exp(t.size(), 1.0);
  std::vector<double> sim(t.size(), 1.0);
  exp[0] = 0.0;
  for (std::size_t i = 0; i < 3; ++i) sim[i] = static_cast<double>(i) / 3.0;
  const auto s = ScorePerformance(t, sim, exp, std::nullopt, CredibilityParams{});
  ASSERT_TRUE(s.has_value());
  const MetricScore& rise = Metric(*s, "rise_time_s");
  ASSERT_TRUE(rise.scored && rise.exp && rise.sim);
  EXPECT_NEAR(*rise.exp, 0.8 * step_s, 1e-12);  // 10 % at 0.1 steps, 90 % at 0.9 steps
  EXPECT_NEAR(*rise.sim, 2.4 * step_s, 1e-12);  // 10 % at 0.3 steps, 90 % at 2.7 steps
  EXPECT_EQ(rise.threshold, step_s);
  const double scaled = 0.75 * step_s;
  EXPECT_NEAR(rise.eta, scaled / std::sqrt(scaled * scaled + 0.4 * 0.4), 1e-9);
  // Settling (exp 0.98 steps, sim 2.94 steps) is below the floor too.
  EXPECT_EQ(Metric(*s, "settling_time_s").threshold, step_s);
}

}  // namespace
}  // namespace hiltwin::analysis
