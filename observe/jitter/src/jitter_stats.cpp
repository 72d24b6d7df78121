#include "jitter_stats.h"

#include <algorithm>

#include "hiltwin/scheduler/log_linear_histogram.h"

namespace hiltwin::analysis::detail {

CycleStats AccumulateCycleStats(const TimingTrace& trace) {
  CycleStats stats;
  stats.latency_recorded.assign(trace.cycles.size(), false);
  bool has_previous = false;
  bool has_previous_start = false;
  scheduler::TimingSample previous;
  for (std::size_t i = 0; i < trace.cycles.size(); ++i) {
    const scheduler::TimingSample& s = trace.cycles[i].sample;
    // The executive's first cycle always finds the loop idle (its "previous end" is the moment
    // before t0); later ones are idle when the previous cycle ended by this release.
    const bool loop_was_idle = !has_previous || previous.end_ns <= s.release_ns;
    const bool neighbour =
        has_previous && s.cycle == previous.cycle + 1 + previous.releases_skipped;
    if (has_previous && !neighbour) {
      ++stats.gaps;
      const std::uint64_t expected = previous.cycle + 1 + previous.releases_skipped;
      if (s.cycle > expected) stats.cycles_missing += s.cycle - expected;
    }
    if (loop_was_idle) {
      stats.latency.Record(s.wake_ns - s.release_ns);
      stats.latency_recorded[i] = true;
    }
    stats.compute.Record(s.end_ns - s.start_ns - s.io_ns);
    stats.response.Record(s.end_ns - s.release_ns);
    // A cycle lost from the trace breaks the chain: start-to-start would span two periods.
    if (has_previous_start && neighbour) {
      stats.period_jitter.Record(s.start_ns - previous.start_ns - trace.period_ns);
    }
    has_previous_start = s.releases_skipped == 0;  // jitter only between neighbours
    previous = s;
    has_previous = true;
  }
  return stats;
}

Distribution MakeDistribution(const char* name, const scheduler::TimingStats& stats) {
  Distribution d;
  d.name = name;
  d.summary = stats.Summary();
  const scheduler::LogLinearHistogram& h = stats.histogram();
  for (std::size_t i = 0; i < scheduler::LogLinearHistogram::BucketCount(); ++i) {
    const std::uint64_t count = h.CountAt(i);
    if (count == 0) continue;
    d.bins.push_back({scheduler::LogLinearHistogram::BucketLow(i),
                      scheduler::LogLinearHistogram::BucketHigh(i), count});
  }
  return d;
}

namespace {

// A miss at position `position` of the judged-release sequence, release index `k`.
struct MissAt {
  std::uint64_t position = 0;
  std::uint64_t k = 0;
};

std::vector<MissAt> JudgedMisses(const TimingTrace& trace, std::uint64_t& releases) {
  std::vector<MissAt> misses;
  releases = 0;
  for (const TracedCycle& c : trace.cycles) {
    if (!c.judged) continue;
    if (c.sample.missed) misses.push_back({releases, c.sample.cycle});
    ++releases;
    for (std::uint32_t j = 1; j <= c.sample.releases_skipped; ++j) {
      misses.push_back({releases, c.sample.cycle + j});
      ++releases;
    }
  }
  return misses;
}

void CountBursts(const std::vector<MissAt>& misses, MissClusters& out) {
  std::uint64_t run = 0;
  std::uint64_t run_start_k = 0;
  for (std::size_t i = 0; i < misses.size(); ++i) {
    const bool continues = i > 0 && misses[i].position == misses[i - 1].position + 1;
    if (!continues) {
      ++out.bursts;
      run = 0;
      run_start_k = misses[i].k;
    }
    ++run;
    if (run > out.longest_burst) {
      out.longest_burst = run;
      out.longest_burst_start_k = run_start_k;
    }
  }
}

// Windows of `k` consecutive judged releases: those ending at t = k-1 .. releases-1 (one
// window, the whole run, when it is shorter than k).
MissClusters::RuleWindows CountWindows(const qos::RuleSpec& rule,
                                       const std::vector<MissAt>& misses,
                                       std::uint64_t releases) {
  MissClusters::RuleWindows w;
  w.rule = rule;
  const std::uint64_t k = std::max<std::uint64_t>(rule.k, 1);
  if (misses.empty()) return w;
  if (releases <= k) {
    w.windows_touched = 1;
    w.max_misses_in_window = misses.size();
    return w;
  }
  // Miss p lies in the windows ending at t ∈ [max(p, k-1), min(p+k-1, releases-1)]; misses
  // are sorted, so the union of these ranges is counted in one pass.
  std::uint64_t covered_until = 0;  // windows ending before this are already counted
  std::size_t first = 0;
  for (std::size_t i = 0; i < misses.size(); ++i) {
    const std::uint64_t p = misses[i].position;
    const std::uint64_t from = std::max({p, k - 1, covered_until});
    const std::uint64_t to = std::min(p + k - 1, releases - 1) + 1;
    if (to > from) {
      w.windows_touched += to - from;
      covered_until = to;
    }
    while (misses[first].position + k <= p) ++first;  // misses within k-1 before p
    w.max_misses_in_window = std::max<std::uint64_t>(w.max_misses_in_window, i - first + 1);
  }
  return w;
}

}  // namespace

MissClusters ClusterMisses(const TimingTrace& trace) {
  MissClusters out;
  std::uint64_t releases = 0;
  const std::vector<MissAt> misses = JudgedMisses(trace, releases);
  out.misses = misses.size();
  CountBursts(misses, out);
  for (const qos::RuleSpec& rule : trace.rules) {
    if (rule.kind == qos::RuleKind::kMkFirm || rule.kind == qos::RuleKind::kMissesInWindow) {
      out.windows.push_back(CountWindows(rule, misses, releases));
    }
  }
  return out;
}

}  // namespace hiltwin::analysis::detail
