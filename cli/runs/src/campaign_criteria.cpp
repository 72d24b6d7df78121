// `hiltwin test`'s pass criteria, the pure half: the step and saturation figures and the
// judgement of each bound. What reads a scenario's files is campaign_measure.cpp.
#include "hiltwin/runs/campaign_criteria.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>

namespace hiltwin::app {
// The helpers' own namespace: the runs library compiles in unity batches, where two files'
// anonymous namespaces are one.
namespace criteria_figures {
namespace {

/// Position of a verdict from best (0) to worst; "" and anything unknown are the worst: a
/// side without a verdict has not shown that its timing was good.
int VerdictRank(const std::string& verdict) noexcept {
  if (verdict == "PASS") return 0;
  if (verdict == "FLAGGED") return 1;
  if (verdict == "ABORTED") return 2;
  if (verdict == "NONE") return 3;
  return 4;
}

/// The sample after the setpoint's largest jump: row k holds the new setpoint, row k - 1 the
/// old. The first of equal jumps wins. Returns 0 when the setpoint never changes.
std::size_t StepIndex(std::span<const double> setpoint_m) noexcept {
  std::size_t step_index = 0;
  double largest_jump_m = 0.0;
  for (std::size_t k = 1; k < setpoint_m.size(); ++k) {
    const double jump_m = std::abs(setpoint_m[k] - setpoint_m[k - 1]);
    if (jump_m > largest_jump_m) {
      largest_jump_m = jump_m;
      step_index = k;
    }
  }
  return step_index;
}

/// From sample `from` on: the time of the first sample after which the position stays within
/// `band_m` of the target to the end, minus the step's time; +inf when the last is outside.
double SettlingTimeS(std::span<const double> time_s, std::span<const double> position_m,
                     std::size_t from, double target_m, double band_m) noexcept {
  std::size_t settled_from = from;
  for (std::size_t i = from; i < position_m.size(); ++i) {
    if (std::abs(position_m[i] - target_m) > band_m) settled_from = i + 1;
  }
  if (settled_from == position_m.size()) return std::numeric_limits<double>::infinity();
  return time_s[settled_from] - time_s[from];
}

CriterionResult Bound(const char* name, const char* unit, const char* relation, double required,
                      std::optional<double> measured) {
  CriterionResult r;
  r.name = name;
  r.unit = unit;
  r.relation = relation;
  r.required = required;
  r.measured = measured;
  // A bound equal to the figure passes ("at most" / "at least"); NaN never does.
  const bool at_least = r.relation == ">=";
  r.passed = measured.has_value() && (at_least ? *measured >= required : *measured <= required);
  return r;
}

CriterionResult VerdictCriterion(const std::string& required, const std::string& measured) {
  CriterionResult r;
  r.name = "verdict";
  r.relation = "at most";
  r.required_text = required;
  r.measured_text = measured;
  r.passed = VerdictRank(measured) <= VerdictRank(required);
  return r;
}

std::optional<double> AsDouble(std::optional<std::uint64_t> count) {
  if (!count) return std::nullopt;
  return static_cast<double>(*count);
}

}  // namespace
}  // namespace criteria_figures

bool NeedsLog(const CampaignCriteria& c) noexcept {
  return c.settling_time_s.has_value() || c.overshoot_pct.has_value() ||
         c.duty_saturation_pct.has_value() || c.credibility_min.has_value();
}

// The target is the setpoint's last value, not the value right after the jump: the same for a
// step that then holds, and the place the wheel must reach when the largest jump is one sample
// of a steep ramp.
StepResponse MeasureStep(std::span<const double> time_s, std::span<const double> setpoint_m,
                         std::span<const double> position_m, double band_pct) {
  if (time_s.size() != setpoint_m.size() || time_s.size() != position_m.size()) {
    throw std::invalid_argument("MeasureStep: time, setpoint and position differ in length");
  }
  if (time_s.size() < 2) throw std::invalid_argument("MeasureStep: fewer than 2 samples");
  const std::size_t k = criteria_figures::StepIndex(setpoint_m);
  if (k == 0) throw std::invalid_argument("MeasureStep: the setpoint has no step");
  StepResponse r;
  r.step_time_s = time_s[k];
  r.step_m = setpoint_m[k] - setpoint_m[k - 1];
  const double target_m = setpoint_m.back();
  const double direction = r.step_m > 0.0 ? 1.0 : -1.0;
  const double step_size_m = std::abs(r.step_m);
  double beyond_m = 0.0;
  for (std::size_t i = k; i < position_m.size(); ++i) {
    beyond_m = std::max(beyond_m, (position_m[i] - target_m) * direction);
  }
  r.overshoot_pct = beyond_m / step_size_m * 100.0;
  r.settling_time_s = criteria_figures::SettlingTimeS(time_s, position_m, k, target_m,
                                                      band_pct / 100.0 * step_size_m);
  return r;
}

// Spans of different lengths are compared over the samples both hold; none gives 0 %.
double DutySaturationPct(std::span<const double> duty_left, std::span<const double> duty_right,
                         double duty_limit) {
  const std::size_t samples = std::min(duty_left.size(), duty_right.size());
  if (samples == 0) return 0.0;
  const double full_duty = 0.999 * duty_limit;
  std::size_t saturated = 0;
  for (std::size_t i = 0; i < samples; ++i) {
    if (std::abs(duty_left[i]) >= full_duty || std::abs(duty_right[i]) >= full_duty) ++saturated;
  }
  return static_cast<double>(saturated) / static_cast<double>(samples) * 100.0;
}

std::vector<CriterionResult> Judge(const CampaignCriteria& c, const ScenarioMeasures& m) {
  std::vector<CriterionResult> results;
  if (c.verdict) results.push_back(criteria_figures::VerdictCriterion(*c.verdict, m.verdict));
  const auto at_most = [&](const char* name, const char* unit, const std::optional<double>& bound,
                           const std::optional<double>& measured) {
    if (bound) results.push_back(criteria_figures::Bound(name, unit, "<=", *bound, measured));
  };
  at_most("tracking_max_m", "m", c.tracking_max_m, m.tracking_max_m);
  at_most("tracking_rms_m", "m", c.tracking_rms_m, m.tracking_rms_m);
  at_most("final_error_m", "m", c.final_error_m, m.final_error_m);
  at_most("settling_time_s", "s", c.settling_time_s, m.settling_time_s);
  at_most("overshoot_pct", "%", c.overshoot_pct, m.overshoot_pct);
  at_most("duty_saturation_pct", "%", c.duty_saturation_pct, m.duty_saturation_pct);
  at_most("missed_deadlines", "1", criteria_figures::AsDouble(c.missed_deadlines),
          criteria_figures::AsDouble(m.missed_deadlines));
  if (c.credibility_min) {
    results.push_back(
        criteria_figures::Bound("credibility_min", "1", ">=", *c.credibility_min, m.credibility));
  }
  return results;
}

std::string WorseVerdict(const std::string& a, const std::string& b) {
  return criteria_figures::VerdictRank(a) >= criteria_figures::VerdictRank(b) ? a : b;
}

}  // namespace hiltwin::app
