#pragma once
/// `hiltwin test`'s result: one typed record per campaign (CampaignResult) from which the JSON
/// result, the JUnit XML, the HTML page, the progress lines and the exit code all derive
/// (campaign_report.h). `hiltwin test merge` reads shards' JSON results back into this record
/// and joins them. Wall-clock figures are kept apart (`wall_s`), so that a lockstep campaign run
/// twice gives the same record in everything else (docs/testing-campaigns.md).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace hiltwin::app {

/// One pass criterion of a scenario, measured. A number criterion has `required` and
/// `measured` (nullopt: the run gave no figure, e.g. it ended before the ECS wrote a report);
/// the verdict criterion has its texts instead (`required_text` "FLAGGED", `measured_text`
/// "ABORTED").
struct CriterionResult {
  std::string name;      ///< the campaign key: "tracking_max_m", "verdict", "credibility_min", ...
  std::string unit;      ///< "m", "s", "%", "1" (a count or a score), "" for the verdict
  std::string relation;  ///< "<=" (at most) or ">=" (at least); "at most" for the verdict
  std::optional<double> required;
  std::optional<double> measured;
  std::string required_text;  ///< the verdict criterion only
  std::string measured_text;  ///< the verdict criterion only
  bool passed = false;
};

/// One curve of a scenario's plot, sampled at ScenarioPlot::time_s.
struct PlotSeries {
  std::string name;  ///< the log's column: "setpoint_left_m", "wheel_left_m", ...
  std::vector<double> values;
};

/// What the HTML page draws for a scenario: its tracking (closed loop: setpoint and wheel of
/// the left wheel) or its wheel positions (open loop), at most kMaxPlotPoints points.
struct ScenarioPlot {
  static constexpr std::size_t kMaxPlotPoints = 400;
  std::string y_unit;  ///< "m"
  std::vector<double> time_s;
  std::vector<PlotSeries> series;
};

/// One scenario after it ran (or could not).
struct ScenarioResult {
  std::size_t index = 0;  ///< 0-based position in the campaign file: the order of every output
  std::string name;
  std::string kind;        ///< "hil" or "run"
  std::string clock;       ///< "virtual" or "realtime"
  std::string controller;  ///< the spec the ECS ran ("pid", "lib:/abs/x.so"); "" for kind run
  int exit_code = 0;       ///< the scenario's command's exit code (hil's or run's)
  std::string verdict;     ///< the worse verdict of its sides: PASS, FLAGGED, ABORTED, NONE, ""
  /// Why the scenario could not be judged (its command crashed, wrote no report, a log could
  /// not be read); empty when it ran. A scenario with an error fails.
  std::string error;
  std::vector<CriterionResult> criteria;
  ScenarioPlot plot;
  double wall_s = 0.0;  ///< wall-clock time of the scenario: not compared between runs
  /// Every criterion passed and there is no error.
  [[nodiscard]] bool passed() const noexcept;
};

/// Which part of a campaign a run covers: scenarios with index % count == shard - 1.
struct ShardSpec {
  std::size_t index = 1;  ///< 1-based: K of K/N
  std::size_t count = 1;  ///< N of K/N
};

struct CampaignResult {
  std::string name;                   ///< [campaign] name (or the file's stem)
  std::string file;                   ///< the campaign file as given
  std::size_t scenarios_in_file = 0;  ///< before --filter and --shard
  std::string filter;                 ///< --filter, "" when none
  /// The shards this result covers: {1/1} for a whole run; a merged result lists every shard
  /// it joined, in order.
  std::vector<ShardSpec> shards;
  std::vector<ScenarioResult> scenarios;  ///< in campaign order (ScenarioResult::index)
  double wall_s = 0.0;                    ///< wall-clock time of the run: not compared
  [[nodiscard]] std::size_t failed() const noexcept;
  /// 0 when every scenario passed, 3 when one failed (an empty campaign passes).
  [[nodiscard]] int exit_code() const noexcept;
};

}  // namespace hiltwin::app
