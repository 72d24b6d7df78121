#include "hiltwin/assess/credibility.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hiltwin::analysis {
namespace {

constexpr double kRiseLow = 0.1;
constexpr double kRiseHigh = 0.9;
constexpr double kSettleBand = 0.02;
constexpr double kFinalFraction = 0.05;
constexpr double kOvershootFloorPct = 1.0;

// First time the normalised response z reaches `level`, linearly interpolated.
std::optional<double> FirstCrossing(std::span<const double> t_s, std::span<const double> z,
                                    double level) {
  if (z.front() >= level) return t_s.front();
  for (std::size_t i = 1; i < z.size(); ++i) {
    if (z[i] >= level) {
      const double w = (level - z[i - 1]) / (z[i] - z[i - 1]);
      return t_s[i - 1] + w * (t_s[i] - t_s[i - 1]);
    }
  }
  return std::nullopt;
}

}  // namespace

double NormalisationFactor(double eta_pass) {
  if (!(eta_pass > 0.0 && eta_pass < 1.0)) {
    throw std::invalid_argument("eta_pass must lie strictly between 0 and 1");
  }
  return eta_pass / std::sqrt(1.0 - eta_pass * eta_pass);
}

double CredibilityScore(double error, double threshold, double eta_pass) {
  if (!std::isfinite(error) || !std::isfinite(threshold) || error < 0.0 || !(threshold > 0.0)) {
    throw std::invalid_argument("credibility score needs an error >= 0 and a threshold > 0");
  }
  const double scaled = NormalisationFactor(eta_pass) * threshold;
  return scaled / std::hypot(scaled, error);
}

TimeDomainScore ScoreTimeDomain(std::span<const double> y_sim, std::span<const double> y_exp,
                                const CredibilityParams& params) {
  if (y_sim.size() != y_exp.size()) {
    throw std::invalid_argument("time domain: curves have different lengths");
  }
  if (y_exp.size() < 2) throw std::invalid_argument("time domain: need at least two samples");
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < y_exp.size(); ++i) {
    const double d = y_exp[i] - y_sim[i];
    sum_sq += d * d;
  }
  const auto [lo, hi] = std::minmax_element(y_exp.begin(), y_exp.end());
  TimeDomainScore score;
  score.samples = y_exp.size();
  score.e_t = std::sqrt(sum_sq / static_cast<double>(y_exp.size()));
  score.eps_t = params.kp * (*hi - *lo);
  if (!(score.eps_t > 0.0)) {
    throw std::invalid_argument("time domain: the experiment curve is constant, so eps_t = 0");
  }
  score.k_e = NormalisationFactor(params.eta_pass);
  score.eta = CredibilityScore(score.e_t, score.eps_t, params.eta_pass);
  return score;
}

StepMetrics ComputeStepMetrics(std::span<const double> t_s, std::span<const double> y,
                               std::optional<double> setpoint) {
  if (t_s.size() != y.size() || t_s.size() < 3) {
    throw std::invalid_argument("step metrics: need at least three aligned samples");
  }
  StepMetrics m;
  const std::size_t n = y.size();
  const auto tail = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(kFinalFraction * static_cast<double>(n))));
  double tail_sum = 0.0;
  for (std::size_t i = n - tail; i < n; ++i) tail_sum += y[i];
  m.initial_value = y.front();
  m.final_value = tail_sum / static_cast<double>(tail);
  if (setpoint) m.steady_state_error = *setpoint - m.final_value;
  const double height = m.final_value - m.initial_value;
  double scale = 0.0;
  for (const double v : y) scale = std::max(scale, std::abs(v));
  if (!(std::abs(height) > 1e-12 * std::max(scale, 1e-300))) return m;  // no step

  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i) z[i] = (y[i] - m.initial_value) / height;
  const double t0 = t_s.front();
  const auto low = FirstCrossing(t_s, z, kRiseLow);
  const auto high = FirstCrossing(t_s, z, kRiseHigh);
  if (low && high) m.rise_time_s = *high - *low;

  const auto peak = std::max_element(z.begin(), z.end());
  const double overshoot = std::max(0.0, (*peak - 1.0) * 100.0);
  m.overshoot_pct = overshoot;
  if (overshoot > kSettleBand * 100.0) {
    m.peak_time_s = t_s[static_cast<std::size_t>(peak - z.begin())] - t0;
  }

  // Settling: the last excursion outside ±2 % ends where the curve re-enters the band.
  std::size_t last_out = n;
  for (std::size_t i = n; i-- > 0;) {
    if (std::abs(z[i] - 1.0) > kSettleBand) {
      last_out = i;
      break;
    }
  }
  if (last_out == n) {
    m.settling_time_s = 0.0;
  } else if (last_out + 1 < n) {
    const double above = z[last_out] > 1.0 ? 1.0 + kSettleBand : 1.0 - kSettleBand;
    const double w = (above - z[last_out]) / (z[last_out + 1] - z[last_out]);
    m.settling_time_s = t_s[last_out] + std::clamp(w, 0.0, 1.0) * (t_s[last_out + 1] - t_s[last_out]) - t0;
  }
  return m;
}

std::optional<PerformanceScore> ScorePerformance(std::span<const double> t_s,
                                                 std::span<const double> y_sim,
                                                 std::span<const double> y_exp,
                                                 std::optional<double> setpoint,
                                                 const CredibilityParams& params) {
  if (t_s.size() != y_sim.size() || t_s.size() != y_exp.size() || t_s.size() < 3) {
    throw std::invalid_argument("performance domain: need at least three aligned samples");
  }
  PerformanceScore score;
  score.t0_s = t_s.front();
  score.t1_s = t_s.back();
  score.samples = t_s.size();
  score.exp = ComputeStepMetrics(t_s, y_exp, std::nullopt);
  const double height_exp = score.exp.final_value - score.exp.initial_value;
  if (!score.exp.overshoot_pct) return std::nullopt;  // the experiment shows no step
  score.setpoint_given = setpoint.has_value();
  score.setpoint = setpoint.value_or(score.exp.final_value);
  score.exp = ComputeStepMetrics(t_s, y_exp, score.setpoint);
  score.sim = ComputeStepMetrics(t_s, y_sim, score.setpoint);

  double step_s = t_s[1] - t_s[0];
  for (std::size_t i = 1; i + 1 < t_s.size(); ++i) step_s = std::min(step_s, t_s[i + 1] - t_s[i]);
  const double time_floor = std::max(step_s, 0.0);
  struct Spec {
    const char* name;
    const char* label;
    std::optional<double> StepMetrics::*member;
    double floor;
    bool one_sided_scores_zero;  // undefined for one curve only: a real disagreement
  };
  const Spec specs[] = {
      {"rise_time_s", "rise time 10-90 % [s]", &StepMetrics::rise_time_s, time_floor, true},
      {"overshoot_pct", "overshoot [%]", &StepMetrics::overshoot_pct, kOvershootFloorPct, true},
      {"settling_time_s", "settling time 2 % [s]", &StepMetrics::settling_time_s, time_floor, true},
      {"peak_time_s", "peak time [s]", &StepMetrics::peak_time_s, time_floor, false},
      {"steady_state_error", "steady-state error", &StepMetrics::steady_state_error,
       params.kp * std::abs(height_exp), true},
  };
  double sum = 0.0;
  std::size_t count = 0;
  for (const Spec& spec : specs) {
    MetricScore metric;
    metric.name = spec.name;
    metric.label = spec.label;
    metric.sim = score.sim.*(spec.member);
    metric.exp = score.exp.*(spec.member);
    if (metric.sim && metric.exp) {
      metric.scored = true;
      metric.error = std::abs(*metric.sim - *metric.exp);
      metric.threshold = std::max(params.kp * std::abs(*metric.exp), spec.floor);
      if (!(metric.threshold > 0.0)) metric.threshold = spec.floor > 0.0 ? spec.floor : 1e-12;
      metric.eta = CredibilityScore(metric.error, metric.threshold, params.eta_pass);
    } else if ((metric.sim.has_value() != metric.exp.has_value()) && spec.one_sided_scores_zero) {
      metric.scored = true;
      metric.eta = 0.0;
    }
    if (metric.scored) {
      sum += metric.eta;
      ++count;
    }
    score.metrics.push_back(std::move(metric));
  }
  score.eta = count > 0 ? sum / static_cast<double>(count) : 0.0;
  return score;
}

}  // namespace hiltwin::analysis
