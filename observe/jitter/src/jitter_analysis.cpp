#include <algorithm>
#include <cstdio>
#include <iterator>
#include <memory>
#include <unordered_map>

#include "cause_attribution.h"
#include "hiltwin/jitter/jitter_report.h"
#include "jitter_format.h"
#include "jitter_stats.h"

namespace hiltwin::analysis {

const char* ToString(CauseClass cause) noexcept {
  switch (cause) {
    case CauseClass::kPreempted:
      return "preempted";
    case CauseClass::kNonPreemptible:
      return "non_preemptible";
    case CauseClass::kInterrupt:
      return "interrupt";
    case CauseClass::kPageFault:
      return "page_fault";
    case CauseClass::kOwnCompute:
      return "own_compute";
    case CauseClass::kInvisible:
      return "invisible";
    case CauseClass::kBacklog:
      return "backlog";
    case CauseClass::kNotRecorded:
      return "not_recorded";
  }
  return "unknown";
}

namespace {

constexpr std::size_t kWorstCycles = 10;

// "1 cycle", "3 cycles".
std::string Count(std::uint64_t n, const char* noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

NotableCycle NotableOf(const scheduler::TimingSample& s) {
  NotableCycle n;
  n.k = s.cycle;
  n.release_ns = s.release_ns;
  n.latency_ns = s.wake_ns - s.release_ns;
  n.compute_ns = s.end_ns - s.start_ns - s.io_ns;
  n.response_ns = s.end_ns - s.release_ns;
  n.missed = s.missed;
  return n;
}

void CountReleases(const TimingTrace& trace, JitterReport& r) {
  std::uint64_t judged_releases = 0;
  for (const TracedCycle& c : trace.cycles) {
    r.releases_skipped += c.sample.releases_skipped;
    if (!c.judged) continue;
    ++r.cycles_judged;
    judged_releases += 1 + c.sample.releases_skipped;
  }
  r.misses = r.clusters.misses;
  r.miss_pct = judged_releases == 0
                   ? 0.0
                   : static_cast<double>(r.misses) * 100.0 / static_cast<double>(judged_releases);
}

// Every judged miss and every wake-up above the latency p99.9, in order of k.
std::vector<std::size_t> NotableIndices(const TimingTrace& trace, const detail::CycleStats& stats,
                                        std::int64_t latency_p999_ns) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < trace.cycles.size(); ++i) {
    const TracedCycle& c = trace.cycles[i];
    const bool late_wake =
        stats.latency_recorded[i] && c.sample.wake_ns - c.sample.release_ns > latency_p999_ns;
    if ((c.judged && c.sample.missed) || late_wake) out.push_back(i);
  }
  return out;
}

std::int64_t ResponseOf(const TracedCycle& c) { return c.sample.end_ns - c.sample.release_ns; }

// A run of consecutive late cycles, by index into the trace; `worst` has the longest response
// (the earliest of equals).
struct Stall {
  std::size_t first = 0;
  std::size_t last = 0;
  std::size_t worst = 0;
  Burst burst;
};

// Cycle `i` alone, or cycle `i` added to the stall before it.
Stall StartStall(const TimingTrace& trace, std::size_t i) {
  const scheduler::TimingSample& s = trace.cycles[i].sample;
  return {i, i, i, Burst{s.cycle, s.cycle, 1, s.releases_skipped, s.end_ns - s.release_ns}};
}
void ExtendStall(const TimingTrace& trace, std::size_t i, Stall& stall) {
  const scheduler::TimingSample& s = trace.cycles[i].sample;
  stall.last = i;
  if (ResponseOf(trace.cycles[i]) > ResponseOf(trace.cycles[stall.worst])) stall.worst = i;
  stall.burst.last_k = s.cycle;
  ++stall.burst.cycles;
  stall.burst.releases_skipped += s.releases_skipped;
  stall.burst.duration_ns = s.end_ns - trace.cycles[stall.first].sample.release_ns;
}

// The stalls of late cycles (missed, or response above the response p99.9 — the same "above
// p99.9" as a notable wake-up's), in trace order. Late cycles are one stall while each follows
// the previous (k on by one plus its skipped releases): a catch-up cycle released while the
// stalled one ran, or the cycle after a skipped release, belongs to the same stall; a cycle
// lost from the trace ends it.
std::vector<Stall> LateStalls(const TimingTrace& trace, std::int64_t response_p999_ns) {
  std::vector<Stall> stalls;
  bool previous_late = false;
  for (std::size_t i = 0; i < trace.cycles.size(); ++i) {
    const TracedCycle& c = trace.cycles[i];
    const bool late = c.sample.missed || ResponseOf(c) > response_p999_ns;
    if (!late) {
      previous_late = false;
      continue;
    }
    const scheduler::TimingSample* before = i > 0 ? &trace.cycles[i - 1].sample : nullptr;
    const bool follows =
        before != nullptr && c.sample.cycle == before->cycle + 1 + before->releases_skipped;
    if (previous_late && follows) {
      ExtendStall(trace, i, stalls.back());
    } else {
      stalls.push_back(StartStall(trace, i));
    }
    previous_late = true;
  }
  return stalls;
}

// The worst stalls, longest response first (earlier first on a tie).
std::vector<Stall> WorstStalls(const TimingTrace& trace, std::vector<Stall> stalls) {
  const std::size_t n = std::min(kWorstCycles, stalls.size());
  auto response = [&](const Stall& s) { return ResponseOf(trace.cycles[s.worst]); };
  std::partial_sort(stalls.begin(), stalls.begin() + static_cast<std::ptrdiff_t>(n), stalls.end(),
                    [&](const Stall& a, const Stall& b) {
                      return response(a) != response(b) ? response(a) > response(b)
                                                        : a.worst < b.worst;
                    });
  stalls.resize(n);
  return stalls;
}

// The stall cycle `i` belongs to: a late stall, or the cycle alone.
Burst BurstAt(const TimingTrace& trace, const std::vector<Stall>& stalls, std::size_t i) {
  auto it = std::upper_bound(stalls.begin(), stalls.end(), i,
                             [](std::size_t key, const Stall& s) { return key < s.first; });
  if (it != stalls.begin() && std::prev(it)->last >= i) return std::prev(it)->burst;
  return StartStall(trace, i).burst;
}

// What the attribution needs of the run: the window and what is normal.
detail::CauseWindow WindowOf(const scheduler::TimingSample& s, bool wake_only,
                             const JitterReport& r) {
  detail::CauseWindow w;
  w.begin_ns = s.release_ns;
  w.end_ns = wake_only ? s.wake_ns : s.end_ns;
  w.step_begin_ns = s.start_ns;
  w.step_end_ns = s.end_ns;
  w.compute_ns = s.end_ns - s.start_ns - s.io_ns;
  w.excess_ns = wake_only ? (s.wake_ns - s.release_ns) - r.latency.summary.p50_ns
                          : (s.end_ns - s.release_ns) - r.response.summary.p50_ns;
  w.wake_only = wake_only;
  w.compute_p50_ns = r.compute.summary.p50_ns;
  w.compute_p999_ns = r.compute.summary.p999_ns;
  return w;
}

void TraceWarnings(const TimingTrace& trace, const detail::CycleStats& stats, JitterReport& r) {
  if (trace.discarded_events > 0) {
    r.warnings.push_back(std::to_string(trace.discarded_events) +
                         " events discarded by the tracer: cycles may be missing from the figures");
  }
  if (!trace.complete) {
    r.warnings.emplace_back(trace.source == TraceSource::kLttng
                                ? "the trace is incomplete (no end of the loop seen): the run was "
                                  "cut short or the trace stopped early"
                                : "the timing log ends in a torn row: the run was cut short");
  }
  if (stats.gaps > 0) {
    r.warnings.push_back(Count(stats.cycles_missing, "cycle") + " missing from the trace in " +
                         Count(stats.gaps, "gap") +
                         " (k jumps): period jitter is left out across them");
  }
  if (trace.other_processes > 0) {
    r.warnings.push_back("the trace holds " + std::to_string(trace.other_processes) +
                         " other hiltwin processes; only pid " + std::to_string(trace.pid) +
                         " is analysed (choose another with `hiltwin trace --analyze DIR --pid "
                         "N`)");
  }
}

}  // namespace

namespace {

PreemptionModel PreemptionOf(const KernelTrace& kernel) {
  if (kernel.preemption_model.empty()) {
    return {"unknown", "the recording does not name it"};
  }
  return {kernel.preemption_model, kernel.preemption_source};
}

// Why kernel events cannot explain this trace's cycles, or "" when they can.
std::string WhyNoCauses(const TimingTrace& trace) {
  if (trace.source == TraceSource::kTimingLog) {
    return "kernel events were not matched to the cycles: a timing log's times count from "
           "release 0, not on the kernel's clock (trace with LTTng for causes)";
  }
  if (!trace.loop || trace.loop->tid <= 0) {
    return "kernel events were not matched to the cycles: the trace does not name the loop "
           "thread (no loop_start event)";
  }
  return "";
}

// The causes of cycles, each found once: a catch-up cycle's needs its predecessor's, and so
// on back to the stall that began the backlog (cause_attribution.h, "backlog").
class CycleCauses {
 public:
  CycleCauses(const TimingTrace& trace, const detail::CauseAttributor& attributor,
              const JitterReport& r)
      : cycles_(trace.cycles), attributor_(attributor), r_(r) {}

  // Cycle i's cause; `wake_only`: only its wake-up is notable (not for a catch-up cycle).
  Cause Of(std::size_t i, bool wake_only) {
    if (wake_only && !Behind(i)) return attributor_.Attribute(WindowOf(Sample(i), true, r_));
    std::size_t j = i;  // back to a cycle already known, or to the start of the backlog
    while (!known_.contains(j) && Behind(j)) --j;
    for (; j <= i; ++j) {
      if (!known_.contains(j)) known_.emplace(j, Resolve(j));
    }
    return known_.at(i);
  }

 private:
  [[nodiscard]] const scheduler::TimingSample& Sample(std::size_t i) const {
    return cycles_[i].sample;
  }
  // Released while its predecessor (the release before it, in the trace) still ran.
  [[nodiscard]] bool Behind(std::size_t i) const {
    if (i == 0) return false;
    const scheduler::TimingSample& p = Sample(i - 1);
    return p.cycle + 1 + p.releases_skipped == Sample(i).cycle && p.end_ns > Sample(i).release_ns;
  }
  // Cycle i's cause over its whole window; Of() has found its predecessor's already.
  Cause Resolve(std::size_t i) {
    detail::CauseWindow w = WindowOf(Sample(i), false, r_);
    if (!Behind(i)) return attributor_.Attribute(w);
    const std::int64_t waited_ns = Sample(i - 1).end_ns - Sample(i).release_ns;
    w.begin_ns = Sample(i - 1).end_ns;
    w.excess_ns -= waited_ns;
    if (w.excess_ns > 0) {
      Cause own = attributor_.Attribute(w);
      if (own.cause != CauseClass::kNotRecorded && own.duration_ns > waited_ns) return own;
    }
    const auto stall = stall_of_.find(i - 1);
    const std::size_t s = stall != stall_of_.end() ? stall->second : i - 1;
    stall_of_[i] = s;
    return detail::BacklogBehind(known_.at(s), Sample(s).cycle, waited_ns);
  }

  const std::vector<TracedCycle>& cycles_;
  const detail::CauseAttributor& attributor_;
  const JitterReport& r_;
  std::unordered_map<std::size_t, Cause> known_;        // full-window causes, by index
  std::unordered_map<std::size_t, std::size_t> stall_of_;  // a backlog cycle's stall
};

void AttributeCauses(const TimingTrace& trace, const KernelTrace* kernel,
                     const std::vector<std::size_t>& notable, const std::vector<std::size_t>& worst,
                     JitterReport& r) {
  const std::string why_not = kernel != nullptr ? WhyNoCauses(trace) : "";
  if (!why_not.empty()) r.warnings.push_back(why_not);
  r.kernel_recorded = kernel != nullptr && why_not.empty();
  if (!r.kernel_recorded) {
    for (NotableCycle& n : r.notable) n.cause.cause = CauseClass::kNotRecorded;
    for (NotableCycle& n : r.worst) n.cause.cause = CauseClass::kNotRecorded;
    return;
  }
  r.kernel_lost_events = kernel->lost_events;
  if (kernel->lost_events > 0) {
    r.warnings.push_back(std::to_string(kernel->lost_events) +
                         " kernel events lost (ring buffer overruns): a cause may be missing");
  }
  const detail::CauseAttributor attributor(*kernel, *trace.loop);
  for (std::string& w : attributor.Warnings()) r.warnings.push_back(std::move(w));
  r.kernel_preemption = PreemptionOf(*kernel);
  CycleCauses causes(trace, attributor, r);
  auto attribute = [&](std::size_t i, NotableCycle& n) {
    const TracedCycle& c = trace.cycles[i];
    // A cycle that is notable only for its wake-up (no miss) is explained up to the wake.
    const bool wake_only =
        !(c.judged && c.sample.missed) && n.response_ns <= r.response.summary.p999_ns;
    n.cause = causes.Of(i, wake_only);
  };
  for (std::size_t j = 0; j < notable.size(); ++j) attribute(notable[j], r.notable[j]);
  for (std::size_t j = 0; j < worst.size(); ++j) attribute(worst[j], r.worst[j]);
  r.causes = detail::RankCauses(r.notable);
}

// The command that finds the rate this machine holds, on the loop's CPU and priority.
std::string TuneAdvice(const std::optional<LoopThread>& loop) {
  std::string advice = "hiltwin tune";
  if (!loop) return advice;
  if (loop->cpu >= 0) advice += " --cpu " + std::to_string(loop->cpu);
  const bool rt = loop->policy == 1 || loop->policy == 2;  // SCHED_FIFO, SCHED_RR
  return advice + " --priority " + std::to_string(rt ? loop->priority : 0);
}

// Whether the median cycle fits its deadline; when not, the verdict the report opens with.
Feasibility JudgeFeasibility(const JitterReport& r) {
  Feasibility f;
  f.latency_p50_ns = r.latency.summary.p50_ns;
  f.compute_p50_ns = r.compute.summary.p50_ns;
  f.deadline_ns = r.deadline_ns;
  const std::int64_t median_ns = f.latency_p50_ns + f.compute_p50_ns;
  if (r.deadline_ns <= 0 || r.period_ns <= 0 || r.latency.summary.count == 0 || median_ns <= 0) {
    return f;  // no deadline known (a trace begun after loop_start), or no latency recorded
  }
  f.max_rate_hz = 1'000'000'000 / median_ns;
  f.advice = TuneAdvice(r.loop);
  if (median_ns <= r.deadline_ns) return f;
  f.feasible = false;
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g Hz", 1e9 / static_cast<double>(r.period_ns));
  f.verdict = "INFEASIBLE HERE: the median wake-up latency (" +
              detail::FormatDuration(f.latency_p50_ns) + ") plus the median compute (" +
              detail::FormatDuration(f.compute_p50_ns) + ") is " +
              detail::FormatDuration(median_ns) + ", above the " +
              detail::FormatDuration(f.deadline_ns) + " deadline: " + rate +
              " cannot be kept on this machine (its medians allow at most " +
              std::to_string(f.max_rate_hz) + " Hz); find the rate it holds with `" + f.advice +
              "`";
  return f;
}

}  // namespace

JitterReport AnalyzeJitter(const TimingTrace& trace, const KernelTrace* kernel) {
  if (trace.cycles.empty()) {
    throw TraceReadError(trace.path +
                         ": the trace holds no cycle of the loop (was the run "
                         "traced, and did it get past its start?)");
  }
  JitterReport r;
  r.source = trace.source;
  r.path = trace.path;
  r.period_ns = trace.period_ns;
  r.deadline_ns = trace.deadline_ns;
  r.cycles = trace.cycles.size();
  r.first_release_ns = trace.cycles.front().sample.release_ns;
  r.discarded_events = trace.discarded_events;
  r.trace_complete = trace.complete;
  r.loop = trace.loop;

  const detail::CycleStats stats = detail::AccumulateCycleStats(trace);
  r.latency = detail::MakeDistribution("latency", stats.latency);
  r.period_jitter = detail::MakeDistribution("period_jitter", stats.period_jitter);
  r.compute = detail::MakeDistribution("compute", stats.compute);
  r.response = detail::MakeDistribution("response", stats.response);
  r.clusters = detail::ClusterMisses(trace);
  CountReleases(trace, r);
  r.feasibility = JudgeFeasibility(r);
  TraceWarnings(trace, stats, r);

  const std::vector<Stall> stalls = LateStalls(trace, r.response.summary.p999_ns);
  const std::vector<std::size_t> notable = NotableIndices(trace, stats, r.latency.summary.p999_ns);
  for (const std::size_t i : notable) {
    r.notable.push_back(NotableOf(trace.cycles[i].sample));
    r.notable.back().burst = BurstAt(trace, stalls, i);
  }
  std::vector<std::size_t> worst;
  for (const Stall& s : WorstStalls(trace, stalls)) {
    worst.push_back(s.worst);
    r.worst.push_back(NotableOf(trace.cycles[s.worst].sample));
    r.worst.back().burst = s.burst;
  }
  AttributeCauses(trace, kernel, notable, worst, r);
  return r;
}

}  // namespace hiltwin::analysis
