#include "hiltwin/tuning/tuning.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>

#include "tuning_format.h"

namespace hiltwin::analysis {
namespace {

using detail::Format;
using detail::HzText;
using detail::MmText;
using detail::UsText;

constexpr double kNsPerS = 1e9;
// The bounds are quotients of measured figures; a rate that is mathematically whole (6250 Hz
// = 0.75e9 / 120000 ns) may land a few ulps below it. Flooring after this relative nudge keeps
// it whole without ever adding a measurable hertz.
constexpr double kWholeHzSlack = 1e-12;

void CheckPolicy(const TuningPolicy& policy) {
  const double rate_hz = policy.controller_rate_hz;
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0)) {
    throw std::invalid_argument(
        Format("the controller rate must be a positive number of hertz, not %g", rate_hz));
  }
  if (rate_hz > policy.max_rate_hz) {
    throw std::invalid_argument(
        Format("the controller rate %g Hz is above the scheduler's limit %g Hz", rate_hz,
               policy.max_rate_hz));
  }
  const double tolerance_m = policy.tolerance_m;
  if (!(std::isfinite(tolerance_m) && tolerance_m > 0.0)) {
    throw std::invalid_argument(
        Format("the RMS error tolerance must be a positive length in metres, not %g", tolerance_m));
  }
}

// Cost of one cycle by method 2: the loop's overhead plus the mean model step.
double CycleNs(const TimingMeasurements& measured) {
  const double cycle_ns = measured.loop_overhead_ns + measured.step_compute.mean_ns;
  if (!(std::isfinite(cycle_ns) && cycle_ns > 0.0)) {
    throw std::invalid_argument(
        Format("unusable measurements: loop overhead %g ns + mean step compute %g ns is not a "
               "positive time",
               measured.loop_overhead_ns, measured.step_compute.mean_ns));
  }
  if (measured.wake_latency.empty()) {
    throw std::invalid_argument(
        "unusable measurements: no wake-up latency was measured at any rate");
  }
  return cycle_ns;
}

double WorstLatencyP999Ns(const TimingMeasurements& measured) {
  std::int64_t worst_ns = 0;
  for (const LatencyAtRate& at : measured.wake_latency)
    worst_ns = std::max(worst_ns, at.wake_latency.p999_ns);
  return static_cast<double>(worst_ns);
}

// "75 % of the timing maximum 8333 Hz (overhead 35.0 us + compute 85.0 us)".
std::string FractionPhrase(const TimingMeasurements& measured, const TuningPolicy& policy,
                           double timing_max_hz) {
  return Format("%.0f %% of the timing maximum %s (overhead %s + compute %s)",
                policy.fraction_of_max * 100.0, HzText(timing_max_hz).c_str(),
                UsText(measured.loop_overhead_ns).c_str(),
                UsText(measured.step_compute.mean_ns).c_str());
}

// The reason before the cap: which of the first four steps set the rate.
std::string UncappedReason(const Recommendation& rec, const TimingMeasurements& measured,
                           const TuningPolicy& policy, double fraction_hz) {
  std::string fraction = FractionPhrase(measured, policy, rec.timing_max_hz);
  switch (rec.deciding_bound) {
    case DecidingBound::kControllerFloor:
      return Format("%s is %s, below %gx the controller rate %s: raised to %s", fraction.c_str(),
                    HzText(fraction_hz).c_str(), policy.min_controller_multiple,
                    HzText(policy.controller_rate_hz).c_str(), HzText(rec.heuristic_hz).c_str());
    case DecidingBound::kControllerCeiling:
      return Format("%s is %s, above %gx the controller rate %s: lowered to %s", fraction.c_str(),
                    HzText(fraction_hz).c_str(), policy.max_controller_multiple,
                    HzText(policy.controller_rate_hz).c_str(), HzText(rec.heuristic_hz).c_str());
    case DecidingBound::kAccuracy:
      return Format(
          "the accuracy bound %s (the lowest multiple of the controller rate %s with an RMS "
          "error within %s) is above the heuristic's %s",
          HzText(*rec.accuracy_bound_hz).c_str(), HzText(policy.controller_rate_hz).c_str(),
          MmText(policy.tolerance_m).c_str(), HzText(rec.heuristic_hz).c_str());
    default:
      return fraction;
  }
}

std::string CapReason(const Recommendation& rec, const TimingMeasurements& measured,
                      const TuningPolicy& policy, double wanted_hz) {
  std::string cap;
  if (rec.deciding_bound == DecidingBound::kLatencyMax) {
    cap = Format(
        "the latency-aware maximum %s (p99.9 wake-up latency %s + p99.9 compute %s + "
        "overhead %s)",
        HzText(rec.latency_max_hz).c_str(), UsText(rec.worst_latency_p999_ns).c_str(),
        UsText(static_cast<double>(measured.step_compute.p999_ns)).c_str(),
        UsText(measured.loop_overhead_ns).c_str());
  } else if (policy.max_rate_hz < rec.timing_max_hz) {
    cap = Format("the scheduler's limit %s", HzText(policy.max_rate_hz).c_str());
  } else {
    cap = Format("the timing maximum %s (overhead %s + compute %s)",
                 HzText(rec.timing_max_hz).c_str(), UsText(measured.loop_overhead_ns).c_str(),
                 UsText(measured.step_compute.mean_ns).c_str());
  }
  return "capped at " + cap + ", below the " + HzText(wanted_hz) + " wanted";
}

void AddWarnings(Recommendation& rec, const TuningPolicy& policy) {
  const double floor_hz = policy.min_controller_multiple * policy.controller_rate_hz;
  if (rec.recommended_hz < floor_hz) {
    rec.warnings.push_back(Format(
        "this machine cannot run the twin at %gx the controller rate (%s): the recommendation %s "
        "gives the controller fewer than %g twin updates per sample; reduce the loop's overhead "
        "or the model's cost, or accept the larger error",
        policy.min_controller_multiple, HzText(floor_hz).c_str(),
        HzText(rec.recommended_hz).c_str(), policy.min_controller_multiple));
  }
  if (!rec.accuracy_bound_hz) {
    rec.warnings.push_back(Format(
        "no accuracy bound: no searched rate kept the RMS error within %s, so the recommendation "
        "rests on timing alone",
        MmText(policy.tolerance_m).c_str()));
  } else if (*rec.accuracy_bound_hz > rec.recommended_hz) {
    rec.warnings.push_back(Format(
        "the accuracy bound %s is above the rate this machine can hold (%s): at the recommended "
        "rate the RMS error exceeds %s",
        HzText(*rec.accuracy_bound_hz).c_str(), HzText(rec.recommended_hz).c_str(),
        MmText(policy.tolerance_m).c_str()));
  }
}

void CheckViewInputs(const TwinTrajectory& twin, const ReferenceSamples& reference) {
  const std::size_t cycles = twin.exchange_time_s.size();
  if (twin.wheel_left_m.size() != cycles || twin.wheel_right_m.size() != cycles) {
    throw std::invalid_argument(
        Format("twin trajectory sizes differ: %zu exchange times, %zu left and %zu right positions",
               cycles, twin.wheel_left_m.size(), twin.wheel_right_m.size()));
  }
  if (reference.wheel_left_m.size() != reference.wheel_right_m.size()) {
    throw std::invalid_argument(Format("reference sizes differ: %zu left and %zu right positions",
                                       reference.wheel_left_m.size(),
                                       reference.wheel_right_m.size()));
  }
  if (!(std::isfinite(twin.period_s) && twin.period_s > 0.0)) {
    throw std::invalid_argument(
        Format("the twin's period must be positive, not %g s", twin.period_s));
  }
  if (!(std::isfinite(reference.controller_period_s) && reference.controller_period_s > 0.0)) {
    throw std::invalid_argument(Format("the controller's period must be positive, not %g s",
                                       reference.controller_period_s));
  }
}

// target_k, what exchange k delivered: the positions of cycle k-1's step; rest for k = 0.
double TargetM(std::size_t k, const std::vector<double>& wheel_m) {
  return k == 0 ? 0.0 : wheel_m[k - 1];
}

// The position of one wheel the board plays out at `t_s`: the latest exchange k at or before
// t_s blends from target_{k-1} to target_k over one period; before exchange 0 it is rest.
double BoardPositionM(const TwinTrajectory& twin, double t_s, const std::vector<double>& wheel_m) {
  const std::vector<double>& times_s = twin.exchange_time_s;
  const auto after = std::upper_bound(times_s.begin(), times_s.end(), t_s);
  if (after == times_s.begin()) return 0.0;
  const auto k = static_cast<std::size_t>(after - times_s.begin()) - 1;
  const double from_m = k == 0 ? 0.0 : TargetM(k - 1, wheel_m);
  const double fraction = std::clamp((t_s - times_s[k]) / twin.period_s, 0.0, 1.0);
  return from_m + fraction * (TargetM(k, wheel_m) - from_m);
}

}  // namespace

const char* ToString(DecidingBound bound) noexcept {
  switch (bound) {
    case DecidingBound::kTimingFraction:
      return "timing_fraction";
    case DecidingBound::kControllerFloor:
      return "controller_floor";
    case DecidingBound::kControllerCeiling:
      return "controller_ceiling";
    case DecidingBound::kAccuracy:
      return "accuracy";
    case DecidingBound::kTimingMax:
      return "timing_max";
    case DecidingBound::kLatencyMax:
      return "latency_max";
  }
  return "unknown";
}

AccuracySearch AccuracyBound(const std::function<double(double rate_hz)>& rms_error_at,
                             const TuningPolicy& policy) {
  CheckPolicy(policy);
  const auto n_max = static_cast<long>(std::floor(policy.max_rate_hz / policy.controller_rate_hz));
  std::map<long, double> error_at_n;  // every evaluation, so no rate is run twice
  auto passes = [&](long n) {
    auto [at, inserted] = error_at_n.try_emplace(n, 0.0);
    if (inserted) at->second = rms_error_at(static_cast<double>(n) * policy.controller_rate_hz);
    return at->second <= policy.tolerance_m;  // NaN fails
  };
  AccuracySearch search;
  if (passes(n_max)) {
    // Invariant: n_pass passes; every n <= n_fail fails (n = 0 stands for "no twin").
    long n_fail = 0;
    long n_pass = n_max;
    while (n_pass - n_fail > 1) {
      const long mid = n_fail + (n_pass - n_fail) / 2;
      (passes(mid) ? n_pass : n_fail) = mid;
    }
    search.bound_hz = static_cast<double>(n_pass) * policy.controller_rate_hz;
  }
  for (const auto& [n, error_m] : error_at_n) {
    search.points.push_back({static_cast<double>(n) * policy.controller_rate_hz, error_m});
  }
  return search;
}

Recommendation Recommend(const TimingMeasurements& measured,
                         const std::optional<double>& accuracy_bound_hz,
                         const TuningPolicy& policy) {
  CheckPolicy(policy);
  const double cycle_ns = CycleNs(measured);
  Recommendation rec;
  rec.timing_max_hz = kNsPerS / cycle_ns;
  rec.worst_latency_p999_ns = WorstLatencyP999Ns(measured);
  rec.latency_max_hz =
      kNsPerS / (rec.worst_latency_p999_ns + static_cast<double>(measured.step_compute.p999_ns) +
                 measured.loop_overhead_ns);
  rec.accuracy_bound_hz = accuracy_bound_hz;
  // fraction * 1e9 first: 0.75e9 / 120000 ns is exactly 6250, 0.75 * 8333.33... is not.
  const double fraction_hz = policy.fraction_of_max * kNsPerS / cycle_ns;
  double rate_hz = fraction_hz;
  rec.deciding_bound = DecidingBound::kTimingFraction;
  if (const double floor_hz = policy.min_controller_multiple * policy.controller_rate_hz;
      rate_hz < floor_hz) {
    rate_hz = floor_hz;
    rec.deciding_bound = DecidingBound::kControllerFloor;
  }
  if (const double ceiling_hz = policy.max_controller_multiple * policy.controller_rate_hz;
      rate_hz > ceiling_hz) {
    rate_hz = ceiling_hz;
    rec.deciding_bound = DecidingBound::kControllerCeiling;
  }
  rec.heuristic_hz = rate_hz;
  if (accuracy_bound_hz && *accuracy_bound_hz > rate_hz) {
    rate_hz = *accuracy_bound_hz;
    rec.deciding_bound = DecidingBound::kAccuracy;
  }
  rec.reason = UncappedReason(rec, measured, policy, fraction_hz);
  const double timing_cap_hz = std::min(rec.timing_max_hz, policy.max_rate_hz);
  if (const double cap_hz = std::min(timing_cap_hz, rec.latency_max_hz); rate_hz > cap_hz) {
    // A tie names the timing cap: the latency-aware maximum then adds nothing to it.
    rec.deciding_bound =
        rec.latency_max_hz < timing_cap_hz ? DecidingBound::kLatencyMax : DecidingBound::kTimingMax;
    rec.reason = CapReason(rec, measured, policy, rate_hz);
    rate_hz = cap_hz;
  }
  rec.recommended_hz = std::floor(rate_hz * (1.0 + kWholeHzSlack));
  AddWarnings(rec, policy);
  return rec;
}

ValidationSummary SummariseValidation(const std::vector<CandidateResult>& candidates,
                                      double improvement_threshold) {
  ValidationSummary summary;
  for (const CandidateResult& c : candidates) {
    if (c.qos_verdict == "PASS") summary.highest_passing_hz = c.rate_hz;
  }
  // Runs whose error could not be computed say nothing about the trend.
  std::vector<const CandidateResult*> measured;
  for (const CandidateResult& c : candidates) {
    if (std::isfinite(c.rms_error_m)) measured.push_back(&c);
  }
  for (std::size_t i = 0; i + 1 < measured.size(); ++i) {
    const double enough_m = (1.0 - improvement_threshold) * measured[i]->rms_error_m;
    const bool flat =
        std::all_of(measured.begin() + static_cast<std::ptrdiff_t>(i) + 1, measured.end(),
                    [&](const CandidateResult* c) { return c->rms_error_m >= enough_m; });
    if (flat) {
      summary.error_stops_improving_hz = measured[i]->rate_hz;
      break;
    }
  }
  return summary;
}

void CheckCandidateRates(const std::vector<double>& rates_hz, double max_rate_hz) {
  if (rates_hz.empty()) {
    throw std::invalid_argument(
        "the candidate list is empty; give rates in Hz, e.g. 1000,2000,4000");
  }
  for (std::size_t i = 0; i < rates_hz.size(); ++i) {
    const double rate_hz = rates_hz[i];
    const std::string entry = Format("candidate rate %g Hz (entry %zu)", rate_hz, i + 1);
    if (!std::isfinite(rate_hz))
      throw std::invalid_argument(entry + " is not a finite number of hertz");
    if (rate_hz < 1.0) throw std::invalid_argument(entry + " is below 1 Hz");
    if (rate_hz > max_rate_hz) {
      throw std::invalid_argument(entry + Format(" is above %g Hz: %g Hz is the scheduler's limit",
                                                 max_rate_hz, max_rate_hz));
    }
    if (i > 0 && !(rate_hz > rates_hz[i - 1])) {
      throw std::invalid_argument(
          Format("candidate rates must be strictly ascending: entry %zu (%g Hz) %s "
                 "entry %zu (%g Hz)",
                 i + 1, rate_hz, rate_hz == rates_hz[i - 1] ? "duplicates" : "is below", i,
                 rates_hz[i - 1]));
    }
  }
}

double ControllerViewRmsError(const TwinTrajectory& twin, const ReferenceSamples& reference) {
  CheckViewInputs(twin, reference);
  const double last_exchange_s = twin.exchange_time_s.empty() ? -1.0 : twin.exchange_time_s.back();
  double sum_squares_m2 = 0.0;
  std::size_t instants = 0;
  for (std::size_t j = 1; j <= reference.wheel_left_m.size(); ++j) {
    const double t_s = static_cast<double>(j) * reference.controller_period_s;
    if (t_s > last_exchange_s) break;
    const double left_m =
        BoardPositionM(twin, t_s, twin.wheel_left_m) - reference.wheel_left_m[j - 1];
    const double right_m =
        BoardPositionM(twin, t_s, twin.wheel_right_m) - reference.wheel_right_m[j - 1];
    sum_squares_m2 += left_m * left_m + right_m * right_m;
    ++instants;
  }
  if (instants == 0) {
    throw std::invalid_argument(Format(
        "no controller instant is covered: %zu reference samples every %g s, last exchange at %g s",
        reference.wheel_left_m.size(), reference.controller_period_s, last_exchange_s));
  }
  return std::sqrt(sum_squares_m2 / static_cast<double>(2 * instants));
}

}  // namespace hiltwin::analysis
