#pragma once
/// The one typed record of a `hiltwin tune` run and everything derived from it: the JSON
/// (`--json`), the text report with its Table 5.1-like validation table, and the
/// self-contained HTML plot (`--plot`) of miss % and RMS error against rate on log axes.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hiltwin/tuning/tuning.h"

namespace hiltwin::analysis {

/// A machine finding that matters for timing (from the `doctor` probe), with what to do.
struct TuneWarning {
  std::string id;      ///< the probe's check id, e.g. "governor"
  std::string text;    ///< what was found
  std::string advice;  ///< what to do
};

/// Everything `hiltwin tune` found.
struct TuneReport {
  std::string clock;  ///< "realtime" or "virtual"
  std::string model;  ///< e.g. "RELbot twin, rk4"
  std::string input;  ///< the profile the error is measured on
  double validate_seconds = 0.0;
  TuningPolicy policy;
  TimingMeasurements measured;
  std::vector<TuneWarning> machine_warnings;
  AccuracySearch accuracy;
  Recommendation recommendation;
  std::vector<CandidateResult> candidates;  ///< ascending by rate
  ValidationSummary validation;
};

/// The JSON document. Top-level keys at least: max_rate_hz (the timing maximum),
/// latency_max_rate_hz, recommended_rate_hz, deciding_bound, deciding_reason,
/// accuracy_bound_hz (null when none), tolerance_m, controller_rate_hz, highest_passing_hz,
/// error_stops_improving_hz, measured {...}, accuracy_search [...], machine_warnings [...],
/// candidates [{rate_hz, miss_pct, qos_verdict, rms_error_m, releases, deadline_misses,
/// recommended}]. Absent optionals are null.
[[nodiscard]] nlohmann::ordered_json ToJson(const TuneReport& report);

/// The text report: measurements, bounds, the recommendation with its deciding bound in
/// words, and the validation table (rate, misses %, QoS verdict, RMS error) with the
/// highest passing rate and the point where the error stops improving.
[[nodiscard]] std::string FormatTuneText(const TuneReport& report);

/// Writes a self-contained HTML page (inline SVG, nothing fetched) with two log-log charts
/// against rate: miss % (zero misses drawn on the axis floor and labelled) and RMS error
/// (with the tolerance line), both marking the timing maximum, the accuracy bound and the
/// recommended rate. Throws std::runtime_error naming the path when it cannot be written.
void WriteTunePlotHtml(const TuneReport& report, const std::string& html_path);

}  // namespace hiltwin::analysis
