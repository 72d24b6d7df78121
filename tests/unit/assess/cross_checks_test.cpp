// Theil's inequality coefficient and the ISO/TS 18571 rating on curves with known answers.
#include "hiltwin/assess/cross_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace hiltwin::analysis {
namespace {

std::vector<double> Pulse(std::size_t n, double shift_samples = 0.0, double gain = 1.0) {
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = (static_cast<double>(i) - shift_samples) / static_cast<double>(n);
    y[i] = gain * std::exp(-std::pow((x - 0.4) / 0.08, 2.0)) * std::sin(2.0 * std::numbers::pi * 3.0 * x);
  }
  return y;
}

TEST(Theil, IdenticalIsZeroOppositeIsOne) {
  const std::vector<double> y = Pulse(500);
  EXPECT_EQ(TheilInequality(y, y).u, 0.0);
  std::vector<double> negated(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) negated[i] = -y[i];
  EXPECT_NEAR(TheilInequality(negated, y).u, 1.0, 1e-12);
}

TEST(Theil, ProportionsSumToOneAndOffsetIsPureBias) {
  const std::vector<double> exp = Pulse(500);
  std::vector<double> offset(exp.size());
  for (std::size_t i = 0; i < exp.size(); ++i) offset[i] = exp[i] + 0.1;
  const TheilCoefficients t = TheilInequality(offset, exp);
  EXPECT_NEAR(t.bias, 1.0, 1e-9);
  EXPECT_NEAR(t.variance, 0.0, 1e-9);
  EXPECT_NEAR(t.covariance, 0.0, 1e-9);

  const std::vector<double> other = Pulse(500, 7.0, 1.2);
  const TheilCoefficients mixed = TheilInequality(other, exp);
  EXPECT_NEAR(mixed.bias + mixed.variance + mixed.covariance, 1.0, 1e-9);
  EXPECT_GT(mixed.u, 0.0);
  EXPECT_LT(mixed.u, 1.0);
}

TEST(Iso18571, IdenticalCurvesRateOneExcellent) {
  const std::vector<double> y = Pulse(1000);
  const IsoRating r = Iso18571Rating(y, y);
  EXPECT_DOUBLE_EQ(r.corridor, 1.0);
  EXPECT_DOUBLE_EQ(r.phase, 1.0);
  EXPECT_DOUBLE_EQ(r.magnitude, 1.0);
  EXPECT_DOUBLE_EQ(r.slope, 1.0);
  EXPECT_DOUBLE_EQ(r.overall, 1.0);
  EXPECT_EQ(r.grade, "excellent");
}

TEST(Iso18571, ShiftIsFoundAndRatedLinearly) {
  const std::size_t n = 1000;
  const std::vector<double> reference = Pulse(n);
  const std::vector<double> shifted = Pulse(n, 20.0);  // 20 samples late, 2 % of the record
  const IsoRating r = Iso18571Rating(reference, shifted);
  EXPECT_EQ(std::abs(r.phase_shift_samples), 20);
  // E_P = (0.2 N - |shift|) / (0.2 N) = (200 - 20) / 200.
  EXPECT_NEAR(r.phase, 0.9, 1e-12);
  // After the shift the curves coincide, so magnitude and slope stay near 1.
  EXPECT_GT(r.magnitude, 0.95);
  EXPECT_GT(r.slope, 0.95);
  EXPECT_LT(r.corridor, 1.0);
}

TEST(Iso18571, MagnitudeErrorRatesByTheStandardsRatio) {
  const std::vector<double> reference = Pulse(800);
  const std::vector<double> larger = Pulse(800, 0.0, 1.2);  // 20 % too large
  const IsoRating r = Iso18571Rating(reference, larger);
  EXPECT_EQ(r.phase_shift_samples, 0);
  // DTW can only lower the L1 error below 0.2, so E_M >= (0.5 - 0.2) / 0.5 = 0.6.
  EXPECT_GE(r.magnitude, 0.6 - 1e-12);
  EXPECT_LT(r.magnitude, 1.0);
  // Slope error is exactly 20 % (no warping): E_S = (2 - 0.2) / 2 = 0.9.
  EXPECT_NEAR(r.slope, 0.9, 1e-9);
  EXPECT_NEAR(r.overall, 0.4 * r.corridor + 0.2 * (r.phase + r.magnitude + r.slope), 1e-12);
}

TEST(Iso18571, RejectsShortOrMismatchedCurves) {
  EXPECT_THROW((void)Iso18571Rating(std::vector<double>(10, 1.0), std::vector<double>(10, 1.0)),
               std::invalid_argument);
  EXPECT_THROW((void)Iso18571Rating(Pulse(100), Pulse(99)), std::invalid_argument);
}

}  // namespace
}  // namespace hiltwin::analysis
