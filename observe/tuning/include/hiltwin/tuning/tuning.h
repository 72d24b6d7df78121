#pragma once
/// `hiltwin tune`'s reasoning, thesis §3.8.2 method 2 made measurable: from measured (or
/// injected) costs and an accuracy search to a recommended update rate and the bound that
/// decided it; from the validation runs to the highest rate that passes QoS and the rate where
/// the error stops improving. Pure functions on typed records, so every figure can be tested
/// on synthetic measurements. The JSON, the text and the HTML plot all derive from TuneReport
/// (tuning_report.h); the measuring and the runs are the command's (cli/runs: hiltwin/runs/tune.h).

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/scheduler/timing_stats.h"

namespace hiltwin::analysis {

/// Wake-up latency measured at one rate.
struct LatencyAtRate {
  double rate_hz = 0.0;
  scheduler::TimingSummary wake_latency;  ///< wake - release, ns
};

/// The machine's costs, in nanoseconds.
struct TimingMeasurements {
  scheduler::TimingSummary step_compute;  ///< the model step alone, after warm-up
  /// Per cycle, everything the loop does besides the model step (executive, I/O exchange,
  /// QoS ledger, log row, tracepoint): the "overhead" of method 2.
  double loop_overhead_ns = 0.0;
  std::vector<LatencyAtRate> wake_latency;  ///< one entry per measured rate, ascending
  bool injected = false;  ///< the figures were given on the command line, not measured
};

/// The heuristic's fixed numbers (thesis §3.8.2: 75 % of the theoretical maximum, then 4-10x
/// the controller's rate) and the user's accuracy requirement.
struct TuningPolicy {
  double controller_rate_hz = 1000.0;
  double tolerance_m = 1.0e-4;  ///< RMS wheel-position error allowed against the reference
  double fraction_of_max = 0.75;
  double min_controller_multiple = 4.0;
  double max_controller_multiple = 10.0;
  double max_rate_hz = 50'000.0;  ///< scheduler::kMaxRateHz
};

/// Which bound set the recommended rate.
enum class DecidingBound : std::uint8_t {
  kTimingFraction,     ///< 75 % of the timing maximum, inside the 4-10x window
  kControllerFloor,    ///< 75 % of the maximum was below 4x the controller rate: raised to it
  kControllerCeiling,  ///< 75 % of the maximum was above 10x the controller rate: lowered to it
  kAccuracy,           ///< raised to the accuracy bound (the timing allowed it)
  kTimingMax,          ///< capped by 1/(overhead + mean compute)
  kLatencyMax,         ///< capped by the latency-aware maximum
};

/// Stable JSON names: "timing_fraction", "controller_floor", "controller_ceiling",
/// "accuracy", "timing_max", "latency_max".
[[nodiscard]] const char* ToString(DecidingBound bound) noexcept;

/// One evaluated point of the accuracy search.
struct AccuracyPoint {
  double rate_hz = 0.0;
  double rms_error_m = 0.0;
};

/// Result of AccuracyBound: the lowest passing rate (none when even the highest searched rate
/// misses the tolerance) and every point evaluated, ascending by rate.
struct AccuracySearch {
  std::optional<double> bound_hz;
  std::vector<AccuracyPoint> points;
};

/// Searches the whole multiples n * controller rate (n >= 1, n * rate <= max_rate_hz) for the
/// lowest one whose `rms_error_at(rate)` is within the tolerance, by bisection on n (the
/// error falls with the rate: a twin at a multiple of the controller's rate sees every
/// controller sample at a release). Evaluates the highest multiple first; when it fails there
/// is no bound. Each rate is evaluated at most once.
[[nodiscard]] AccuracySearch AccuracyBound(
    const std::function<double(double rate_hz)>& rms_error_at, const TuningPolicy& policy);

/// The recommendation and every figure it came from.
struct Recommendation {
  double timing_max_hz = 0.0;  ///< 1 / (loop_overhead + mean step compute), method 2
  /// 1 / (worst p99.9 wake latency over the measured rates + p99.9 step compute + overhead):
  /// the highest rate whose deadline (= period) holds the p99.9 cycle. The worst rate's
  /// latency is used because latency between measured rates is unknown.
  double latency_max_hz = 0.0;
  double worst_latency_p999_ns = 0.0;  ///< the latency figure latency_max_hz used
  double heuristic_hz = 0.0;           ///< fraction_of_max * timing_max clamped to the 4-10x window
  std::optional<double> accuracy_bound_hz;
  double recommended_hz = 0.0;  ///< whole hertz
  DecidingBound deciding_bound = DecidingBound::kTimingFraction;
  std::string reason;                 ///< one sentence: which bound decided and with what figures
  std::vector<std::string> warnings;  ///< e.g. the timing cannot reach 4x the controller rate
};

/// Steps, in this order:
///   r = fraction_of_max * timing_max                             (kTimingFraction)
///   r < min_multiple * controller: r = that                      (kControllerFloor)
///   r > max_multiple * controller: r = that                      (kControllerCeiling)
///   accuracy bound > r: r = accuracy bound                       (kAccuracy)
///   r > min(timing_max, latency_max, max_rate): r = that min     (kTimingMax / kLatencyMax;
///                                                                 max_rate counts as timing)
/// then r is floored to whole hertz. Throws std::invalid_argument when the measurements are
/// unusable (mean compute + overhead <= 0, no latency measured).
[[nodiscard]] Recommendation Recommend(const TimingMeasurements& measured,
                                       const std::optional<double>& accuracy_bound_hz,
                                       const TuningPolicy& policy);

/// One validation run.
struct CandidateResult {
  double rate_hz = 0.0;
  std::uint64_t releases = 0;  ///< judged releases
  std::uint64_t deadline_misses = 0;
  double miss_pct = 0.0;
  std::string qos_verdict;   ///< "PASS", "FLAGGED", "ABORTED"
  double rms_error_m = 0.0;  ///< as the controller sees it, against the reference
  bool recommended = false;  ///< the recommended rate (added to the list if absent)
};

/// What the validation table says.
struct ValidationSummary {
  std::optional<double> highest_passing_hz;  ///< highest rate whose verdict is PASS
  /// The lowest rate from which no higher candidate lowers the error by more than
  /// `improvement_threshold` (relative): beyond it a faster twin buys no accuracy. None when
  /// the error still improves at the highest candidate.
  std::optional<double> error_stops_improving_hz;
};

/// Relative error improvement below which a higher rate is said to buy nothing (10 %).
inline constexpr double kErrorImprovementThreshold = 0.10;

/// Summarises runs sorted by ascending rate.
[[nodiscard]] ValidationSummary SummariseValidation(
    const std::vector<CandidateResult>& candidates,
    double improvement_threshold = kErrorImprovementThreshold);

/// Checks a candidate list given by the user: not empty, finite, strictly ascending, each
/// within [1, max_rate_hz]. Throws std::invalid_argument saying which entry and why.
void CheckCandidateRates(const std::vector<double>& rates_hz, double max_rate_hz);

/// The twin as its controller saw it during one run: per executed cycle k, when its exchange
/// with the board happened and the wheel positions its step computed (sent at cycle k+1).
struct TwinTrajectory {
  double period_s = 0.0;
  std::vector<double> exchange_time_s;  ///< since release 0
  std::vector<double> wheel_left_m;     ///< after cycle k's step
  std::vector<double> wheel_right_m;
};

/// Reference wheel positions at the controller's sample instants t_j = j * controller_period,
/// j = 1, 2, ... (SimulateReference with sample_step = controller period).
struct ReferenceSamples {
  double controller_period_s = 0.0;
  std::vector<double> wheel_left_m;
  std::vector<double> wheel_right_m;
};

/// RMS (both wheels) of the position the controller reads from the board at each t_j minus
/// the reference there. The board plays what it received in the exchange of cycle k (the
/// positions of cycle k-1's step) as encoder pulses spread evenly over one period from that
/// exchange (io/encoder_emulator.h), so the controller sees the linear blend of the previous
/// and the new positions; before the first positions arrive it sees rest (0). Only instants
/// up to the last exchange count. Throws std::invalid_argument when no instant is covered.
[[nodiscard]] double ControllerViewRmsError(const TwinTrajectory& twin,
                                            const ReferenceSamples& reference);

}  // namespace hiltwin::analysis
