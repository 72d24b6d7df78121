#pragma once
/// `hiltwin test`'s run: a campaign's scenarios, each a `hiltwin hil` or `hiltwin run` process
/// of this binary, up to `jobs` lockstep scenarios at once (a real-time scenario runs alone),
/// each judged on its criteria as it ends (campaign_criteria.h), then the JSON result, JUnit XML
/// and HTML page (campaign_report.h); and `hiltwin test merge`, which joins shards' results.
/// No scheduler of our own: sharding is for the cluster's (Slurm arrays, GitLab parallel:).

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runs/campaign_result.h"

namespace hiltwin::app {

/// Where the outputs go; "" for an output not asked for.
struct CampaignOutputs {
  std::string json_path;
  std::string junit_path;
  std::string html_path;
};

struct CampaignRunOptions {
  std::string campaign_path;
  std::string controller;      ///< --controller: every hil scenario's controller ("": the file's)
  std::string controller_map;  ///< --controller-map, with --controller
  std::size_t jobs = 1;        ///< lockstep scenarios at once, >= 1
  ShardSpec shard;             ///< checked: 1 <= index <= count
  std::string filter;          ///< glob on scenario names (fnmatch); "": all
  bool fail_fast = false;      ///< start no scenario after the first that failed
  std::string keep_dir;        ///< keep each scenario's logs and reports in DIR/NAME; "": none
  CampaignOutputs outputs;
  bool progress = true;  ///< a line per scenario as it starts and ends
};

/// "K/N" (1 <= K <= N). Throws std::invalid_argument saying what is wrong.
[[nodiscard]] ShardSpec ParseShard(const std::string& text);

/// The shard a cluster's job array gives this process, or nullopt when none is set:
/// SLURM_ARRAY_TASK_ID (from SLURM_ARRAY_TASK_MIN, default 0) of SLURM_ARRAY_TASK_COUNT, or
/// GitLab's CI_NODE_INDEX (1-based) of CI_NODE_TOTAL. Throws std::invalid_argument naming the
/// variable when one is set and not a whole number in range.
[[nodiscard]] std::optional<ShardSpec> ShardFromEnvironment(
    const std::map<std::string, std::string>& environment);

/// Runs the campaign; returns 0 (all passed), 3 (one failed) or, when an output cannot be
/// written, 5. Throws CommandError: exit 2 for a campaign file that cannot be used or a
/// controller that cannot be loaded, 5 for a folder that cannot be made.
int RunCampaign(const CampaignRunOptions& o);

/// Joins shard results (JSON files) into one result and writes `outputs`; prints the summary.
/// Returns the joined result's exit code (0 or 3), 5 when an output cannot be written.
/// Throws CommandError: exit 2 for a file that is not a shard result or shards that do not join.
int RunCampaignMerge(const std::vector<std::string>& inputs, const CampaignOutputs& outputs);

}  // namespace hiltwin::app
