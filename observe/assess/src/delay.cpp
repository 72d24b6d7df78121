#include "hiltwin/assess/delay.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "fftw_util.h"

namespace hiltwin::analysis {
namespace {

constexpr double kNoShiftSamples = 1e-9;  // sub-sample shifts below this are reported as 0

// Smallest 2^a·3^b·5^c ≥ n: FFTW is fastest on such sizes, and it keeps padding small.
std::size_t SmoothSize(std::size_t n) {
  for (std::size_t m = std::max<std::size_t>(n, 1);; ++m) {
    std::size_t r = m;
    for (const std::size_t p : {2u, 3u, 5u}) {
      while (r % p == 0) r /= p;
    }
    if (r == 1) return m;
  }
}

// Exact variance of the difference y[i] − x[i − k] over the overlap (a constant offset
// between the curves must not pass for a delay).
double DirectSpread(std::span<const double> x, std::span<const double> y, long k) {
  const auto n = static_cast<long>(y.size());
  const long begin = std::max(0L, k);
  const long end = std::min(n, n + k);
  const auto count = static_cast<double>(end - begin);
  double mean = 0.0;
  for (long i = begin; i < end; ++i) {
    mean += y[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(i - k)];
  }
  mean /= count;
  double sum = 0.0;
  for (long i = begin; i < end; ++i) {
    const double d = y[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(i - k)] - mean;
    sum += d * d;
  }
  return sum / count;
}

// The curves less the experiment's mean: a common offset changes no difference, and removing
// it keeps the FFT sums small.
struct CentredCurves {
  std::vector<double> x;  // simulation
  std::vector<double> y;  // experiment
};

CentredCurves Centre(std::span<const double> y_sim, std::span<const double> y_exp) {
  const std::size_t n = y_exp.size();
  double mean = 0.0;
  for (const double v : y_exp) mean += v;
  mean /= static_cast<double>(n);
  CentredCurves curves{std::vector<double>(n), std::vector<double>(n)};
  for (std::size_t i = 0; i < n; ++i) {
    curves.x[i] = y_sim[i] - mean;
    curves.y[i] = y_exp[i] - mean;
  }
  return curves;
}

// c(k) = Σ_i y[i]·x[i − k] for |k| ≤ max_lag at index k (k ≥ 0) or size() − |k| (k < 0).
std::vector<double> CrossCorrelation(const std::vector<double>& x, const std::vector<double>& y,
                                     std::size_t max_lag_samples) {
  // Linear (not circular) correlation for |k| ≤ max_lag needs n + max_lag points.
  const std::size_t m = SmoothSize(x.size() + max_lag_samples + 1);
  const std::size_t bins = m / 2 + 1;
  detail::RealBuffer real(m);
  detail::ComplexBuffer spec_x(bins);
  detail::ComplexBuffer spec_y(bins);
  const int m_int = static_cast<int>(m);
  const detail::FftwPlan forward_x(
      fftw_plan_dft_r2c_1d(m_int, real.data(), spec_x.data(), FFTW_ESTIMATE));
  const detail::FftwPlan forward_y(
      fftw_plan_dft_r2c_1d(m_int, real.data(), spec_y.data(), FFTW_ESTIMATE));
  const detail::FftwPlan backward(
      fftw_plan_dft_c2r_1d(m_int, spec_y.data(), real.data(), FFTW_ESTIMATE));
  std::fill(real.data(), real.data() + m, 0.0);
  std::copy(x.begin(), x.end(), real.data());
  forward_x.Execute();
  std::fill(real.data(), real.data() + m, 0.0);
  std::copy(y.begin(), y.end(), real.data());
  forward_y.Execute();
  for (std::size_t b = 0; b < bins; ++b) {
    // Y·conj(X): its inverse is c(k).
    const double re = spec_y[b][0] * spec_x[b][0] + spec_y[b][1] * spec_x[b][1];
    const double im = spec_y[b][1] * spec_x[b][0] - spec_y[b][0] * spec_x[b][1];
    spec_y[b][0] = re;
    spec_y[b][1] = im;
  }
  backward.Execute();  // c2r overwrites its input; spec_y is not used again
  std::vector<double> correlation(m);
  for (std::size_t i = 0; i < m; ++i) correlation[i] = real[i] / static_cast<double>(m);
  return correlation;
}

// Variance of y[i] − x[i − k] over the overlap for every searched lag k, from one FFT
// correlation and prefix sums instead of a pass over the curves per lag.
class LagSpreads {
 public:
  LagSpreads(const CentredCurves& curves, std::size_t max_lag_samples)
      : correlation_(CrossCorrelation(curves.x, curves.y, max_lag_samples)),
        prefix_x_(curves.x.size() + 1, 0.0),
        prefix_y_(curves.x.size() + 1, 0.0),
        prefix_xx_(curves.x.size() + 1, 0.0),
        prefix_yy_(curves.x.size() + 1, 0.0) {
    const auto& x = curves.x;
    const auto& y = curves.y;
    for (std::size_t i = 0; i < x.size(); ++i) {
      prefix_x_[i + 1] = prefix_x_[i] + x[i];
      prefix_y_[i + 1] = prefix_y_[i] + y[i];
      prefix_xx_[i + 1] = prefix_xx_[i] + x[i] * x[i];
      prefix_yy_[i + 1] = prefix_yy_[i] + y[i] * y[i];
    }
  }

  [[nodiscard]] double At(long k) const {
    const auto ln = static_cast<long>(prefix_x_.size() - 1);
    const auto y_begin = static_cast<std::size_t>(std::max(0L, k));
    const auto y_end = static_cast<std::size_t>(std::min(ln, ln + k));
    const auto x_begin = static_cast<std::size_t>(std::max(0L, -k));
    const auto x_end = static_cast<std::size_t>(std::min(ln, ln - k));
    const std::size_t index =
        k >= 0 ? static_cast<std::size_t>(k) : correlation_.size() - static_cast<std::size_t>(-k);
    const double c = correlation_[index];
    const auto count = static_cast<double>(y_end - y_begin);
    const double energy =
        (prefix_yy_[y_end] - prefix_yy_[y_begin]) + (prefix_xx_[x_end] - prefix_xx_[x_begin]);
    const double mean_diff =
        ((prefix_y_[y_end] - prefix_y_[y_begin]) - (prefix_x_[x_end] - prefix_x_[x_begin])) /
        count;
    return (energy - 2.0 * c) / count - mean_diff * mean_diff;
  }

  // A lag must beat the best so far by more than rounding noise of the FFT sums.
  [[nodiscard]] double RoundingNoise() const {
    const std::size_t n = prefix_x_.size() - 1;
    return 1e-13 * (prefix_xx_[n] + prefix_yy_[n]) / static_cast<double>(n);
  }

 private:
  std::vector<double> correlation_;
  std::vector<double> prefix_x_;
  std::vector<double> prefix_y_;
  std::vector<double> prefix_xx_;
  std::vector<double> prefix_yy_;
};

long BestWholeLag(const LagSpreads& spreads, long max_lag) {
  // Lags in the order 0, 1, -1, 2, -2, ...: with a strict '<' a tie keeps the smaller shift
  // (no delay unless the data say so).
  const double noise = spreads.RoundingNoise();
  long best = 0;
  double best_msd = spreads.At(0);
  for (long lag = 1; lag <= max_lag; ++lag) {
    for (const long k : {lag, -lag}) {
      const double v = spreads.At(k);
      if (v < best_msd - noise) {
        best_msd = v;
        best = k;
      }
    }
  }
  return best;
}

// The sub-sample part of the delay from a parabola through the spreads at best−1, best, best+1;
// also fills the spread at the best lag and whether the search hit its limit.
double SubSampleFraction(const CentredCurves& curves, long best, long max_lag,
                         DelayEstimate& estimate) {
  // The three values around the minimum are recomputed exactly: the FFT sum subtracts large
  // energies, which would blur a parabola fitted to nearly identical curves.
  const double centre = DirectSpread(curves.x, curves.y, best);
  estimate.spread_at_delay = std::sqrt(std::max(centre, 0.0));
  double fraction = 0.0;
  if (std::abs(best) < max_lag) {
    const double before = DirectSpread(curves.x, curves.y, best - 1);
    const double after = DirectSpread(curves.x, curves.y, best + 1);
    const double curvature = before - 2.0 * centre + after;
    if (curvature > 0.0) fraction = std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
    // Rounding in the three spreads leaves ~1e-15 samples where the curves have no shift;
    // no record resolves a billionth of a sample, and "6.2e-17 s" would read as a finding.
    if (std::abs(fraction) < kNoShiftSamples) fraction = 0.0;
  } else if (max_lag > 0) {
    estimate.at_search_limit = true;
  }
  return fraction;
}

}  // namespace

DelayEstimate EstimateDelay(std::span<const double> y_sim, std::span<const double> y_exp,
                            double step_s, double max_delay_s) {
  if (y_sim.size() != y_exp.size()) throw std::invalid_argument("delay: curves differ in length");
  if (y_exp.size() < 4) throw std::invalid_argument("delay: need at least four samples");
  if (!(step_s > 0.0)) throw std::invalid_argument("delay: step must be positive");
  const std::size_t n = y_exp.size();
  DelayEstimate estimate;
  const double lag_limit = std::floor(std::max(max_delay_s, 0.0) / step_s + 1e-9);
  estimate.max_lag_samples =
      std::min<std::size_t>(static_cast<std::size_t>(lag_limit), n / 2);
  const auto max_lag = static_cast<long>(estimate.max_lag_samples);

  const CentredCurves curves = Centre(y_sim, y_exp);
  const long best = BestWholeLag(LagSpreads(curves, estimate.max_lag_samples), max_lag);
  const double fraction = SubSampleFraction(curves, best, max_lag, estimate);
  estimate.delay_samples = static_cast<double>(best) + fraction;
  estimate.delay_s = estimate.delay_samples * step_s;
  return estimate;
}

}  // namespace hiltwin::analysis
