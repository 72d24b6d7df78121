// `hiltwin test merge`: shard results of one campaign joined into the result one unsharded run
// would have given. Everything but the wall-clock figures and the shard list is then equal to
// that run's: the scenarios in campaign order, each as its shard measured it.

#include <algorithm>

#include "campaign_text.h"
#include "hiltwin/runs/campaign_report.h"

namespace hiltwin::app {
namespace campaign_merge {

// "result 2 (shard 2/3)": results carry no file name, the command that read them adds it.
std::string Describe(const CampaignResult& result, std::size_t position) {
  const std::string shards = campaign_text::ShardsLabel(result);
  return "result " + std::to_string(position + 1) + " (shard " + (shards.empty() ? "?" : shards) +
         ")";
}

void RefuseDifference(const CampaignResult& first, const CampaignResult& other,
                      std::size_t position, const std::string& what, const std::string& first_value,
                      const std::string& other_value) {
  throw CampaignResultError("cannot merge: " + Describe(other, position) + " and " +
                            Describe(first, 0) + " differ in " + what + ": " + other_value +
                            " against " + first_value +
                            ": merge the shards of one run of one campaign file");
}

// Shards of one run share the campaign, its file and scenario count, and --filter.
void CheckSameCampaign(const CampaignResult& first, const CampaignResult& other,
                       std::size_t position) {
  if (other.file != first.file) {
    RefuseDifference(first, other, position, "campaign file", "'" + first.file + "'",
                     "'" + other.file + "'");
  }
  if (other.scenarios_in_file != first.scenarios_in_file) {
    RefuseDifference(first, other, position, "scenarios in the file",
                     std::to_string(first.scenarios_in_file),
                     std::to_string(other.scenarios_in_file));
  }
  if (other.name != first.name) {
    RefuseDifference(first, other, position, "campaign name", "'" + first.name + "'",
                     "'" + other.name + "'");
  }
  if (other.filter != first.filter) {
    RefuseDifference(first, other, position, "--filter", "'" + first.filter + "'",
                     "'" + other.filter + "'");
  }
}

void SortAndCheckShards(std::vector<ShardSpec>& shards) {
  std::sort(shards.begin(), shards.end(), [](const ShardSpec& a, const ShardSpec& b) {
    return a.count != b.count ? a.count < b.count : a.index < b.index;
  });
  const auto label = [](const ShardSpec& shard) {
    return std::to_string(shard.index) + "/" + std::to_string(shard.count);
  };
  for (std::size_t i = 1; i < shards.size(); ++i) {
    if (shards[i].count != shards[0].count) {
      throw CampaignResultError("cannot merge: shard " + label(shards[i]) + " beside shard " +
                                label(shards[0]) +
                                ": the results come from runs split differently (--shard K/N)");
    }
    if (shards[i].index == shards[i - 1].index) {
      throw CampaignResultError("cannot merge: shard " + label(shards[i]) +
                                " is given twice: give each shard's result once");
    }
  }
  // A shard left out would leave its scenarios out of the joined result unseen: a grade made
  // of part of the campaign.
  std::string missing;
  for (std::size_t k = 1, i = 0; k <= shards.front().count; ++k) {
    if (i < shards.size() && shards[i].index == k) {
      ++i;
    } else {
      missing += (missing.empty() ? "" : ", ") + label({k, shards.front().count});
    }
  }
  if (!missing.empty()) {
    throw CampaignResultError("cannot merge: shard " + missing +
                              " is missing: give the result of every shard of the run");
  }
}

void SortAndCheckScenarios(std::vector<ScenarioResult>& scenarios) {
  std::stable_sort(
      scenarios.begin(), scenarios.end(),
      [](const ScenarioResult& a, const ScenarioResult& b) { return a.index < b.index; });
  for (std::size_t i = 1; i < scenarios.size(); ++i) {
    if (scenarios[i].index == scenarios[i - 1].index) {
      throw CampaignResultError("cannot merge: scenario " + std::to_string(scenarios[i].index) +
                                " ('" + scenarios[i].name +
                                "') is in two of the results: give each shard's result once");
    }
  }
}

}  // namespace campaign_merge

CampaignResult MergeCampaignResults(std::vector<CampaignResult> shards) {
  if (shards.empty()) {
    throw CampaignResultError(
        "nothing to merge: give the JSON results of a campaign's shards (hiltwin test --shard "
        "K/N --json FILE)");
  }
  CampaignResult merged;
  merged.name = shards.front().name;
  merged.file = shards.front().file;
  merged.scenarios_in_file = shards.front().scenarios_in_file;
  merged.filter = shards.front().filter;
  for (std::size_t position = 0; position < shards.size(); ++position) {
    CampaignResult& part = shards[position];
    campaign_merge::CheckSameCampaign(shards.front(), part, position);
    merged.shards.insert(merged.shards.end(), part.shards.begin(), part.shards.end());
    std::move(part.scenarios.begin(), part.scenarios.end(), std::back_inserter(merged.scenarios));
    // The shards ran side by side: the campaign took as long as the slowest.
    merged.wall_s = std::max(merged.wall_s, part.wall_s);
  }
  campaign_merge::SortAndCheckShards(merged.shards);
  campaign_merge::SortAndCheckScenarios(merged.scenarios);
  return merged;
}

}  // namespace hiltwin::app
