#include "campaign_text.h"

#include <algorithm>

#include "hiltwin/report_kit/string_format.h"
#include "hiltwin/runs/campaign_report.h"

namespace hiltwin::app {
namespace campaign_text {

using analysis::detail::Format;

std::string Quantity(double value, const std::string& unit) {
  // "1" is a count or a score: a number without a unit reads best.
  const bool unitless = unit.empty() || unit == "1";
  return Format("%.4g", value) + (unitless ? "" : " " + unit);
}

// The verdict criterion has texts, every other criterion numbers.
static bool IsTextCriterion(const CriterionResult& criterion) {
  return !criterion.required.has_value() && !criterion.required_text.empty();
}

std::string Required(const CriterionResult& criterion) {
  if (IsTextCriterion(criterion)) return criterion.relation + " " + criterion.required_text;
  if (!criterion.required) return criterion.relation + " nothing (no bound was given)";
  return criterion.relation + " " + Quantity(*criterion.required, criterion.unit);
}

std::string Measured(const CriterionResult& criterion) {
  if (IsTextCriterion(criterion)) {
    return criterion.measured_text.empty() ? "nothing (the run gave no verdict)"
                                           : criterion.measured_text;
  }
  if (!criterion.measured) return "nothing (the run gave no figure)";
  return Quantity(*criterion.measured, criterion.unit);
}

std::string Shortfall(const CriterionResult& criterion) {
  return "measured " + Measured(criterion) + ", required " + Required(criterion);
}

std::string WallTime(double wall_s) { return Format("%.2f s", wall_s); }

std::string OneLine(std::string text) {
  std::replace_if(
      text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r' || c == '\t'; }, ' ');
  return text;
}

std::string FailureReasons(const ScenarioResult& scenario) {
  if (!scenario.error.empty()) return "error: " + OneLine(scenario.error);
  std::string reasons;
  for (const CriterionResult& criterion : scenario.criteria) {
    if (criterion.passed) continue;
    if (!reasons.empty()) reasons += "; ";
    reasons += criterion.name + " " + Shortfall(criterion);
  }
  return reasons;
}

std::string ShardsLabel(const CampaignResult& result) {
  std::string label;
  for (const ShardSpec& shard : result.shards) {
    if (!label.empty()) label += "+";
    label += std::to_string(shard.index) + "/" + std::to_string(shard.count);
  }
  return label;
}

}  // namespace campaign_text

std::string FormatScenarioLine(const ScenarioResult& scenario, std::size_t done,
                               std::size_t total) {
  const bool passed = scenario.passed();
  std::string line = "[" + std::to_string(done) + "/" + std::to_string(total) + "] " +
                     (passed ? "PASS " : "FAIL ") + scenario.name + " " +
                     campaign_text::WallTime(scenario.wall_s);
  if (!passed) line += ": " + campaign_text::FailureReasons(scenario);
  return line;
}

std::string FormatCampaignSummary(const CampaignResult& result) {
  std::size_t name_width = 0;
  for (const ScenarioResult& scenario : result.scenarios) {
    name_width = std::max(name_width, scenario.name.size());
  }
  std::string summary;
  for (const ScenarioResult& scenario : result.scenarios) {
    if (scenario.passed()) {
      summary += "  PASS  " + scenario.name + "\n";
      continue;
    }
    // Failed rows align their reasons in one column after the longest name.
    summary += "  FAIL  " + scenario.name + std::string(name_width - scenario.name.size(), ' ') +
               "  " + campaign_text::FailureReasons(scenario) + "\n";
  }
  const std::size_t failed = result.failed();
  summary += std::to_string(result.scenarios.size() - failed) + " passed, " +
             std::to_string(failed) + " failed of " + std::to_string(result.scenarios.size()) +
             " (campaign " + result.name + ")\n";
  return summary;
}

}  // namespace hiltwin::app
