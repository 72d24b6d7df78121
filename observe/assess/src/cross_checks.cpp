#include "hiltwin/assess/cross_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace hiltwin::analysis {
namespace {

// ISO/TS 18571:2014 parameters (table 2 of the standard).
constexpr double kInnerCorridor = 0.05;   // a_0
constexpr double kOuterCorridor = 0.50;   // b_0
constexpr double kCorridorExponent = 2.0; // k_Z
constexpr double kMaxShiftFraction = 0.2; // ε_P*
constexpr double kMaxMagnitudeError = 0.5;  // ε_M*
constexpr double kMaxSlopeError = 2.0;    // ε_S*
constexpr double kDtwWindowFraction = 0.1;

double Pearson(std::span<const double> a, std::span<const double> b) {
  const auto n = static_cast<double>(a.size());
  double ma = 0.0;
  double mb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  double sab = 0.0;
  double saa = 0.0;
  double sbb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  if (saa <= 0.0 || sbb <= 0.0) return saa == sbb ? 1.0 : 0.0;
  return sab / std::sqrt(saa * sbb);
}

double L1(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += std::abs(x);
  return s;
}

// Error ratio → rating: 1 at 0, 0 at or beyond `limit`, ((limit − e)/limit)^1 between.
double RatioRating(double error, double limit) {
  if (error <= 0.0) return 1.0;
  if (error >= limit) return 0.0;
  return (limit - error) / limit;
}

// Banded dynamic time warping (Sakoe-Chiba), squared difference as local cost, steps
// (1,0), (0,1), (1,1) of weight 1. Returns both sequences along the optimal path.
void Warp(std::span<const double> a, std::span<const double> b, std::vector<double>& wa,
          std::vector<double>& wb) {
  const std::size_t n = a.size();
  const auto band = static_cast<std::size_t>(std::ceil(kDtwWindowFraction * static_cast<double>(n)));
  const std::size_t width = 2 * band + 1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> cost(n * width, kInf);  // cost[i*width + (j - i + band)]
  auto at = [&](std::size_t i, std::size_t j) -> double& { return cost[i * width + (j + band - i)]; };
  auto inside = [&](std::size_t i, std::size_t j) { return j + band >= i && j <= i + band && j < n; };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j_lo = i > band ? i - band : 0;
    const std::size_t j_hi = std::min(n - 1, i + band);
    for (std::size_t j = j_lo; j <= j_hi; ++j) {
      const double d = a[i] - b[j];
      double prev = 0.0;
      if (i > 0 || j > 0) {
        prev = kInf;
        if (i > 0 && inside(i - 1, j)) prev = std::min(prev, at(i - 1, j));
        if (j > 0 && inside(i, j - 1)) prev = std::min(prev, at(i, j - 1));
        if (i > 0 && j > 0 && inside(i - 1, j - 1)) prev = std::min(prev, at(i - 1, j - 1));
      }
      at(i, j) = d * d + prev;
    }
  }
  wa.clear();
  wb.clear();
  std::size_t i = n - 1;
  std::size_t j = n - 1;
  while (true) {
    wa.push_back(a[i]);
    wb.push_back(b[j]);
    if (i == 0 && j == 0) break;
    double best = kInf;
    std::size_t ni = i;
    std::size_t nj = j;
    if (i > 0 && j > 0 && inside(i - 1, j - 1) && at(i - 1, j - 1) <= best) {
      best = at(i - 1, j - 1);
      ni = i - 1;
      nj = j - 1;
    }
    if (i > 0 && inside(i - 1, j) && at(i - 1, j) < best) {
      best = at(i - 1, j);
      ni = i - 1;
      nj = j;
    }
    if (j > 0 && inside(i, j - 1) && at(i, j - 1) < best) {
      ni = i;
      nj = j - 1;
    }
    i = ni;
    j = nj;
  }
  std::reverse(wa.begin(), wa.end());
  std::reverse(wb.begin(), wb.end());
}

// Central-difference derivative (one-sided at the ends) smoothed by the standard's moving
// average: 9 points inside, 1/3/5/7 points at each end.
std::vector<double> SmoothedSlope(std::span<const double> v) {
  const std::size_t n = v.size();
  std::vector<double> d(n);
  d[0] = v[1] - v[0];
  d[n - 1] = v[n - 1] - v[n - 2];
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = 0.5 * (v[i + 1] - v[i - 1]);
  auto mean = [&](std::size_t from, std::size_t count) {
    double sum = 0.0;
    for (std::size_t k = from; k < from + count; ++k) sum += d[k];
    return sum / static_cast<double>(count);
  };
  std::vector<double> s(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t from_end = n - 1 - i;
    if (i >= 4 && from_end >= 4) {
      s[i] = mean(i - 4, 9);
    } else if (i < from_end) {
      s[i] = mean(0, 2 * i + 1);
    } else {
      s[i] = mean(n - (2 * from_end + 1), 2 * from_end + 1);
    }
  }
  return s;
}

}  // namespace

TheilCoefficients TheilInequality(std::span<const double> y_sim, std::span<const double> y_exp) {
  if (y_sim.size() != y_exp.size() || y_exp.size() < 2) {
    throw std::invalid_argument("Theil: need two equally long curves of at least two samples");
  }
  const auto n = static_cast<double>(y_exp.size());
  double ms = 0.0;
  double me = 0.0;
  double ss = 0.0;
  double se = 0.0;
  double sd = 0.0;
  for (std::size_t i = 0; i < y_exp.size(); ++i) {
    ms += y_sim[i];
    me += y_exp[i];
    ss += y_sim[i] * y_sim[i];
    se += y_exp[i] * y_exp[i];
    sd += (y_sim[i] - y_exp[i]) * (y_sim[i] - y_exp[i]);
  }
  ms /= n;
  me /= n;
  TheilCoefficients t;
  const double mse = sd / n;
  const double denom = std::sqrt(ss / n) + std::sqrt(se / n);
  t.u = denom > 0.0 ? std::sqrt(mse) / denom : 0.0;
  if (mse > 0.0) {
    double vs = 0.0;
    double ve = 0.0;
    double cov = 0.0;
    for (std::size_t i = 0; i < y_exp.size(); ++i) {
      vs += (y_sim[i] - ms) * (y_sim[i] - ms);
      ve += (y_exp[i] - me) * (y_exp[i] - me);
      cov += (y_sim[i] - ms) * (y_exp[i] - me);
    }
    const double sigma_s = std::sqrt(vs / n);
    const double sigma_e = std::sqrt(ve / n);
    const double rho = (sigma_s > 0.0 && sigma_e > 0.0) ? (cov / n) / (sigma_s * sigma_e) : 0.0;
    t.bias = (ms - me) * (ms - me) / mse;
    t.variance = (sigma_s - sigma_e) * (sigma_s - sigma_e) / mse;
    t.covariance = 2.0 * (1.0 - rho) * sigma_s * sigma_e / mse;
  }
  return t;
}

IsoRating Iso18571Rating(std::span<const double> reference, std::span<const double> comparison) {
  if (reference.size() != comparison.size() || reference.size() < 20) {
    throw std::invalid_argument("ISO 18571: need two equally long curves of at least 20 samples");
  }
  const std::size_t n = reference.size();
  IsoRating r;
  r.samples = n;

  // Corridor: inner and outer half widths relative to the reference's largest magnitude.
  double norm = 0.0;
  for (const double v : reference) norm = std::max(norm, std::abs(v));
  const double inner = kInnerCorridor * norm;
  const double outer = kOuterCorridor * norm;
  double z = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::abs(reference[i] - comparison[i]);
    if (d <= inner) {
      z += 1.0;
    } else if (d < outer) {
      z += std::pow((outer - d) / (outer - inner), kCorridorExponent);
    }
  }
  r.corridor = z / static_cast<double>(n);

  // Phase: the shift (≤ 20 % of the record) with the highest Pearson correlation.
  const double max_shift = kMaxShiftFraction * static_cast<double>(n);
  const auto max_lag = static_cast<long>(std::floor(max_shift));
  const auto ln = static_cast<long>(n);
  double best_rho = -std::numeric_limits<double>::infinity();
  long best_lag = 0;
  for (long lag = 0; lag <= max_lag; ++lag) {
    for (const long k : {lag, -lag}) {
      if (lag == 0 && k != 0) continue;
      // comparison[i − k] against reference[i]
      const auto begin = static_cast<std::size_t>(std::max(0L, k));
      const auto end = static_cast<std::size_t>(std::min(ln, ln + k));
      const double rho = Pearson(reference.subspan(begin, end - begin),
                                 comparison.subspan(begin - static_cast<std::size_t>(k), end - begin));
      if (rho > best_rho + 1e-12) {
        best_rho = rho;
        best_lag = k;
      }
    }
  }
  r.phase_shift_samples = best_lag;
  const double shift = std::abs(static_cast<double>(best_lag));
  r.phase = best_lag == 0 ? 1.0 : (shift >= max_shift ? 0.0 : (max_shift - shift) / max_shift);

  const auto begin = static_cast<std::size_t>(std::max(0L, best_lag));
  const auto length = n - static_cast<std::size_t>(std::abs(best_lag));
  const auto ref_ts = reference.subspan(begin, length);
  const auto cmp_ts = comparison.subspan(begin - static_cast<std::size_t>(best_lag), length);

  // Magnitude: L1 error after dynamic time warping of the shifted curves.
  std::vector<double> ref_w;
  std::vector<double> cmp_w;
  Warp(cmp_ts, ref_ts, cmp_w, ref_w);
  std::vector<double> diff(ref_w.size());
  for (std::size_t i = 0; i < ref_w.size(); ++i) diff[i] = cmp_w[i] - ref_w[i];
  const double ref_norm = L1(ref_w);
  const double mag_error = ref_norm > 0.0 ? L1(diff) / ref_norm : (L1(diff) > 0.0 ? 1e300 : 0.0);
  r.magnitude = RatioRating(mag_error, kMaxMagnitudeError);

  // Slope: L1 error of the smoothed derivatives of the shifted curves.
  const std::vector<double> ref_slope = SmoothedSlope(ref_ts);
  const std::vector<double> cmp_slope = SmoothedSlope(cmp_ts);
  std::vector<double> slope_diff(ref_slope.size());
  for (std::size_t i = 0; i < ref_slope.size(); ++i) slope_diff[i] = cmp_slope[i] - ref_slope[i];
  const double slope_norm = L1(ref_slope);
  const double slope_error =
      slope_norm > 0.0 ? L1(slope_diff) / slope_norm : (L1(slope_diff) > 0.0 ? 1e300 : 0.0);
  r.slope = RatioRating(slope_error, kMaxSlopeError);

  r.overall = 0.4 * r.corridor + 0.2 * r.phase + 0.2 * r.magnitude + 0.2 * r.slope;
  r.grade = r.overall > 0.94 ? "excellent" : r.overall > 0.80 ? "good" : r.overall > 0.58 ? "fair" : "poor";
  return r;
}

}  // namespace hiltwin::analysis
