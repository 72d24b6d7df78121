#pragma once
/// Time shift between two curves: cross-correlation (FFTW) with sub-sample refinement.

#include <cstddef>
#include <span>

namespace hiltwin::analysis {

/// Result of EstimateDelay. Positive delay: the experiment lags, y_exp(t) ≈ y_sim(t − delay_s).
struct DelayEstimate {
  double delay_s = 0.0;
  double delay_samples = 0.0;          ///< in grid steps, with the sub-sample part
  double spread_at_delay = 0.0;        ///< std. deviation of the difference at the best lag
  std::size_t max_lag_samples = 0;     ///< search range ± this many steps
  bool at_search_limit = false;        ///< best lag is the edge of the range: widen it
};

/// Finds the shift minimising the spread (variance) of the difference over the overlapping
/// part, V(k) = (Σy_exp² + Σy_sim² − 2·c(k)) / n_k − (mean difference)², with the
/// cross-correlation c(k) from FFTW and the sums from prefix sums, then refines the minimum
/// with a parabola through the three neighbouring lags. A constant offset does not move it. Both curves on one uniform grid of `step_s`; |lag| ≤ max_delay_s.
/// Throws std::invalid_argument for different lengths or fewer than 4 samples.
[[nodiscard]] DelayEstimate EstimateDelay(std::span<const double> y_sim,
                                          std::span<const double> y_exp, double step_s,
                                          double max_delay_s);

}  // namespace hiltwin::analysis
