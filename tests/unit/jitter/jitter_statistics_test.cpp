// The jitter report's figures against known answers and against scheduler::TimingStats fed
// the same values the executive would have fed it.

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/scheduler/timing_stats.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {

using testing::CycleOverride;
using testing::MakeTrace;
using testing::RunSpec;

// 10 000 releases at 50 µs, deadline 40 µs. Wake-up latency 3.0–3.7 µs, compute 20–24.5 µs.
// Injected: k=1000 compute 41 µs (miss); k=3000 wake-up 25 µs (no miss, above p99.9);
// k=5000 compute 130 µs (miss, releases 5001 and 5002 skipped: a burst of 3);
// k=7000, 7002 compute 42/43 µs (misses); k=9000..9009 paused (not judged), 9005 misses.
RunSpec ReferenceRun() {
  RunSpec spec;
  spec.releases = 10'000;
  spec.period_ns = 50'000;
  spec.deadline_ns = 40'000;
  spec.io_ns = 1'000;
  spec.latency_ns = [](std::uint64_t k) { return 3'000 + static_cast<std::int64_t>(k % 8) * 100; };
  spec.compute_ns = [](std::uint64_t k) { return 20'000 + static_cast<std::int64_t>(k % 10) * 500; };
  auto base_latency = spec.latency_ns;
  spec.overrides[1000] = {base_latency(1000), 41'000};
  spec.overrides[3000] = {25'000, 10'000};
  spec.overrides[5000] = {base_latency(5000), 130'000};
  spec.overrides[7000] = {base_latency(7000), 42'000};
  spec.overrides[7002] = {base_latency(7002), 43'000};
  spec.overrides[9005] = {base_latency(9005), 44'000};
  for (std::uint64_t k = 9000; k < 9010; ++k) spec.unjudged.insert(k);
  return spec;
}

TimingTrace ReferenceTrace() {
  TimingTrace trace = MakeTrace(ReferenceRun());
  trace.rules = {qos::MakeMkRule(3, 4), qos::MakeMissesInWindowRule(1, 10),
                 qos::MakeConsecutiveMissesRule(5)};
  return trace;
}

void ExpectSameSummary(const scheduler::TimingSummary& got, const scheduler::TimingSummary& want,
                       const char* what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(got.count, want.count);
  EXPECT_EQ(got.min_ns, want.min_ns);
  EXPECT_DOUBLE_EQ(got.mean_ns, want.mean_ns);
  EXPECT_EQ(got.p50_ns, want.p50_ns);
  EXPECT_EQ(got.p99_ns, want.p99_ns);
  EXPECT_EQ(got.p999_ns, want.p999_ns);
  EXPECT_EQ(got.max_ns, want.max_ns);
}

TEST(JitterStatistics, CountsMissesAndSkippedReleasesLikeTheQosLedger) {
  const JitterReport r = AnalyzeJitter(ReferenceTrace(), nullptr);
  EXPECT_EQ(r.cycles, 9'998u);  // 5001 and 5002 never ran
  EXPECT_EQ(r.cycles_judged, 9'988u);
  EXPECT_EQ(r.releases_skipped, 2u);
  EXPECT_EQ(r.misses, 6u);  // 1000, 5000, 5001, 5002, 7000, 7002 (9005 was not judged)
  EXPECT_DOUBLE_EQ(r.miss_pct, 6.0 * 100.0 / 9'990.0);
  EXPECT_EQ(r.period_ns, 50'000);
  EXPECT_EQ(r.deadline_ns, 40'000);
  EXPECT_EQ(r.first_release_ns, 1'000'000'000);
}

TEST(JitterStatistics, BurstsAndWindowsByHand) {
  const JitterReport r = AnalyzeJitter(ReferenceTrace(), nullptr);
  const MissClusters& c = r.clusters;
  EXPECT_EQ(c.misses, 6u);
  EXPECT_EQ(c.bursts, 4u);  // {1000} {5000 5001 5002} {7000} {7002}
  EXPECT_EQ(c.longest_burst, 3u);
  EXPECT_EQ(c.longest_burst_start_k, 5000u);
  ASSERT_EQ(c.windows.size(), 2u);  // the consecutive-miss rule has no windows
  // (3,4): windows ending at t ∈ [3, 9989] (9990 judged releases). A miss at p touches those
  // ending at p..p+3: 1000 → 4; 5000–5002 → 5000..5005 = 6; 7000, 7002 → 7000..7005 = 6.
  EXPECT_EQ(c.windows[0].rule, qos::MakeMkRule(3, 4));
  EXPECT_EQ(c.windows[0].windows_touched, 16u);
  EXPECT_EQ(c.windows[0].max_misses_in_window, 3u);
  // At most 1 in 10: 1000 → 10; 5000–5002 → 5000..5011 = 12; 7000, 7002 → 7000..7011 = 12.
  EXPECT_EQ(c.windows[1].windows_touched, 34u);
  EXPECT_EQ(c.windows[1].max_misses_in_window, 3u);
}

TEST(JitterStatistics, PercentilesEqualTimingStatsFedTheSameValues) {
  const RunSpec spec = ReferenceRun();
  const TimingTrace trace = ReferenceTrace();
  scheduler::TimingStats latency, jitter, compute, response;
  std::int64_t previous_latency = 0;
  std::uint64_t previous_k = 0;
  bool first = true;
  for (std::uint64_t k = 0; k < spec.releases; ++k) {
    if (k == 5001 || k == 5002) continue;  // skipped: never ran
    std::int64_t l = spec.latency_ns(k);
    std::int64_t c = spec.compute_ns(k);
    if (const auto o = spec.overrides.find(k); o != spec.overrides.end()) {
      l = o->second.latency_ns;
      c = o->second.compute_ns;
    }
    latency.Record(l);  // every cycle found the loop asleep at its release
    compute.Record(c);
    response.Record(l + testing::kWakeToStartNs + c + spec.io_ns);
    // start-to-start minus the period is the latency difference between neighbours; none for
    // the first cycle and none across the skipped releases (5000 → 5003).
    if (!first && k == previous_k + 1) jitter.Record(l - previous_latency);
    first = false;
    previous_k = k;
    previous_latency = l;
  }
  const JitterReport r = AnalyzeJitter(trace, nullptr);
  ExpectSameSummary(r.latency.summary, latency.Summary(), "latency");
  ExpectSameSummary(r.period_jitter.summary, jitter.Summary(), "period jitter");
  ExpectSameSummary(r.compute.summary, compute.Summary(), "compute");
  ExpectSameSummary(r.response.summary, response.Summary(), "response");
  EXPECT_EQ(r.period_jitter.summary.count, 9'996u);
  // The bins are the histogram's own: they add up to the count and ascend.
  std::uint64_t binned = 0;
  for (std::size_t i = 0; i < r.latency.bins.size(); ++i) {
    binned += r.latency.bins[i].count;
    EXPECT_LT(r.latency.bins[i].low_ns, r.latency.bins[i].high_ns);
    if (i > 0) {
      EXPECT_LE(r.latency.bins[i - 1].high_ns, r.latency.bins[i].low_ns);
    }
  }
  EXPECT_EQ(binned, r.latency.summary.count);
}

TEST(JitterStatistics, TheTenWorstCyclesInOrderOfResponse) {
  const JitterReport r = AnalyzeJitter(ReferenceTrace(), nullptr);
  std::vector<std::uint64_t> ks;
  for (const NotableCycle& n : r.worst) ks.push_back(n.k);
  // 5000 134.1 µs, 9005 48.6, 7002 47.3, 7000 46.1, 1000 45.1, 3000 36.1, then the run's
  // longest ordinary cycles (29.3 µs: k ≡ 39 mod 40), earliest first.
  const std::vector<std::uint64_t> want = {5000, 9005, 7002, 7000, 1000, 3000, 39, 79, 119, 159};
  EXPECT_EQ(ks, want);
  EXPECT_EQ(r.worst[0].response_ns, 134'100);
  EXPECT_EQ(r.worst[0].latency_ns, 3'000);
  EXPECT_EQ(r.worst[0].compute_ns, 130'000);
  EXPECT_TRUE(r.worst[0].missed);
  EXPECT_EQ(r.worst[0].release_ns, 1'000'000'000 + 5000 * 50'000);
  EXPECT_FALSE(r.worst[5].missed);
}

TEST(JitterStatistics, NotableCyclesAreJudgedMissesAndWakeUpsStrictlyAboveP999) {
  const JitterReport r = AnalyzeJitter(ReferenceTrace(), nullptr);
  std::vector<std::uint64_t> ks;
  for (const NotableCycle& n : r.notable) ks.push_back(n.k);
  const std::vector<std::uint64_t> want = {1000, 3000, 5000, 7000, 7002};
  EXPECT_EQ(ks, want);
  EXPECT_GT(r.notable[1].latency_ns, r.latency.summary.p999_ns);
  EXPECT_FALSE(r.notable[1].missed);
  EXPECT_FALSE(r.kernel_recorded);
  EXPECT_TRUE(r.causes.empty());
  for (const NotableCycle& n : r.notable) EXPECT_EQ(n.cause.cause, CauseClass::kNotRecorded);
  for (const NotableCycle& n : r.worst) EXPECT_EQ(n.cause.cause, CauseClass::kNotRecorded);
}

TEST(JitterStatistics, CatchUpCyclesLeaveLatencyOutButKeepPeriodJitter) {
  // Three cycles under catch-up: k=1 overruns past release 2, so k=2 starts late with the
  // loop busy at its release: the executive records no wake-up latency for it.
  TimingTrace trace;
  trace.period_ns = 50'000;
  trace.deadline_ns = 50'000;
  auto cycle = [](std::uint64_t k, std::int64_t wake, std::int64_t end) {
    scheduler::TimingSample s;
    s.cycle = k;
    s.release_ns = static_cast<std::int64_t>(k) * 50'000;
    s.wake_ns = wake;
    s.start_ns = wake;
    s.end_ns = end;
    s.missed = end > s.release_ns + 50'000;
    return TracedCycle{s, true};
  };
  trace.cycles = {cycle(0, 2'000, 20'000), cycle(1, 52'000, 130'000), cycle(2, 130'500, 150'000)};
  const JitterReport r = AnalyzeJitter(trace, nullptr);
  EXPECT_EQ(r.latency.summary.count, 2u);
  EXPECT_EQ(r.latency.summary.max_ns, 2'000);
  EXPECT_EQ(r.period_jitter.summary.count, 2u);
  EXPECT_EQ(r.period_jitter.summary.max_ns, 130'500 - 52'000 - 50'000);
  EXPECT_EQ(r.response.summary.count, 3u);
  EXPECT_EQ(r.misses, 1u);
}

TEST(JitterStatistics, ACycleLostFromTheTraceBreaksPeriodJitterAndIsWarnedAbout) {
  RunSpec spec;
  spec.releases = 100;
  TimingTrace trace = MakeTrace(spec);
  trace.cycles.erase(trace.cycles.begin() + 50);
  trace.discarded_events = 3;
  const JitterReport r = AnalyzeJitter(trace, nullptr);
  EXPECT_EQ(r.period_jitter.summary.count, 97u);  // 98 neighbours, less the pair across the gap
  EXPECT_EQ(r.discarded_events, 3u);
  const auto mentions = [&](const char* text) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(mentions("1 cycle missing from the trace in 1 gap"));
  EXPECT_TRUE(mentions("3 events discarded"));
}

TEST(JitterStatistics, AnEmptyTraceIsAnError) {
  TimingTrace trace;
  trace.path = "empty.ctf";
  EXPECT_THROW((void)AnalyzeJitter(trace, nullptr), TraceReadError);
}

}  // namespace
}  // namespace hiltwin::analysis
