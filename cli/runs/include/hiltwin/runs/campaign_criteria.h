#pragma once
/// `hiltwin test`'s pass criteria: what a scenario's run is measured on (from its run reports
/// and logs) and the judgement of each criterion against its bound. The figures are pure
/// functions of plain inputs (MeasureStep, DutySaturationPct, Judge), each tested with a value
/// just inside and just outside its bound; Measure* read a finished scenario's files.

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/runs/campaign_result.h"

namespace hiltwin::app {

/// A scenario's criteria, as the campaign file gives them (docs/testing-campaigns.md): each
/// bound is optional; a scenario with none is judged on nothing but having run.
struct CampaignCriteria {
  std::optional<std::string> verdict;         ///< the worst verdict allowed: "PASS" or "FLAGGED"
  std::optional<double> tracking_max_m;       ///< <=: the larger wheel's max |error|, m
  std::optional<double> tracking_rms_m;       ///< <=: RMS error of both wheels, m
  std::optional<double> final_error_m;        ///< <=: the larger wheel's |error| at the end, m
  std::optional<double> settling_time_s;      ///< <=: after the setpoint's step, s
  double settling_band_pct = 2.0;             ///< the settling band, % of the step
  std::optional<double> overshoot_pct;        ///< <=: beyond the step's target, % of the step
  std::optional<double> duty_saturation_pct;  ///< <=: share of ECS cycles at full duty, %
  std::optional<std::uint64_t> missed_deadlines;  ///< <=: both sides' deadline misses, summed
  std::optional<double> credibility_min;          ///< >=: assess's score against `reference`
  std::string reference_file;    ///< CSV with the reference curve (absolute after loading)
  std::string reference_column;  ///< its column, by header name
  std::string compare_column = "wheel_right_m";   ///< the scenario log's column compared with it
  std::optional<double> credibility_max_delay_s;  ///< assess's --max-delay; default: assess's
};

/// Which log a criterion needs: a scenario that asks for none of these is not logged.
[[nodiscard]] bool NeedsLog(const CampaignCriteria& c) noexcept;

/// Step response of one wheel: the setpoint's largest jump between two samples is the step.
struct StepResponse {
  double step_time_s = 0.0;
  double step_m = 0.0;         ///< the jump, signed
  double overshoot_pct = 0.0;  ///< max excursion beyond the target, % of |step|; >= 0
  /// From the step until the position stays within band_pct of |step| around the target to
  /// the end of the log; +infinity when it never does.
  double settling_time_s = 0.0;
};

/// Throws std::invalid_argument when the spans differ in length, hold fewer than 2 samples or
/// the setpoint has no step (no change at all).
[[nodiscard]] StepResponse MeasureStep(std::span<const double> time_s,
                                       std::span<const double> setpoint_m,
                                       std::span<const double> position_m, double band_pct);

/// Share of samples, in %, in which either wheel's |duty| is at least 0.999 * duty_limit.
[[nodiscard]] double DutySaturationPct(std::span<const double> duty_left,
                                       std::span<const double> duty_right, double duty_limit = 1.0);

/// What a scenario measured; nullopt: not measured (not asked for, or the run gave no figure).
struct ScenarioMeasures {
  std::string verdict;  ///< the worse verdict of the scenario's sides; "" when there is none
  std::optional<double> tracking_max_m, tracking_rms_m, final_error_m;
  std::optional<double> settling_time_s, overshoot_pct;  ///< the worse of the two wheels
  std::optional<double> duty_saturation_pct;
  std::optional<std::uint64_t> missed_deadlines;
  std::optional<double> credibility;
};

/// One CriterionResult per bound `c` sets, in the order of the fields above; a bound whose
/// figure was not measured fails (measured nullopt).
[[nodiscard]] std::vector<CriterionResult> Judge(const CampaignCriteria& c,
                                                 const ScenarioMeasures& m);

/// The worse of two verdicts (PASS < FLAGGED < ABORTED < NONE < ""): "" is a side without one.
[[nodiscard]] std::string WorseVerdict(const std::string& a, const std::string& b);

/// A `hiltwin hil` scenario: its combined report (--report) and, when NeedsLog(c), the ECS's
/// log (--log-dir's ecs.csv). Throws std::runtime_error naming the file when a needed log
/// cannot be read or lacks a column.
[[nodiscard]] ScenarioMeasures MeasureHil(const nlohmann::json& hil_report,
                                          const std::filesystem::path& ecs_log,
                                          const CampaignCriteria& c);
/// A `hiltwin run` scenario (the twin alone): its run report and, when NeedsLog(c), its log.
[[nodiscard]] ScenarioMeasures MeasureRun(const nlohmann::json& run_report,
                                          const std::filesystem::path& twin_log,
                                          const CampaignCriteria& c);

/// The scenario's plot from its log: closed loop (the log has setpoint_left_m): setpoint and
/// wheel of the left wheel; otherwise wheel_left_m and wheel_right_m; evenly thinned to at
/// most ScenarioPlot::kMaxPlotPoints. An unreadable log gives an empty plot.
[[nodiscard]] ScenarioPlot PlotOf(const std::filesystem::path& log);

}  // namespace hiltwin::app
