#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_format.h"
#include "hiltwin/report_kit/string_format.h"
#include "hiltwin/report_kit/time_units.h"
#include "hiltwin/scheduler/log_linear_histogram.h"

namespace hiltwin::analysis {
namespace {

using detail::Us;

using detail::Format;


void Header(const JitterReport& r, std::string& out) {
  if (!r.feasibility.feasible) out += r.feasibility.verdict + "\n";  // before any cause
  out += "hiltwin jitter report: " + r.path + " (" + detail::SourceName(r.source) + ")\n";
  out += Format("period %s, deadline %s; %llu cycles (%llu judged), %llu releases skipped\n",
                detail::FormatDuration(r.period_ns).c_str(),
                detail::FormatDuration(r.deadline_ns).c_str(),
                static_cast<unsigned long long>(r.cycles),
                static_cast<unsigned long long>(r.cycles_judged),
                static_cast<unsigned long long>(r.releases_skipped));
  out += Format("deadline misses: %llu (%.3f %% of judged releases, skipped ones included)\n",
                static_cast<unsigned long long>(r.misses), r.miss_pct);
  out += Format("%llu events discarded by the tracer; kernel: ",
                static_cast<unsigned long long>(r.discarded_events));
  out += r.kernel_recorded ? Format("recorded, %llu events lost\n",
                                    static_cast<unsigned long long>(r.kernel_lost_events))
                           : std::string("not recorded\n");
  out += std::string("trace complete: ") + (r.trace_complete ? "yes" : "no");
  if (r.loop) {
    const bool rt = r.loop->policy == 1 || r.loop->policy == 2;  // SCHED_FIFO, SCHED_RR
    out += Format("; loop thread tid %d on CPU %d (%s", r.loop->tid, r.loop->cpu,
                  detail::PolicyName(r.loop->policy));
    out += rt ? Format(" %d)", r.loop->priority) : std::string(")");
  }
  out += "\n";
  if (r.kernel_recorded) {
    out += "kernel preemption model: " + r.kernel_preemption.model + " (" +
           r.kernel_preemption.source + ")\n";
  }
  out += "\n";
}

void Table(const JitterReport& r, std::string& out) {
  out += "[us]                 count       min       p50       p99     p99.9       max\n";
  for (const Distribution* d : {&r.latency, &r.period_jitter, &r.compute, &r.response}) {
    const scheduler::TimingSummary& s = d->summary;
    std::string name = d->name == "period_jitter" ? "period jitter |x|" : d->name;
    out += Format("%-17s %8llu %9.1f %9.1f %9.1f %9.1f %9.1f\n", name.c_str(),
                  static_cast<unsigned long long>(s.count), Us(s.min_ns), Us(s.p50_ns),
                  Us(s.p99_ns), Us(s.p999_ns), Us(s.max_ns));
  }
  out += "(period jitter: min and max signed, percentiles of the magnitude)\n\n";
}

// A bin edge in µs to the nanosecond: "4.992", "50", "1998.848".
std::string ExactUs(std::int64_t ns) {
  std::string text = Format("%.3f", Us(ns));
  text.erase(text.find_last_not_of('0') + 1);
  if (text.back() == '.') text.pop_back();
  return text;
}

// Row edges on a 1-2-5 scale from 0 to past `last_low_ns`, each moved down to the edge of the
// histogram bin it falls in (5 µs lies inside the bin [4992, 5024) ns: the row edge is 4992),
// so a row holds whole bins and its count is exact for the range it prints. The histogram's
// top bin (2^40 ns and above) ends the scale: what lies past the last edge is the last row's.
std::vector<std::int64_t> RowEdges(std::int64_t last_low_ns) {
  using Bins = scheduler::LogLinearHistogram;
  constexpr std::int64_t kLastDecade = 1'000'000'000'000;  // 1000 s, past the top bin
  std::vector<std::int64_t> edges = {0};
  for (std::int64_t decade = 100; edges.back() <= last_low_ns && decade <= kLastDecade;
       decade *= 10) {
    for (const std::int64_t step : {1, 2, 5}) {
      const std::int64_t edge = Bins::BucketLow(Bins::BucketIndex(decade * step));
      if (edge > edges.back()) edges.push_back(edge);
    }
  }
  return edges;
}

// Rows from the first to the last non-empty one, bars on a log scale, then the cycles with no
// wake-up latency (released while the previous one ran, as the run report leaves them out),
// so the rows add up to every cycle of the trace.
void AsciiHistogram(const JitterReport& r, std::string& out) {
  const Distribution& d = r.latency;
  if (d.bins.empty()) return;
  const std::vector<std::int64_t> edges = RowEdges(d.bins.back().low_ns);
  std::vector<std::uint64_t> counts(edges.size(), 0);
  for (const HistogramBin& b : d.bins) {
    const auto row = std::upper_bound(edges.begin(), edges.end(), b.low_ns) - edges.begin() - 1;
    counts[static_cast<std::size_t>(row)] += b.count;
  }
  std::size_t first = 0;
  while (counts[first] == 0) ++first;
  std::size_t last = counts.size() - 1;
  while (counts[last] == 0) --last;
  const std::uint64_t most = *std::max_element(counts.begin(), counts.end());
  out += "wake-up latency histogram (bars on a log scale; rows are whole bins of the JSON's\n"
         "latency_ns.bins, so each count is exact for its range):\n";
  for (std::size_t i = first; i <= last; ++i) {
    const double scale = std::log10(static_cast<double>(most) + 1.0);
    const auto width = static_cast<std::size_t>(
        std::lround(40.0 * std::log10(static_cast<double>(counts[i]) + 1.0) / scale));
    const std::string upper = i + 1 < edges.size() ? ExactUs(edges[i + 1]) : "inf";
    out += Format("  %9s - %-9s us |%-40s %llu\n", ExactUs(edges[i]).c_str(), upper.c_str(),
                  std::string(width, '#').c_str(), static_cast<unsigned long long>(counts[i]));
  }
  const std::uint64_t without = r.cycles - d.summary.count;
  if (without > 0) {
    out += Format("  no wake-up latency (released while the previous cycle ran): %llu\n",
                  static_cast<unsigned long long>(without));
  }
  out += Format("  total: %llu cycles\n\n", static_cast<unsigned long long>(r.cycles));
}

void Clusters(const JitterReport& r, std::string& out) {
  const MissClusters& c = r.clusters;
  out += Format("misses: %llu in %llu bursts; longest burst %llu releases from k=%llu\n",
                static_cast<unsigned long long>(c.misses), static_cast<unsigned long long>(c.bursts),
                static_cast<unsigned long long>(c.longest_burst),
                static_cast<unsigned long long>(c.longest_burst_start_k));
  for (const MissClusters::RuleWindows& w : c.windows) {
    out += "  " + qos::Describe(w.rule) +
           Format(": %llu windows held a miss, at most %llu misses in one window\n",
                  static_cast<unsigned long long>(w.windows_touched),
                  static_cast<unsigned long long>(w.max_misses_in_window));
  }
  out += "\n";
}

}  // namespace

namespace {

// "stall k=8000..8049: 50 cycles (+2 releases skipped), 2.50 ms".
std::string StallLine(const Burst& b) {
  std::string line = "stall k=" + std::to_string(b.first_k);
  if (b.last_k != b.first_k) line += ".." + std::to_string(b.last_k);
  line += Format(": %llu cycle%s", static_cast<unsigned long long>(b.cycles),
                 b.cycles == 1 ? "" : "s");
  if (b.releases_skipped > 0) {
    line += Format(" (+%llu release%s skipped)",
                   static_cast<unsigned long long>(b.releases_skipped),
                   b.releases_skipped == 1 ? "" : "s");
  }
  return line + ", " + detail::FormatDuration(b.duration_ns);
}

// One entry per stall (consecutive late cycles), shown by its worst cycle: a stall and the
// catch-up behind it are one event, not ten.
void Worst(const JitterReport& r, std::string& out) {
  const std::string p999 = detail::FormatDuration(r.response.summary.p999_ns);
  if (r.worst.empty()) {
    out += "worst stalls: none (no cycle missed or responded above p99.9 = " + p999 + ")\n\n";
    return;
  }
  out += Format("%zu worst stalls by response time (a stall: consecutive cycles that missed or\n"
                "responded above p99.9 = %s, shown by its worst; t: seconds since the first "
                "release):\n",
                r.worst.size(), p999.c_str());
  out += "         k          t    latency    compute   response  miss  cause\n";
  for (const NotableCycle& n : r.worst) {
    out += Format("  %8llu %10.6f %10s %10s %10s  %-4s  %s\n", static_cast<unsigned long long>(n.k),
                  static_cast<double>(n.release_ns - r.first_release_ns) * 1e-9,
                  detail::FormatDuration(n.latency_ns).c_str(),
                  detail::FormatDuration(n.compute_ns).c_str(),
                  detail::FormatDuration(n.response_ns).c_str(), n.missed ? "MISS" : "",
                  ToString(n.cause.cause));
    out += "            " + StallLine(n.burst) + "\n";
    if (!n.cause.evidence.empty()) out += "            " + n.cause.evidence + "\n";
  }
  out += "\n";
}

void Causes(const JitterReport& r, std::string& out) {
  if (!r.kernel_recorded) {
    out += std::string(detail::kCausesNotRecorded) + "\n\n";
    return;
  }
  out += Format("causes of the %zu notable cycles (every miss, every wake-up above p99.9 = %s):\n",
                r.notable.size(), detail::FormatDuration(r.latency.summary.p999_ns).c_str());
  if (r.causes.empty()) out += "  none: no cycle missed and no wake-up was above p99.9\n";
  // A stall's catch-up cycles count with it ("of them backlog"), under its class and culprit.
  if (!r.causes.empty()) out += "  cause            cycles  misses  backlog  top culprits\n";
  for (const CauseCount& c : r.causes) {
    std::string culprits;
    for (const auto& [name, cycles] : c.culprits) {
      culprits += (culprits.empty() ? "" : ", ") + name + Format(" x%llu", static_cast<unsigned long long>(cycles));
    }
    out += Format("  %-15s %7llu %7llu  %7llu  %s\n", ToString(c.cause),
                  static_cast<unsigned long long>(c.cycles),
                  static_cast<unsigned long long>(c.misses),
                  static_cast<unsigned long long>(c.backlog), culprits.c_str());
  }
  out += "\n";
}

void Warnings(const JitterReport& r, std::string& out) {
  if (r.warnings.empty()) {
    out += "warnings: none\n";
    return;
  }
  out += "warnings:\n";
  for (const std::string& w : r.warnings) out += "  - " + w + "\n";
}

}  // namespace

std::string FormatJitterText(const JitterReport& report) {
  std::string out;
  Header(report, out);
  Table(report, out);
  AsciiHistogram(report, out);
  Clusters(report, out);
  Worst(report, out);
  Causes(report, out);
  Warnings(report, out);
  return out;
}

}  // namespace hiltwin::analysis
