#pragma once
/// `hiltwin test`'s outputs, every one derived from the typed CampaignResult: the JSON result
/// (which `hiltwin test merge` reads back), JUnit XML for CI servers, one self-contained HTML
/// page, the progress line of a scenario and the closing summary. Pure: strings in, strings out.

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/runs/campaign_result.h"

namespace hiltwin::app {

/// A JSON result that cannot be read back, or shards that do not join: what, where, what to do.
class CampaignResultError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The JSON result: {"format": "hiltwin-campaign-result/1", "campaign", "file",
/// "scenarios_in_file", "filter", "shards", "passed", "failed", "exit_code", "scenarios": [...],
/// "wall_s"}; each scenario with its criteria and plot and its own "wall_s". Numbers are
/// written so they read back as the same doubles.
[[nodiscard]] nlohmann::ordered_json ToJson(const CampaignResult& result);

/// Reads a JSON result back. Throws CampaignResultError naming `source` and the key.
[[nodiscard]] CampaignResult CampaignResultFromJson(const nlohmann::json& json,
                                                    std::string_view source);

/// Joins shard results of one campaign into one result, scenarios in campaign order, wall_s
/// the largest shard's. Throws CampaignResultError when they name different campaign files or
/// scenario counts, when two hold the same shard or the same scenario, or when none is given.
[[nodiscard]] CampaignResult MergeCampaignResults(std::vector<CampaignResult> shards);

/// JUnit XML (the schema Jenkins, GitLab and GitHub read): one <testsuite> named after the
/// campaign, one <testcase classname="CAMPAIGN" name="SCENARIO" time="wall_s"> per scenario,
/// and for a failed one a <failure message=...> per failed criterion ("tracking_max_m:
/// measured 0.0041 m, required <= 0.003 m") or its error.
[[nodiscard]] std::string ToJunitXml(const CampaignResult& result);

/// One self-contained HTML page (no script or style from elsewhere): a table (scenario,
/// criterion, required, measured, pass/fail) and each scenario's plot as inline SVG.
[[nodiscard]] std::string ToHtml(const CampaignResult& result);

/// "[3/12] PASS step_response 0.41 s" or "[4/12] FAIL burst_lost_frames 0.39 s:
/// tracking_max_m measured 0.0041 m, required <= 0.003 m": the line printed as a scenario ends.
[[nodiscard]] std::string FormatScenarioLine(const ScenarioResult& scenario, std::size_t done,
                                             std::size_t total);

/// The closing summary: one row per scenario (name, pass/fail, failed criteria), then
/// "N passed, M failed of K (campaign NAME)".
[[nodiscard]] std::string FormatCampaignSummary(const CampaignResult& result);

}  // namespace hiltwin::app
