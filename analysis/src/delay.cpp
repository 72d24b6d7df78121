#include "hiltwin/analysis/delay.h"

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

  // A common offset changes no difference; removing it keeps the FFT sums small.
  double mean = 0.0;
  for (const double v : y_exp) mean += v;
  mean /= static_cast<double>(n);
  std::vector<double> x(n);
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = y_sim[i] - mean;
    y[i] = y_exp[i] - mean;
  }

  // Linear (not circular) correlation for |k| ≤ max_lag needs n + max_lag points.
  const std::size_t m = SmoothSize(n + estimate.max_lag_samples + 1);
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
    // Y·conj(X): its inverse is c(k) = Σ_i y[i]·x[i − k].
    const double re = spec_y[b][0] * spec_x[b][0] + spec_y[b][1] * spec_x[b][1];
    const double im = spec_y[b][1] * spec_x[b][0] - spec_y[b][0] * spec_x[b][1];
    spec_y[b][0] = re;
    spec_y[b][1] = im;
  }
  backward.Execute();  // c2r overwrites its input; spec_y is not used again

  std::vector<double> prefix_x(n + 1, 0.0);
  std::vector<double> prefix_y(n + 1, 0.0);
  std::vector<double> prefix_xx(n + 1, 0.0);
  std::vector<double> prefix_yy(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    prefix_x[i + 1] = prefix_x[i] + x[i];
    prefix_y[i + 1] = prefix_y[i] + y[i];
    prefix_xx[i + 1] = prefix_xx[i] + x[i] * x[i];
    prefix_yy[i + 1] = prefix_yy[i] + y[i] * y[i];
  }
  const auto ln = static_cast<long>(n);
  auto msd_fft = [&](long k) {
    const auto y_begin = static_cast<std::size_t>(std::max(0L, k));
    const auto y_end = static_cast<std::size_t>(std::min(ln, ln + k));
    const auto x_begin = static_cast<std::size_t>(std::max(0L, -k));
    const auto x_end = static_cast<std::size_t>(std::min(ln, ln - k));
    const std::size_t index = k >= 0 ? static_cast<std::size_t>(k) : m - static_cast<std::size_t>(-k);
    const double c = real[index] / static_cast<double>(m);
    const auto count = static_cast<double>(y_end - y_begin);
    const double energy =
        (prefix_yy[y_end] - prefix_yy[y_begin]) + (prefix_xx[x_end] - prefix_xx[x_begin]);
    const double mean_diff =
        ((prefix_y[y_end] - prefix_y[y_begin]) - (prefix_x[x_end] - prefix_x[x_begin])) / count;
    return (energy - 2.0 * c) / count - mean_diff * mean_diff;
  };

  // Lags in the order 0, 1, -1, 2, -2, ...: with a strict '<' a tie keeps the smaller shift
  // (no delay unless the data say so).
  // A lag must beat the best so far by more than rounding noise of the FFT sums.
  const double noise = 1e-13 * (prefix_xx[n] + prefix_yy[n]) / static_cast<double>(n);
  long best = 0;
  double best_msd = msd_fft(0);
  for (long lag = 1; lag <= max_lag; ++lag) {
    for (const long k : {lag, -lag}) {
      const double v = msd_fft(k);
      if (v < best_msd - noise) {
        best_msd = v;
        best = k;
      }
    }
  }
  // The three values around the minimum are recomputed exactly: the FFT sum subtracts large
  // energies, which would blur a parabola fitted to nearly identical curves.
  const double centre = DirectSpread(x, y, best);
  estimate.spread_at_delay = std::sqrt(std::max(centre, 0.0));
  double fraction = 0.0;
  if (std::abs(best) < max_lag) {
    const double before = DirectSpread(x, y, best - 1);
    const double after = DirectSpread(x, y, best + 1);
    const double curvature = before - 2.0 * centre + after;
    if (curvature > 0.0) fraction = std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
    // Rounding in the three spreads leaves ~1e-15 samples where the curves have no shift;
    // no record resolves a billionth of a sample, and "6.2e-17 s" would read as a finding.
    if (std::abs(fraction) < kNoShiftSamples) fraction = 0.0;
  } else if (max_lag > 0) {
    estimate.at_search_limit = true;
  }
  estimate.delay_samples = static_cast<double>(best) + fraction;
  estimate.delay_s = estimate.delay_samples * step_s;
  return estimate;
}

}  // namespace hiltwin::analysis
