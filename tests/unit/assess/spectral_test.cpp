// Welch frequency responses and the frequency-domain score on systems with known answers.
#include "hiltwin/assess/spectral.h"

#include <gtest/gtest.h>

#include <limits>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace hiltwin::analysis {
namespace {

std::vector<double> Noise(std::size_t n, std::uint64_t seed) {
  std::vector<double> u(n);
  std::uint64_t s = seed;
  for (double& v : u) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    v = static_cast<double>(s >> 11) / 9007199254740992.0 - 0.5;
  }
  return u;
}

// y[k] = a*y[k-1] + (1-a)*u[k]: a first-order low-pass with unit DC gain.
std::vector<double> LowPass(const std::vector<double>& u, double a, double gain = 1.0) {
  std::vector<double> y(u.size());
  double state = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    state = a * state + (1.0 - a) * u[i];
    y[i] = gain * state;
  }
  return y;
}

TEST(Welch, PureGainHasThatGainAndFullCoherence) {
  const std::vector<double> u = Noise(8192, 1);
  std::vector<double> y(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) y[i] = 2.5 * u[i];
  const FrequencyResponse r = EstimateFrequencyResponse(u, y, 1e-3, 256);
  ASSERT_EQ(r.h.size(), 129u);
  EXPECT_EQ(r.segments, 63u);  // (8192 - 256) / 128 + 1
  EXPECT_NEAR(r.frequency_hz[128], 500.0, 1e-9);
  for (std::size_t b = 1; b < r.h.size(); ++b) {
    EXPECT_NEAR(std::abs(r.h[b]), 2.5, 1e-9);
    EXPECT_NEAR(std::arg(r.h[b]), 0.0, 1e-9);
    EXPECT_NEAR(r.coherence[b], 1.0, 1e-9);
  }
}

TEST(Welch, LowPassMatchesItsTransferFunction) {
  const double a = 0.9;
  const std::vector<double> u = Noise(1 << 16, 7);
  const std::vector<double> y = LowPass(u, a);
  const FrequencyResponse r = EstimateFrequencyResponse(u, y, 1e-3, 1024);
  for (const std::size_t b : {5u, 20u, 100u, 300u}) {
    const double w = 2.0 * std::numbers::pi * static_cast<double>(b) / 1024.0;
    const std::complex<double> z = std::polar(1.0, -w);
    const std::complex<double> h = (1.0 - a) / (1.0 - a * z);
    EXPECT_NEAR(std::abs(r.h[b]), std::abs(h), 0.03 * std::abs(h)) << "bin " << b;
    EXPECT_NEAR(std::arg(r.h[b]), std::arg(h), 0.03) << "bin " << b;
  }
}

TEST(FrequencyScore, IdenticalSystemsScoreOne) {
  const std::vector<double> u = Noise(1 << 14, 3);
  const std::vector<double> y = LowPass(u, 0.8);
  std::string why;
  const auto s = ScoreFrequency(u, y, y, 1e-3, 512, 0.8, CredibilityParams{}, why);
  ASSERT_TRUE(s.has_value()) << why;
  EXPECT_GT(s->bins_used, 200u);
  EXPECT_NEAR(s->magnitude.e, 0.0, 1e-9);
  EXPECT_NEAR(s->phase.e, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(s->eta, 1.0);
}

TEST(FrequencyScore, FivePercentGainErrorScoresPassingOnMagnitude) {
  const std::vector<double> u = Noise(1 << 14, 5);
  const std::vector<double> y_exp = LowPass(u, 0.8);
  const std::vector<double> y_sim = LowPass(u, 0.8, 1.05);
  std::string why;
  const auto s = ScoreFrequency(u, y_sim, y_exp, 1e-3, 512, 0.8, CredibilityParams{}, why);
  ASSERT_TRUE(s.has_value()) << why;
  EXPECT_NEAR(s->magnitude.e, 20.0 * std::log10(1.05), 1e-9);
  EXPECT_NEAR(s->magnitude.eta, 0.6, 1e-9);  // error == threshold
  EXPECT_NEAR(s->phase.eta, 1.0, 1e-9);
  EXPECT_NEAR(s->eta, 0.8, 1e-9);
}

TEST(FrequencyScore, UncorrelatedOutputHasNoCoherentBin) {
  const std::vector<double> u = Noise(4096, 11);
  const std::vector<double> other = Noise(4096, 12);
  std::string why;
  const auto s = ScoreFrequency(u, other, other, 1e-3, 256, 0.8, CredibilityParams{}, why);
  EXPECT_FALSE(s.has_value());
  EXPECT_NE(why.find("coherence"), std::string::npos);
}

// A wheel driven through a first-order drivetrain (time constant 60 ms, as the RELbot's,
// docs/relbot-model.md): v' = (u - v)/tau, x' = v, integrated at 4 kHz with Euler or RK4.
// The duty follows steps and ramps set by a 1 kHz controller and quantised to 1/2048, as
// `hiltwin run` logs it: almost all input power lies below a few Hz, and the quantisation
// leaves a faint broadband floor where the two integrators differ most.
struct WheelRun {
  std::vector<double> duty;
  std::vector<double> euler;
  std::vector<double> rk4;
};

double DutyProfile(double t_s) {
  // Knots (time, duty) joined by ramps; equal times make a step.
  static constexpr double kKnots[][2] = {
      {0.0, 0.0}, {1.0, 0.0}, {1.0, 0.4}, {3.0, 0.4}, {6.0, 1.0}, {8.0, 1.0}, {8.0, -0.5},
      {10.0, -0.5}, {12.0, 0.0}, {13.0, 0.0}, {13.0, 0.6}, {15.0, 0.6}, {15.0, -0.3},
      {17.0, -0.3}, {20.0, 0.8}, {23.0, 0.8}, {23.0, 0.2}, {27.0, -1.0}, {29.0, -1.0},
      {29.0, 0.3}, {32.0, 0.3}, {34.0, 0.0}, {34.5, 0.0}, {34.5, 0.1}, {35.5, 0.1},
      {35.5, 0.0}, {36.0, 0.0}};
  double duty = 0.0;
  for (std::size_t k = 1; k < std::size(kKnots); ++k) {
    const double t0 = kKnots[k - 1][0];
    const double t1 = kKnots[k][0];
    if (t_s >= t0 && t_s < t1) {
      duty = kKnots[k - 1][1] + (kKnots[k][1] - kKnots[k - 1][1]) * (t_s - t0) / (t1 - t0);
    }
  }
  return std::round(duty * 2048.0) / 2048.0;
}

WheelRun SimulateWheel(double step_s, std::size_t n) {
  constexpr double kTau = 0.06;
  auto f = [](double u, double v) { return (u - v) / kTau; };
  WheelRun run;
  double v_e = 0.0;
  double x_e = 0.0;
  double v_r = 0.0;
  double x_r = 0.0;
  double u = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 4 == 0) u = DutyProfile(static_cast<double>(i) * step_s);  // 1 kHz controller
    run.duty.push_back(u);
    run.euler.push_back(x_e);
    run.rk4.push_back(x_r);
    x_e += step_s * v_e;
    v_e += step_s * f(u, v_e);
    const double k1 = f(u, v_r);
    const double k2 = f(u, v_r + 0.5 * step_s * k1);
    const double k3 = f(u, v_r + 0.5 * step_s * k2);
    const double k4 = f(u, v_r + step_s * k3);
    x_r += step_s * (v_r + step_s / 6.0 * (k1 + k2 + k3));
    v_r += step_s / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return run;
}

TEST(Spectral, EulerAgainstRk4OfOneSmoothModelScoresHigh) {
  const double step_s = 2.5e-4;
  const WheelRun run = SimulateWheel(step_s, 144000);  // 36 s at 4 kHz
  std::string why;
  const auto s = ScoreFrequency(run.duty, run.euler, run.rk4, step_s, DefaultWelchSegment(144000),
                                0.8, CredibilityParams{}, why);
  ASSERT_TRUE(s.has_value()) << why;
  // Noise-free data keep the coherence ~1 in every bin; only the input-power gate leaves out
  // the quantisation floor, where Euler's phase lag and gain error grow with frequency.
  EXPECT_GT(s->bins_low_input, s->bins_total / 2);
  EXPECT_LT(s->f_max_hz, 50.0);
  EXPECT_EQ(s->segments, s->segments_total);  // the duty keeps moving over the whole record
  EXPECT_GE(s->eta, 0.9) << "magnitude e " << s->magnitude.e << " dB, phase e " << s->phase.e
                         << " deg over " << s->bins_used << " bins up to " << s->f_max_hz << " Hz";
}

TEST(Spectral, SingleStepExcitesTooFewSegmentsForAScore) {
  // A step at 1 s in a 10 s record: after each segment's line is removed, only the two
  // segments holding the step carry input power, and two averages give no coherence estimate.
  const std::size_t n = 10000;
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = i < 1000 ? 0.0 : 1.0;
  const std::vector<double> y = LowPass(u, 0.95);
  const FrequencyResponse r = EstimateFrequencyResponse(u, y, 1e-3, 1024);
  EXPECT_EQ(r.segments, 18u);  // (10000 - 1024) / 512 + 1
  EXPECT_EQ(r.segments_with_input, 2u);
  std::string why;
  const auto s = ScoreFrequency(u, y, y, 1e-3, 1024, 0.8, CredibilityParams{}, why);
  EXPECT_FALSE(s.has_value());
  EXPECT_NE(why.find("only 2 of 18 Welch segments"), std::string::npos) << why;
  EXPECT_NE(why.find("keeps changing"), std::string::npos) << why;
  // With fewer than 4 segments in all, shorter segments are what helps.
  const auto one = ScoreFrequency(u, y, y, 1e-3, 8192, 0.8, CredibilityParams{}, why);
  EXPECT_FALSE(one.has_value());
  EXPECT_NE(why.find("only 1 of 1 Welch segments"), std::string::npos) << why;
  EXPECT_NE(why.find("use shorter Welch segments or a longer record"), std::string::npos) << why;
  EXPECT_EQ(why.find("--"), std::string::npos) << why;
  // A command line names its flag through the namer; the library adds only the hint.
  const OptionNamer flags = [](AssessOption option) -> std::string_view {
    return option == AssessOption::kWelchSegment ? "--welch-segment" : "";
  };
  (void)ScoreFrequency(u, y, y, 1e-3, 8192, 0.8, CredibilityParams{}, why, 0.0,
                       std::numeric_limits<double>::infinity(), flags);
  EXPECT_NE(why.find("use shorter Welch segments (--welch-segment) or a longer record"),
            std::string::npos)
      << why;
}

TEST(Welch, DefaultSegment) {
  EXPECT_EQ(DefaultWelchSegment(100), 16u);
  EXPECT_EQ(DefaultWelchSegment(8192), 1024u);
  EXPECT_EQ(DefaultWelchSegment(100'000'000), 65536u);
}

}  // namespace
}  // namespace hiltwin::analysis
