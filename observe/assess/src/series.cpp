#include "hiltwin/assess/series.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hiltwin::analysis {

std::vector<double> InterpolateAt(std::span<const double> t_s, std::span<const double> y,
                                  std::span<const double> at_s) {
  if (t_s.size() != y.size() || t_s.empty()) {
    throw std::invalid_argument("InterpolateAt: time and value sizes differ or are empty");
  }
  std::vector<double> out(at_s.size());
  std::size_t k = 0;  // queries ascend, so the bracketing interval only moves forward
  const std::size_t last = t_s.size() - 1;
  for (std::size_t i = 0; i < at_s.size(); ++i) {
    const double t = at_s[i];
    if (t <= t_s.front()) {
      out[i] = y.front();
      continue;
    }
    if (t >= t_s[last]) {
      out[i] = y[last];
      continue;
    }
    while (k + 1 < last && t_s[k + 1] <= t) ++k;
    while (k > 0 && t_s[k] > t) --k;  // tolerate a query that steps back
    const double span_s = t_s[k + 1] - t_s[k];
    const double w = (t - t_s[k]) / span_s;
    out[i] = y[k] + w * (y[k + 1] - y[k]);
  }
  return out;
}

double MedianStep(std::span<const double> t_s) {
  if (t_s.size() < 2) throw std::invalid_argument("MedianStep: need two times");
  std::vector<double> steps(t_s.size() - 1);
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) steps[i] = t_s[i + 1] - t_s[i];
  const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  return *mid;
}

std::vector<double> UniformGrid(double t0_s, double t1_s, double step_s) {
  if (!(step_s > 0.0) || !(t1_s >= t0_s)) throw std::invalid_argument("UniformGrid: bad range");
  const auto n = static_cast<std::size_t>(std::floor((t1_s - t0_s) / step_s + 1e-9)) + 1;
  std::vector<double> grid(n);
  for (std::size_t i = 0; i < n; ++i) grid[i] = t0_s + static_cast<double>(i) * step_s;
  return grid;
}

bool IsUniform(std::span<const double> t_s, double tolerance) {
  if (t_s.size() < 3) return true;
  const double step = MedianStep(t_s);
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) {
    if (std::abs((t_s[i + 1] - t_s[i]) - step) > tolerance * step) return false;
  }
  return true;
}

}  // namespace hiltwin::analysis
