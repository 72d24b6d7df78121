#include <string>

#include "cause_attribution.h"
#include "hiltwin/jitter/jitter_outputs.h"
#include "hiltwin/scheduler/timing_stats.h"
#include "jitter_format.h"

namespace hiltwin::analysis {
namespace {

using nlohmann::ordered_json;

// Same shape as the run report's timing figures (engine/runtime/src/run_report.cpp), plus the bins.
ordered_json DistributionJson(const Distribution& d) {
  const scheduler::TimingSummary& s = d.summary;
  ordered_json out = {{"count", s.count}, {"min", s.min_ns}, {"mean", s.mean_ns},
                      {"p50", s.p50_ns},  {"p99", s.p99_ns}, {"p999", s.p999_ns},
                      {"max", s.max_ns}};
  ordered_json bins = ordered_json::array();
  for (const HistogramBin& b : d.bins) {
    bins.push_back({{"low_ns", b.low_ns}, {"high_ns", b.high_ns}, {"count", b.count}});
  }
  out["bins"] = std::move(bins);
  return out;
}

ordered_json RuleJson(const qos::RuleSpec& rule) {
  return {{"kind", qos::ToString(rule.kind)}, {"m", rule.m}, {"k", rule.k}, {"n", rule.n},
          {"description", qos::Describe(rule)}};
}

ordered_json ClustersJson(const MissClusters& c) {
  ordered_json windows = ordered_json::array();
  for (const MissClusters::RuleWindows& w : c.windows) {
    windows.push_back({{"rule", RuleJson(w.rule)},
                       {"windows_touched", w.windows_touched},
                       {"max_misses_in_window", w.max_misses_in_window}});
  }
  return {{"misses", c.misses},
          {"bursts", c.bursts},
          {"longest_burst", c.longest_burst},
          {"longest_burst_start_k", c.longest_burst_start_k},
          {"windows", std::move(windows)}};
}

// Every field of every class, so a reader finds the same keys on every cause (behind_cycle
// and inherited: null unless a backlog).
ordered_json CauseJson(const Cause& c) {
  ordered_json behind = c.behind_cycle ? ordered_json(*c.behind_cycle) : ordered_json(nullptr);
  ordered_json inherited =
      c.inherited ? ordered_json(ToString(*c.inherited)) : ordered_json(nullptr);
  return {{"class", ToString(c.cause)},
          {"duration_ns", c.duration_ns},
          {"cpu", c.cpu},
          {"behind_cycle", std::move(behind)},
          {"inherited", std::move(inherited)},
          {"thread", c.thread},
          {"pid", c.pid},
          {"policy", c.policy},
          {"priority", c.priority},
          {"interrupt", c.interrupt},
          {"irq", c.irq},
          {"faults", c.faults},
          {"address", c.address},
          {"evidence", c.evidence}};
}

ordered_json FeasibilityJson(const Feasibility& f) {
  return {{"feasible", f.feasible},
          {"latency_p50_ns", f.latency_p50_ns},
          {"compute_p50_ns", f.compute_p50_ns},
          {"deadline_ns", f.deadline_ns},
          {"max_rate_hz", f.max_rate_hz},
          {"verdict", f.verdict},
          {"advice", f.advice}};
}

ordered_json BurstJson(const Burst& b) {
  return {{"first_k", b.first_k},
          {"last_k", b.last_k},
          {"cycles", b.cycles},
          {"releases_skipped", b.releases_skipped},
          {"duration_ns", b.duration_ns}};
}

ordered_json CycleJson(const NotableCycle& n) {
  return {{"k", n.k},
          {"release_ns", n.release_ns},
          {"latency_ns", n.latency_ns},
          {"compute_ns", n.compute_ns},
          {"response_ns", n.response_ns},
          {"missed", n.missed},
          {"cause", CauseJson(n.cause)},
          {"burst", BurstJson(n.burst)}};
}

ordered_json CyclesJson(const std::vector<NotableCycle>& cycles) {
  ordered_json out = ordered_json::array();
  for (const NotableCycle& n : cycles) out.push_back(CycleJson(n));
  return out;
}

ordered_json CausesJson(const std::vector<CauseCount>& causes) {
  ordered_json out = ordered_json::array();
  for (const CauseCount& c : causes) {
    ordered_json culprits = ordered_json::array();
    for (const auto& [name, cycles] : c.culprits) culprits.push_back({{"name", name}, {"cycles", cycles}});
    out.push_back({{"class", ToString(c.cause)},
                   {"cycles", c.cycles},
                   {"misses", c.misses},
                   {"backlog_cycles", c.backlog},
                   {"culprits", std::move(culprits)}});
  }
  return out;
}

ordered_json LoopJson(const std::optional<LoopThread>& loop) {
  if (!loop) return nullptr;
  return {{"tid", loop->tid}, {"cpu", loop->cpu}, {"policy", detail::PolicyName(loop->policy)},
          {"priority", loop->priority}};
}

}  // namespace

ordered_json JitterToJson(const JitterReport& r) {
  ordered_json out;
  out["feasibility"] = FeasibilityJson(r.feasibility);  // first, as the text's first line
  out["source"] = detail::SourceName(r.source);
  out["path"] = r.path;
  out["period_ns"] = r.period_ns;
  out["deadline_ns"] = r.deadline_ns;
  out["first_release_ns"] = r.first_release_ns;
  out["cycles"] = r.cycles;
  out["cycles_judged"] = r.cycles_judged;
  out["releases_skipped"] = r.releases_skipped;
  out["deadline_misses"] = r.misses;
  out["miss_pct"] = r.miss_pct;
  out["trace_complete"] = r.trace_complete;
  out["discarded_events"] = r.discarded_events;
  out["kernel_recorded"] = r.kernel_recorded;
  out["kernel_lost_events"] = r.kernel_lost_events;
  out["kernel_preemption"] = {{"model", r.kernel_preemption.model},
                              {"source", r.kernel_preemption.source}};
  out["loop"] = LoopJson(r.loop);
  out["latency_ns"] = DistributionJson(r.latency);
  out["period_jitter_ns"] = DistributionJson(r.period_jitter);
  out["compute_ns"] = DistributionJson(r.compute);
  out["response_ns"] = DistributionJson(r.response);
  out["clusters"] = ClustersJson(r.clusters);
  out["worst"] = CyclesJson(r.worst);
  out["notable"] = CyclesJson(r.notable);
  out["causes"] = CausesJson(r.causes);
  out["warnings"] = r.warnings;
  return out;
}

}  // namespace hiltwin::analysis
