#pragma once
/// Sampled curves: linear interpolation onto another time base and uniform grids.

#include <cstddef>
#include <span>
#include <vector>

namespace hiltwin::analysis {

/// Value of the piecewise-linear curve (t_s, y) at each time of `at_s`. `t_s` strictly
/// increasing; `at_s` ascending and inside [t_s.front(), t_s.back()] (clamped otherwise).
[[nodiscard]] std::vector<double> InterpolateAt(std::span<const double> t_s,
                                                std::span<const double> y,
                                                std::span<const double> at_s);

/// Median of the steps between consecutive times (robust against a few odd gaps).
[[nodiscard]] double MedianStep(std::span<const double> t_s);

/// Times t0, t0 + step, ... not beyond t1 (with a rounding allowance of 1e-9 steps).
[[nodiscard]] std::vector<double> UniformGrid(double t0_s, double t1_s, double step_s);

/// True when every step is within `tolerance` (relative) of the median step.
[[nodiscard]] bool IsUniform(std::span<const double> t_s, double tolerance = 1e-6);

}  // namespace hiltwin::analysis
