// Welch frequency responses and the frequency-domain score on systems with known answers.
#include "hiltwin/analysis/spectral.h"

#include <gtest/gtest.h>

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

TEST(Welch, DefaultSegment) {
  EXPECT_EQ(DefaultWelchSegment(100), 16u);
  EXPECT_EQ(DefaultWelchSegment(8192), 1024u);
  EXPECT_EQ(DefaultWelchSegment(100'000'000), 65536u);
}

}  // namespace
}  // namespace hiltwin::analysis
