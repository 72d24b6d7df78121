#pragma once
/// Independent measures reported beside the credibility score: Theil's inequality coefficient
/// and the ISO/TS 18571 objective rating. Simplifications: docs/credibility.md.

#include <cstddef>
#include <span>
#include <string>

namespace hiltwin::analysis {

/// Theil (1966): U = RMS(s − e) / (RMS(s) + RMS(e)), 0 = perfect, 1 = worst; and the split
/// of the mean squared error into bias, variance and covariance proportions (sum 1).
struct TheilCoefficients {
  double u = 0.0;
  double bias = 0.0;        ///< (mean s − mean e)² / MSE
  double variance = 0.0;    ///< (σ_s − σ_e)² / MSE
  double covariance = 0.0;  ///< 2(1 − ρ)σ_sσ_e / MSE
};

/// Throws std::invalid_argument for different lengths or fewer than two samples.
[[nodiscard]] TheilCoefficients TheilInequality(std::span<const double> y_sim,
                                                std::span<const double> y_exp);

/// ISO/TS 18571:2014 rating of a comparison curve against a reference, each in [0, 1].
struct IsoRating {
  double corridor = 0.0;
  double phase = 0.0;
  double magnitude = 0.0;
  double slope = 0.0;
  double overall = 0.0;            ///< 0.4·corridor + 0.2·(phase + magnitude + slope)
  long phase_shift_samples = 0;    ///< shift with the best Pearson correlation
  std::size_t samples = 0;
  std::string grade;               ///< excellent > 0.94 ≥ good > 0.80 ≥ fair > 0.58 ≥ poor
};

/// Rates `comparison` (the simulation) against `reference` (the experiment): both on one
/// uniform grid. Throws std::invalid_argument for different lengths or fewer than 20 samples.
[[nodiscard]] IsoRating Iso18571Rating(std::span<const double> reference,
                                       std::span<const double> comparison);

}  // namespace hiltwin::analysis
