#pragma once
/// Credibility scores of Dai, Ke, Quan and Cai (2021) as the thesis uses them (§2.4.1,
/// appendix C), plus the performance-domain mapping hiltwin chose. Formulas and sources:
/// docs/credibility.md.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace hiltwin::analysis {

/// The two user parameters of the method (thesis §5.6.2: Kp = 0.05, η_pass = 0.6).
struct CredibilityParams {
  double kp = 0.05;        ///< confidence interval: acceptable error as a fraction
  double eta_pass = 0.6;   ///< passing score, in (0, 1)
};

/// K_e = η_pass / √(1 − η_pass²): makes η = η_pass when the error equals its threshold.
/// Throws std::invalid_argument unless 0 < η_pass < 1.
[[nodiscard]] double NormalisationFactor(double eta_pass);

/// η = K_e·ε / √((K_e·ε)² + e²) for error e ≥ 0 and threshold ε > 0 (η = 1 when e = 0).
/// Throws std::invalid_argument for ε ≤ 0, e < 0 or non-finite input.
[[nodiscard]] double CredibilityScore(double error, double threshold, double eta_pass);

/// One error mapped through the η function, with its parts for printing.
struct DomainScore {
  double e = 0.0;    ///< error
  double eps = 0.0;  ///< error threshold
  double k_e = 0.0;  ///< normalisation factor
  double eta = 0.0;  ///< score in [0, 1]
};

/// Time-domain score: e_t = RMS(y_e − y_s), ε_t = Kp·(max y_e − min y_e).
struct TimeDomainScore {
  double e_t = 0.0;
  double eps_t = 0.0;
  double k_e = 0.0;
  double eta = 0.0;
  std::size_t samples = 0;
};

/// Thesis §2.4.1 / appendix C on equally long, sample-aligned curves. Throws
/// std::invalid_argument for different lengths, fewer than two samples or a constant y_exp.
[[nodiscard]] TimeDomainScore ScoreTimeDomain(std::span<const double> y_sim,
                                              std::span<const double> y_exp,
                                              const CredibilityParams& params);

/// Step-response metrics of one curve (null where undefined: no step, never reached, ...).
struct StepMetrics {
  double initial_value = 0.0;  ///< first sample of the segment
  double final_value = 0.0;    ///< mean of the last 5 % of the segment
  std::optional<double> rise_time_s;         ///< 10 % → 90 % of the step, interpolated
  std::optional<double> overshoot_pct;       ///< (peak − final)/(final − initial)·100, ≥ 0
  std::optional<double> settling_time_s;     ///< from segment start until it stays in ±2 %
  std::optional<double> peak_time_s;         ///< from segment start; only when overshoot > 2 %
  std::optional<double> steady_state_error;  ///< setpoint − final value
};

/// Metrics of the curve (t_s, y) taken as a step response starting at t_s.front().
/// `setpoint` defaults to nothing (steady-state error then null).
[[nodiscard]] StepMetrics ComputeStepMetrics(std::span<const double> t_s,
                                             std::span<const double> y,
                                             std::optional<double> setpoint);

/// One performance metric of both curves and its score.
struct MetricScore {
  std::string name;   ///< JSON key, e.g. "rise_time_s"
  std::string label;  ///< for the table, e.g. "rise time 10-90 %"
  std::optional<double> sim;
  std::optional<double> exp;
  bool scored = false;  ///< false: undefined for both curves, left out of the mean
  double error = 0.0;   ///< |sim − exp|
  double threshold = 0.0;
  double eta = 0.0;
};

/// Performance domain: per-metric η and their mean.
struct PerformanceScore {
  double t0_s = 0.0;
  double t1_s = 0.0;
  std::size_t samples = 0;
  double setpoint = 0.0;
  bool setpoint_given = false;  ///< false: the experiment's final value was used
  StepMetrics sim;
  StepMetrics exp;
  std::vector<MetricScore> metrics;
  double eta = 0.0;  ///< mean over scored metrics
};

/// Scores the step-response metrics of two aligned curves on (t_s) from t_s.front(). The
/// threshold is max(Kp·|metric_exp|, floor): floors are one sample step for times, 1
/// percentage point for overshoot, Kp·|step height of y_exp| for the steady-state error.
/// Returns nullopt when y_exp has no step (final == initial).
[[nodiscard]] std::optional<PerformanceScore> ScorePerformance(
    std::span<const double> t_s, std::span<const double> y_sim, std::span<const double> y_exp,
    std::optional<double> setpoint, const CredibilityParams& params);

}  // namespace hiltwin::analysis
