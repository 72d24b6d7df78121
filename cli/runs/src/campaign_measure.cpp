// `hiltwin test`'s pass criteria, the half that reads a finished scenario's files: its run
// report (JSON, already parsed) and its CSV log, read with the project's one CSV reader. The
// credibility score is `hiltwin assess`'s, through the same library calls (ReadCsv,
// ResolveColumn, ExtractCurve, Assess), so a campaign scores a log as
// `hiltwin assess --sim LOG:COL --exp REF:COL --max-delay S` does.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>

#include "hiltwin/assess/assessment.h"
#include "hiltwin/runs/campaign_criteria.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::app {
// The helpers' own namespace: the runs library compiles in unity batches, where two files'
// anonymous namespaces are one.
namespace criteria_files {
namespace {

using CampaignJson = nlohmann::json;

/// A log as the loops write it. Time may repeat (a profile clock held over a pause), never go
/// backwards.
analysis::CsvTable ReadLog(const std::filesystem::path& log) {
  analysis::CsvRules rules;
  rules.time_order = analysis::TimeOrder::kStepsAllowed;
  rules.purpose = "to measure a scenario's criteria";
  return analysis::ReadCsv(log.string(), rules);
}

/// The log's column `name`, which `criterion` needs. Throws (InputError, a runtime_error)
/// naming the file, the column and the columns there are.
const std::vector<double>& Column(const analysis::CsvTable& log, const std::string& name,
                                  const std::string& criterion) {
  const std::string needs = "the criterion " + criterion + " needs column";
  return log.columns[analysis::ResolveColumn(log, name, needs)];
}

std::optional<double> FiniteAt(const CampaignJson& json, const char* key) {
  if (!json.is_object() || !json.contains(key) || !json[key].is_number()) return std::nullopt;
  const double value = json[key].get<double>();
  if (!std::isfinite(value)) return std::nullopt;
  return value;
}

/// A count; a negative or fractional number is no count.
std::optional<std::uint64_t> CountAt(const CampaignJson& report, const char* key) {
  if (!report.is_object() || !report.contains(key)) return std::nullopt;
  const CampaignJson& value = report[key];
  if (value.is_number_unsigned()) return value.get<std::uint64_t>();
  if (value.is_number_integer() && value.get<std::int64_t>() >= 0) {
    return static_cast<std::uint64_t>(value.get<std::int64_t>());
  }
  return std::nullopt;
}

std::string VerdictOf(const CampaignJson& report) {
  if (!report.is_object() || !report.contains("verdict") || !report["verdict"].is_string()) {
    return "";
  }
  return report["verdict"].get<std::string>();
}

// "final_error_m" is one figure in the combined report already: the larger |error| of the two
// wheels (hil_report.cpp). Tracking is null in open loop and without an ECS report; a side's
// report is null when that side wrote none.
ScenarioMeasures HilReportFigures(const CampaignJson& hil_report) {
  ScenarioMeasures m;
  const CampaignJson no_report;
  const CampaignJson& twin = hil_report.contains("twin") ? hil_report["twin"] : no_report;
  const CampaignJson& ecs = hil_report.contains("ecs") ? hil_report["ecs"] : no_report;
  m.verdict = WorseVerdict(VerdictOf(twin), VerdictOf(ecs));
  if (hil_report.contains("tracking_error_max_m")) {
    const std::optional<double> left_m = FiniteAt(hil_report["tracking_error_max_m"], "left");
    const std::optional<double> right_m = FiniteAt(hil_report["tracking_error_max_m"], "right");
    if (left_m && right_m) m.tracking_max_m = std::max(*left_m, *right_m);
  }
  m.tracking_rms_m = FiniteAt(hil_report, "tracking_error_rms_m");
  m.final_error_m = FiniteAt(hil_report, "final_error_m");
  const std::optional<std::uint64_t> twin_misses = CountAt(twin, "deadline_misses");
  const std::optional<std::uint64_t> ecs_misses = CountAt(ecs, "deadline_misses");
  if (twin_misses && ecs_misses) m.missed_deadlines = *twin_misses + *ecs_misses;
  return m;
}

/// The larger of the two wheels' step figures; a wheel whose setpoint never changes has no
/// step and is left out. Neither with a step: an error, the criterion cannot be measured.
void MeasureSteps(const analysis::CsvTable& log, const CampaignCriteria& c, ScenarioMeasures& m) {
  const std::string criterion = c.settling_time_s ? "settling_time_s" : "overshoot_pct";
  const std::vector<double>& time_s = log.columns[0];
  std::optional<StepResponse> worse;
  for (const char* wheel : {"left", "right"}) {
    const auto& setpoint = Column(log, std::string("setpoint_") + wheel + "_m", criterion);
    const auto& position = Column(log, std::string("wheel_") + wheel + "_m", criterion);
    if (std::adjacent_find(setpoint.begin(), setpoint.end(), std::not_equal_to<>()) ==
        setpoint.end()) {
      continue;
    }
    const StepResponse r = MeasureStep(time_s, setpoint, position, c.settling_band_pct);
    if (!worse) worse = r;
    worse->settling_time_s = std::max(worse->settling_time_s, r.settling_time_s);
    worse->overshoot_pct = std::max(worse->overshoot_pct, r.overshoot_pct);
  }
  if (!worse) {
    throw std::runtime_error(log.path + ": setpoint_left_m and setpoint_right_m never change; " +
                             criterion + " needs a setpoint with a step");
  }
  if (c.settling_time_s) m.settling_time_s = worse->settling_time_s;
  if (c.overshoot_pct) m.overshoot_pct = worse->overshoot_pct;
}

/// The curve with one sample per time: a repeated time (a held profile clock) keeps its last
/// row, since assess's curves must move forward in time.
analysis::Curve DistinctTimes(analysis::Curve curve) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < curve.t_s.size(); ++i) {
    if (i + 1 < curve.t_s.size() && curve.t_s[i + 1] == curve.t_s[i]) continue;
    curve.t_s[kept] = curve.t_s[i];
    curve.y[kept] = curve.y[i];
    curve.lines[kept] = curve.lines[i];
    ++kept;
  }
  curve.t_s.resize(kept);
  curve.y.resize(kept);
  curve.lines.resize(kept);
  return curve;
}

/// assess's total score of the log's compare_column (y_s) against the reference (y_e), with
/// assess's defaults except the delay search range.
double CredibilityOf(const analysis::CsvTable& log, const CampaignCriteria& c) {
  if (c.reference_file.empty() || c.reference_column.empty()) {
    throw std::runtime_error("credibility_min needs a reference file and column");
  }
  const analysis::Curve sim = DistinctTimes(analysis::ExtractCurve(
      log, analysis::ResolveColumn(log, c.compare_column, "compare_column")));
  const analysis::CsvTable reference = analysis::ReadCsv(c.reference_file);
  const analysis::Curve exp = analysis::ExtractCurve(
      reference, analysis::ResolveColumn(reference, c.reference_column, "reference column"));
  analysis::AssessOptions options;
  options.max_delay_s = c.credibility_max_delay_s;
  try {
    return analysis::Assess(sim, exp, nullptr, options).total;
  } catch (const analysis::InputError& e) {
    throw std::runtime_error(std::string("credibility_min: ") + e.what());
  }
}

/// The figures that come from the log, each only when its bound is set.
void MeasureLog(const std::filesystem::path& log_path, const CampaignCriteria& c,
                ScenarioMeasures& m) {
  if (!NeedsLog(c)) return;
  const analysis::CsvTable log = ReadLog(log_path);
  if (c.settling_time_s || c.overshoot_pct) MeasureSteps(log, c, m);
  if (c.duty_saturation_pct) {
    m.duty_saturation_pct = DutySaturationPct(Column(log, "duty_left", "duty_saturation_pct"),
                                              Column(log, "duty_right", "duty_saturation_pct"));
  }
  if (c.credibility_min) m.credibility = CredibilityOf(log, c);
}

/// Indices of at most `most` samples of `samples`, evenly spread, the first and last included.
std::vector<std::size_t> ThinnedIndices(std::size_t samples, std::size_t most) {
  std::vector<std::size_t> indices;
  if (samples <= most) {
    for (std::size_t i = 0; i < samples; ++i) indices.push_back(i);
    return indices;
  }
  const double stride = static_cast<double>(samples - 1) / static_cast<double>(most - 1);
  for (std::size_t i = 0; i < most; ++i) {
    indices.push_back(static_cast<std::size_t>(std::lround(static_cast<double>(i) * stride)));
  }
  return indices;
}

ScenarioPlot PlotOfTable(const analysis::CsvTable& log) {
  const auto has = [&log](const char* name) {
    return std::find(log.names.begin(), log.names.end(), name) != log.names.end();
  };
  const bool closed_loop = has("setpoint_left_m");
  const std::array<const char*, 2> names = closed_loop
                                               ? std::array{"setpoint_left_m", "wheel_left_m"}
                                               : std::array{"wheel_left_m", "wheel_right_m"};
  ScenarioPlot plot;
  if (!has(names[0]) || !has(names[1])) return plot;
  plot.y_unit = "m";
  const std::vector<std::size_t> kept = ThinnedIndices(log.rows(), ScenarioPlot::kMaxPlotPoints);
  for (const std::size_t row : kept) plot.time_s.push_back(log.columns[0][row]);
  for (const char* name : names) {
    const auto column = static_cast<std::size_t>(
        std::find(log.names.begin(), log.names.end(), name) - log.names.begin());
    PlotSeries series{name, {}};
    for (const std::size_t row : kept) series.values.push_back(log.columns[column][row]);
    plot.series.push_back(std::move(series));
  }
  return plot;
}

}  // namespace
}  // namespace criteria_files

ScenarioMeasures MeasureHil(const nlohmann::json& hil_report, const std::filesystem::path& ecs_log,
                            const CampaignCriteria& c) {
  ScenarioMeasures m = criteria_files::HilReportFigures(hil_report);
  criteria_files::MeasureLog(ecs_log, c, m);
  return m;
}

ScenarioMeasures MeasureRun(const nlohmann::json& run_report, const std::filesystem::path& twin_log,
                            const CampaignCriteria& c) {
  ScenarioMeasures m;
  m.verdict = criteria_files::VerdictOf(run_report);
  m.missed_deadlines = criteria_files::CountAt(run_report, "deadline_misses");
  criteria_files::MeasureLog(twin_log, c, m);
  return m;
}

ScenarioPlot PlotOf(const std::filesystem::path& log) {
  try {
    return criteria_files::PlotOfTable(criteria_files::ReadLog(log));
  } catch (const std::exception&) {
    return {};  // the plot is an illustration: the criteria report what went wrong with the log
  }
}

}  // namespace hiltwin::app
