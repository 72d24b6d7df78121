// The text report's counts against the cycles they come from: the latency histogram's rows
// (each row exact for the range it prints, all rows together = every cycle of the trace) and
// the worst stalls (one entry per burst of late cycles, with the burst's length), in the text
// and in the JSON.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {
// Named too: the tests are compiled in unity batches, where anonymous namespaces merge.
namespace text_rows_test {

// A run under the catch-up policy (no release is skipped): a cycle released while the
// previous one still ran starts 200 ns after its end, with no wake-up latency of its own.
TimingTrace CatchUpTrace(std::uint64_t releases, std::int64_t period_ns,
                         const std::function<std::int64_t(std::uint64_t)>& latency_ns,
                         const std::function<std::int64_t(std::uint64_t)>& compute_ns) {
  testing::RunSpec one;
  one.releases = 1;
  TimingTrace trace = testing::MakeTrace(one);
  trace.period_ns = period_ns;
  trace.deadline_ns = period_ns;
  trace.cycles.clear();
  std::int64_t previous_end = 0;
  for (std::uint64_t k = 0; k < releases; ++k) {
    scheduler::TimingSample s;
    s.cycle = k;
    s.release_ns = 1'000'000'000 + static_cast<std::int64_t>(k) * period_ns;
    const bool busy = k > 0 && previous_end > s.release_ns;
    s.wake_ns = busy ? previous_end + 200 : s.release_ns + latency_ns(k);
    s.start_ns = s.wake_ns + testing::kWakeToStartNs;
    s.end_ns = s.start_ns + compute_ns(k);
    s.missed = s.end_ns > s.release_ns + trace.deadline_ns;
    previous_end = s.end_ns;
    trace.cycles.push_back({s, true});
  }
  return trace;
}

// Latencies piled up on both sides of the 1-2-5 row edges (5, 10, 50 µs fall inside the
// histogram's bins [4992, 5024), [9984, 10048), [49920, 50176)), and three stalls of 400 µs
// each followed by catch-up cycles.
TimingTrace SkewedTrace() {
  auto latency = [](std::uint64_t k) -> std::int64_t {
    static constexpr std::int64_t kValues[] = {4'995, 5'010, 5'020, 9'990, 10'030, 49'950, 50'100};
    return k % 50 == 7 ? 2'000 : kValues[k % 7];
  };
  auto compute = [](std::uint64_t k) -> std::int64_t {
    return k == 1'000 || k == 3'000 || k == 7'000 ? 400'000 : 20'000;
  };
  return CatchUpTrace(10'000, 100'000, latency, compute);
}

struct Row {
  std::int64_t low_ns = 0;
  std::int64_t high_ns = 0;  // -1: open ("inf")
  std::uint64_t count = 0;
};

std::int64_t UsToNs(const std::string& us) { return std::llround(std::stod(us) * 1e3); }

// The histogram's rows and its line for the cycles without a wake-up latency.
std::vector<Row> HistogramRows(const std::string& text, std::uint64_t& without_latency) {
  const std::regex row(R"(^\s+([0-9.]+) - ([0-9.]+|inf)\s+us \|#*\s+(\d+)$)");
  const std::regex none(
      R"(^\s+no wake-up latency \(released while the previous cycle ran\):\s+(\d+)$)");
  std::vector<Row> rows;
  without_latency = 0;
  std::istringstream in(text.substr(text.find("wake-up latency histogram")));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line) && !line.empty()) {
    std::smatch m;
    if (std::regex_match(line, m, row)) {
      rows.push_back({UsToNs(m[1]), m[2] == "inf" ? -1 : UsToNs(m[2]), std::stoull(m[3])});
    } else if (std::regex_match(line, m, none)) {
      without_latency = std::stoull(m[1]);
    }
  }
  return rows;
}

TEST(JitterTextRows, HistogramRowsAreExactForTheirRangeAndSumToEveryCycle) {
  const TimingTrace trace = SkewedTrace();
  const JitterReport r = AnalyzeJitter(trace, nullptr);
  const std::string text = FormatJitterText(r);
  std::uint64_t without_latency = 0;
  const std::vector<Row> rows = HistogramRows(text, without_latency);
  ASSERT_GE(rows.size(), 4u) << text;
  std::uint64_t sum = without_latency;
  for (const Row& row : rows) {
    std::uint64_t in_range = 0;  // recomputed from the cycles whose latency was recorded
    for (std::size_t i = 0; i < trace.cycles.size(); ++i) {
      const scheduler::TimingSample& s = trace.cycles[i].sample;
      if (i > 0 && trace.cycles[i - 1].sample.end_ns > s.release_ns) continue;  // catch-up
      const std::int64_t v = s.wake_ns - s.release_ns;
      if (v >= row.low_ns && (row.high_ns < 0 || v < row.high_ns)) ++in_range;
    }
    EXPECT_EQ(row.count, in_range) << "row " << row.low_ns << " - " << row.high_ns << "\n" << text;
    sum += row.count;
  }
  EXPECT_GT(without_latency, 0u) << text;
  EXPECT_EQ(without_latency, r.cycles - r.latency.summary.count);
  EXPECT_EQ(sum, r.cycles) << text;
  EXPECT_NE(text.find("total: 10000 cycles"), std::string::npos) << text;
}

// 10 000 releases at 50 µs, deadline 40 µs; three stalls of 50 consecutive missed cycles
// (compute 45 µs: response 48.1 µs, no release skipped), one cycle in each a little worse.
TimingTrace ThreeStalls() {
  testing::RunSpec spec;
  spec.releases = 10'000;
  spec.deadline_ns = 40'000;
  for (const std::uint64_t first : {2'000u, 5'000u, 8'000u}) {
    for (std::uint64_t k = first; k < first + 50; ++k) spec.overrides[k] = {3'000, 45'000};
  }
  spec.overrides[2'010] = {3'000, 45'500};
  spec.overrides[5'020] = {3'000, 46'000};
  spec.overrides[8'030] = {3'000, 46'500};
  return testing::MakeTrace(spec);
}

TEST(JitterTextRows, WorstListsOneEntryPerStallWithItsLength) {
  const JitterReport r = AnalyzeJitter(ThreeStalls(), nullptr);
  ASSERT_EQ(r.worst.size(), 3u);
  const std::uint64_t want_k[] = {8'030, 5'020, 2'010};
  const std::uint64_t want_first[] = {8'000, 5'000, 2'000};
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(r.worst[i].k, want_k[i]);
    EXPECT_EQ(r.worst[i].burst.first_k, want_first[i]);
    EXPECT_EQ(r.worst[i].burst.last_k, want_first[i] + 49);
    EXPECT_EQ(r.worst[i].burst.cycles, 50u);
    EXPECT_EQ(r.worst[i].burst.releases_skipped, 0u);
    EXPECT_EQ(r.worst[i].burst.duration_ns, 49 * 50'000 + 3'000 + 100 + 45'000);
  }
  const std::string text = FormatJitterText(r);
  EXPECT_NE(text.find("3 worst stalls by response time"), std::string::npos) << text;
  EXPECT_NE(text.find("stall k=8000..8049: 50 cycles, 2.50 ms"), std::string::npos) << text;
  const nlohmann::json j = nlohmann::json::parse(JitterToJson(r).dump());
  ASSERT_EQ(j["worst"].size(), 3u);
  EXPECT_EQ(j["worst"][0]["burst"]["cycles"], 50);
  EXPECT_EQ(j["worst"][0]["burst"]["first_k"], 8'000);
  // Every miss stays a notable cycle of its own, and says which stall it belongs to.
  ASSERT_EQ(j["notable"].size(), 150u);
  EXPECT_EQ(j["notable"][0]["k"], 2'000);
  EXPECT_EQ(j["notable"][0]["burst"]["first_k"], 2'000);
  EXPECT_EQ(j["notable"][149]["burst"]["last_k"], 8'049);
}

TEST(JitterTextRows, ASkippedReleaseContinuesTheStallAndIsCounted) {
  testing::RunSpec spec;
  spec.releases = 2'000;
  spec.deadline_ns = 40'000;
  spec.overrides[1'000] = {3'000, 45'000};
  spec.overrides[1'001] = {3'000, 60'000};  // ends after release 1002: skips it
  spec.overrides[1'003] = {3'000, 45'000};
  const JitterReport r = AnalyzeJitter(testing::MakeTrace(spec), nullptr);
  ASSERT_FALSE(r.worst.empty());
  EXPECT_EQ(r.worst[0].k, 1'001u);
  EXPECT_EQ(r.worst[0].burst.first_k, 1'000u);
  EXPECT_EQ(r.worst[0].burst.last_k, 1'003u);
  EXPECT_EQ(r.worst[0].burst.cycles, 3u);
  EXPECT_EQ(r.worst[0].burst.releases_skipped, 1u);
  EXPECT_NE(FormatJitterText(r).find("stall k=1000..1003: 3 cycles (+1 release skipped)"),
            std::string::npos);
}

TEST(JitterTextRows, CatchUpCyclesAfterAStallAreOneStall) {
  const JitterReport r = AnalyzeJitter(SkewedTrace(), nullptr);
  ASSERT_GE(r.worst.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(r.worst[i].burst.first_k % 1'000, 0u);  // 1000, 3000, 7000: the stalled cycle
    EXPECT_GT(r.worst[i].burst.cycles, 1u);           // and its catch-up cycles
  }
}

TEST(JitterTextRows, ARunLateThroughoutIsOneStallFoundInLinearTime) {
  // Every cycle misses (response 23.1 µs, deadline 20 µs): one stall of 100 000 cycles, each a
  // notable cycle that names it. A stall's figures are summed once, not per notable cycle
  // (that was 10^10 steps here).
  testing::RunSpec spec;
  spec.releases = 100'000;
  spec.deadline_ns = 20'000;
  const JitterReport r = AnalyzeJitter(testing::MakeTrace(spec), nullptr);
  ASSERT_EQ(r.worst.size(), 1u);
  EXPECT_EQ(r.worst[0].burst.cycles, 100'000u);
  ASSERT_EQ(r.notable.size(), 100'000u);
  EXPECT_EQ(r.notable.back().burst.first_k, 0u);
  EXPECT_EQ(r.notable.back().burst.cycles, 100'000u);
}

}  // namespace text_rows_test
}  // namespace
}  // namespace hiltwin::analysis
