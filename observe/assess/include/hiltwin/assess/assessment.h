#pragma once
/// `hiltwin assess` without the command line: align two curves, score them in the time,
/// performance and frequency domains (thesis §2.4, appendix C), estimate their delay, add
/// the cross-checks, and report as text or JSON.

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/assess/assess_option.h"
#include "hiltwin/assess/credibility.h"
#include "hiltwin/assess/cross_checks.h"
#include "hiltwin/assess/delay.h"
#include "hiltwin/assess/spectral.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::analysis {

/// The scale of the numbers Assess scores. Every time and value of the curves stays within
/// +-kMaxAssessedMagnitude and the experiment (and the input) move by at least
/// kMinAssessedRange over the compared range: inside both, every difference, square and sum of
/// squares the domains form is a normal double (no overflow to Inf, no underflow to 0, which
/// would score any simulation 1), and no quantity in SI units comes near either end. Outside,
/// Assess throws an OptionError naming the file, line and column (docs/credibility.md).
constexpr double kMaxAssessedMagnitude = 1e100;
constexpr double kMinAssessedRange = 1e-100;
/// A time base that is not uniform is resampled onto a uniform grid at its median step (for
/// the delay, the spectra and ISO 18571); that grid may hold at most this many points per
/// compared sample. A few gaps cost a few points; a file whose median step is far finer than
/// its range (nanosecond samples, then one a day later) is refused instead of being resampled
/// onto 1e15 points.
constexpr std::size_t kMaxGridPointsPerSample = 16;

/// One curve taken from a CSV column, with where it came from for messages.
struct Curve {
  std::string path;
  std::string label;                ///< e.g. "run.csv column 3 'y_e'"
  std::size_t column = 0;           ///< 0-based
  std::vector<double> t_s;
  std::vector<double> y;
  std::vector<std::size_t> lines;   ///< 1-based file line of each sample
};

/// Copies column `column` (0-based, not time) of `table`.
[[nodiscard]] Curve ExtractCurve(const CsvTable& table, std::size_t column);

/// Everything the user can choose (defaults: the thesis's choices, §3.9 and §5.6).
struct AssessOptions {
  CredibilityParams params;
  std::array<double, 3> weights{1.0, 0.0, 0.0};  ///< time, performance, frequency
  std::optional<std::pair<double, double>> segment;  ///< performance domain [t0, t1] s
  std::optional<double> setpoint;       ///< for the steady-state error
  std::optional<double> max_delay_s;    ///< delay search range (default 10 % of the overlap)
  bool total_uses_compensated = false;  ///< put the delay-compensated time score in the total
  std::size_t welch_segment = 0;        ///< 0: DefaultWelchSegment
  double coherence_min = 0.8;
  std::optional<std::pair<double, double>> band_hz;  ///< frequency domain band [lo, hi] Hz
  std::size_t iso_max_samples = 2000;   ///< ISO/TS 18571 runs on at most this many points
  OptionNamer name_option = NoOptionNames;  ///< how advice in notes and errors names options
};

/// The result of Assess, in the order it is printed.
struct Assessment {
  std::string sim_label;
  std::string exp_label;
  std::string input_label;  ///< empty without an input column
  bool same_time_base = false;
  double overlap_t0_s = 0.0;
  double overlap_t1_s = 0.0;
  std::size_t samples = 0;  ///< experiment samples in the overlap
  double grid_step_s = 0.0;
  bool uniform_time_base = false;
  AssessOptions options;

  TimeDomainScore time;
  DelayEstimate delay;
  TimeDomainScore time_compensated;
  std::optional<PerformanceScore> performance;
  std::string performance_note;  ///< why performance is null
  std::optional<FrequencyScore> frequency;
  std::string frequency_note;    ///< why frequency is null
  TheilCoefficients theil;
  std::optional<IsoRating> iso;
  std::string iso_note;          ///< why iso is null
  double total = 0.0;
  bool pass = false;
  std::vector<std::string> notes;

  /// Aligned series on the experiment's time base over the overlap (for --plot).
  std::vector<double> t_s;
  std::vector<double> y_sim;
  std::vector<double> y_exp;
  std::vector<double> y_sim_compensated;  ///< NaN where the shifted simulation has no data
};

/// Runs the whole assessment. `input` (may be null) enables the frequency domain. Throws
/// OptionError for a bad option or a curve that cannot serve (constant experiment, a value
/// beyond kMaxAssessedMagnitude, a grid beyond kMaxGridPointsPerSample, a domain with
/// weight > 0 that cannot be computed, ...) and InputError for data that do not fit
/// together (no overlap), naming file, line and column; messages never name command-line
/// flags (see OptionError::option and AssessOptions::name_option).
[[nodiscard]] Assessment Assess(const Curve& sim, const Curve& exp, const Curve* input,
                                const AssessOptions& options);

/// JSON report: time_domain {e_t, eps_t, k_e, eta}, delay_s, time_domain_compensated,
/// performance_domain, frequency_domain, cross_checks {theil, iso18571} (each null when not
/// computed, with the reason under not_computed), total, pass.
[[nodiscard]] nlohmann::json ToJson(const Assessment& assessment);

/// The text table printed by `hiltwin assess`.
[[nodiscard]] std::string FormatText(const Assessment& assessment);

}  // namespace hiltwin::analysis
