#include "hiltwin/tuning/tuning_report.h"

#include <string>

#include "tuning_format.h"
#include "hiltwin/report_kit/time_units.h"

namespace hiltwin::analysis {
namespace {

using detail::Us;

using detail::Format;
using detail::HzText;
using detail::MmText;
using detail::UsText;
using nlohmann::ordered_json;


template <typename T>
ordered_json OrNull(const std::optional<T>& value) {
  return value ? ordered_json(*value) : ordered_json(nullptr);
}

ordered_json MeasuredJson(const TimingMeasurements& m, const Recommendation& rec) {
  const scheduler::TimingSummary& c = m.step_compute;
  ordered_json latency = ordered_json::array();
  for (const LatencyAtRate& at : m.wake_latency) {
    latency.push_back({{"rate_hz", at.rate_hz},
                       {"p99_us", Us(at.wake_latency.p99_ns)},
                       {"p999_us", Us(at.wake_latency.p999_ns)},
                       {"max_us", Us(at.wake_latency.max_ns)}});
  }
  return {{"step_compute_us",
           {{"mean", Us(c.mean_ns)},
            {"p99", Us(c.p99_ns)},
            {"p999", Us(c.p999_ns)},
            {"max", Us(c.max_ns)},
            {"count", c.count}}},
          {"loop_overhead_us", Us(m.loop_overhead_ns)},
          {"wake_latency", std::move(latency)},
          {"worst_latency_p999_us", Us(rec.worst_latency_p999_ns)},
          {"injected", m.injected}};
}

ordered_json PolicyJson(const TuningPolicy& p) {
  return {{"fraction_of_max", p.fraction_of_max},
          {"min_controller_multiple", p.min_controller_multiple},
          {"max_controller_multiple", p.max_controller_multiple},
          {"scheduler_max_rate_hz", p.max_rate_hz}};
}

ordered_json AccuracyJson(const AccuracySearch& search) {
  ordered_json points = ordered_json::array();
  for (const AccuracyPoint& p : search.points) {
    points.push_back({{"rate_hz", p.rate_hz}, {"rms_error_m", p.rms_error_m}});
  }
  return points;
}

ordered_json MachineWarningsJson(const std::vector<TuneWarning>& warnings) {
  ordered_json out = ordered_json::array();
  for (const TuneWarning& w : warnings) {
    out.push_back({{"id", w.id}, {"text", w.text}, {"advice", w.advice}});
  }
  return out;
}

ordered_json CandidatesJson(const std::vector<CandidateResult>& candidates) {
  ordered_json out = ordered_json::array();
  for (const CandidateResult& c : candidates) {
    out.push_back({{"rate_hz", c.rate_hz},
                   {"miss_pct", c.miss_pct},
                   {"qos_verdict", c.qos_verdict},
                   {"rms_error_m", c.rms_error_m},
                   {"releases", c.releases},
                   {"deadline_misses", c.deadline_misses},
                   {"recommended", c.recommended}});
  }
  return out;
}

void MeasuredText(const TuneReport& r, std::string& out) {
  const TimingMeasurements& m = r.measured;
  const scheduler::TimingSummary& c = m.step_compute;
  out += m.injected ? "Measured (injected on the command line)\n" : "Measured\n";
  out += Format("  step compute     mean %s, p99 %s, p99.9 %s, max %s (%llu steps)\n",
                UsText(c.mean_ns).c_str(), UsText(static_cast<double>(c.p99_ns)).c_str(),
                UsText(static_cast<double>(c.p999_ns)).c_str(),
                UsText(static_cast<double>(c.max_ns)).c_str(),
                static_cast<unsigned long long>(c.count));
  out += Format("  loop overhead    %s per cycle\n", UsText(m.loop_overhead_ns).c_str());
  for (const LatencyAtRate& at : m.wake_latency) {
    out +=
        Format("  wake-up latency  at %s: p99 %s, p99.9 %s, max %s\n", HzText(at.rate_hz).c_str(),
               UsText(static_cast<double>(at.wake_latency.p99_ns)).c_str(),
               UsText(static_cast<double>(at.wake_latency.p999_ns)).c_str(),
               UsText(static_cast<double>(at.wake_latency.max_ns)).c_str());
  }
}

void BoundsText(const TuneReport& r, std::string& out) {
  const Recommendation& rec = r.recommendation;
  const TuningPolicy& p = r.policy;
  out += "Bounds\n";
  out += Format("  timing maximum         %10s = 1 / (overhead %s + mean compute %s)\n",
                HzText(rec.timing_max_hz).c_str(), UsText(r.measured.loop_overhead_ns).c_str(),
                UsText(r.measured.step_compute.mean_ns).c_str());
  out += Format(
      "  latency-aware maximum  %10s = 1 / (worst p99.9 wake-up %s + p99.9 compute %s + "
      "overhead %s)\n",
      HzText(rec.latency_max_hz).c_str(), UsText(rec.worst_latency_p999_ns).c_str(),
      UsText(static_cast<double>(r.measured.step_compute.p999_ns)).c_str(),
      UsText(r.measured.loop_overhead_ns).c_str());
  out += Format(
      "  heuristic              %10s = %.0f %% of the timing maximum, kept within %g-%gx "
      "the controller rate %s\n",
      HzText(rec.heuristic_hz).c_str(), p.fraction_of_max * 100.0, p.min_controller_multiple,
      p.max_controller_multiple, HzText(p.controller_rate_hz).c_str());
  const std::string evaluated = Format("%zu rates evaluated", r.accuracy.points.size());
  if (rec.accuracy_bound_hz) {
    out +=
        Format("  accuracy bound         %10s = lowest multiple of %s with RMS error <= %s (%s)\n",
               HzText(*rec.accuracy_bound_hz).c_str(), HzText(p.controller_rate_hz).c_str(),
               MmText(p.tolerance_m).c_str(), evaluated.c_str());
  } else {
    out += Format(
        "  accuracy bound               none: no multiple of %s kept the RMS error <= %s (%s)\n",
        HzText(p.controller_rate_hz).c_str(), MmText(p.tolerance_m).c_str(), evaluated.c_str());
  }
}

void RecommendationText(const TuneReport& r, std::string& out) {
  const Recommendation& rec = r.recommendation;
  out += "Recommendation: " + HzText(rec.recommended_hz) + " (decided by: " + rec.reason + ")\n";
  for (const std::string& w : rec.warnings) out += "  warning: " + w + "\n";
}

void ValidationText(const TuneReport& r, std::string& out) {
  out += Format("Validation (%g s per candidate on %s)\n", r.validate_seconds, r.input.c_str());
  if (r.candidates.empty()) {
    out += "  no validation runs\n";
    return;
  }
  out += "  rate [Hz]   misses [%]   QoS       RMS error [mm]\n";
  for (const CandidateResult& c : r.candidates) {
    out +=
        Format("  %9.0f   %10.3f   %-8s  %14.3f%s\n", c.rate_hz, c.miss_pct, c.qos_verdict.c_str(),
               c.rms_error_m * 1e3, c.recommended ? "   <- recommended" : "");
  }
  const ValidationSummary& v = r.validation;
  out += v.highest_passing_hz
             ? "  highest rate passing QoS: " + HzText(*v.highest_passing_hz) + "\n"
             : std::string("  highest rate passing QoS: none passed\n");
  out += v.error_stops_improving_hz
             ? Format(
                   "  the error stops improving at %s (no higher rate lowers it by more than "
                   "%.0f %%)\n",
                   HzText(*v.error_stops_improving_hz).c_str(), kErrorImprovementThreshold * 100.0)
             : std::string("  the error still improves at the highest candidate\n");
}

void MachineText(const TuneReport& r, std::string& out) {
  if (r.machine_warnings.empty()) return;
  out += "Machine\n";
  for (const TuneWarning& w : r.machine_warnings) {
    out += "  warning [" + w.id + "]: " + w.text + "\n    advice: " + w.advice + "\n";
  }
}

}  // namespace

ordered_json ToJson(const TuneReport& report) {
  const Recommendation& rec = report.recommendation;
  return {{"clock", report.clock},
          {"model", report.model},
          {"input", report.input},
          {"validate_seconds", report.validate_seconds},
          {"controller_rate_hz", report.policy.controller_rate_hz},
          {"tolerance_m", report.policy.tolerance_m},
          {"policy", PolicyJson(report.policy)},
          {"max_rate_hz", rec.timing_max_hz},
          {"latency_max_rate_hz", rec.latency_max_hz},
          {"heuristic_hz", rec.heuristic_hz},
          {"accuracy_bound_hz", OrNull(rec.accuracy_bound_hz)},
          {"recommended_rate_hz", rec.recommended_hz},
          {"deciding_bound", ToString(rec.deciding_bound)},
          {"deciding_reason", rec.reason},
          {"warnings", rec.warnings},
          {"highest_passing_hz", OrNull(report.validation.highest_passing_hz)},
          {"error_stops_improving_hz", OrNull(report.validation.error_stops_improving_hz)},
          {"measured", MeasuredJson(report.measured, rec)},
          {"accuracy_search", AccuracyJson(report.accuracy)},
          {"machine_warnings", MachineWarningsJson(report.machine_warnings)},
          {"candidates", CandidatesJson(report.candidates)}};
}

std::string FormatTuneText(const TuneReport& report) {
  std::string out = Format("hiltwin tune: %s, %s clock, controller at %s, tolerance %s RMS\n",
                           report.model.c_str(), report.clock.c_str(),
                           HzText(report.policy.controller_rate_hz).c_str(),
                           MmText(report.policy.tolerance_m).c_str());
  MeasuredText(report, out);
  BoundsText(report, out);
  RecommendationText(report, out);
  ValidationText(report, out);
  MachineText(report, out);
  return out;
}

}  // namespace hiltwin::analysis
