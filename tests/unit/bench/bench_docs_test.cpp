// The cost figures docs/tracing.md and docs/telemetry.md state, and docs/BENCHMARKS.md's loop
// speed table, are the ones the benchmarks printed, as docs/BENCHMARKS.md quotes their output: a re-run whose output is pasted without
// updating the prose (or prose changed without a run) fails here. No figure is written in this
// file; each is read from the quoted output, in the format the benchmark prints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cycle/cycle_table.h"
#include "fakes/test_paths.h"

namespace {

std::string Read(const char* path) {
  std::ifstream in(hiltwin::test::BesideTest(path));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// From the heading that starts with `heading` to the next second-level heading.
std::string Section(const std::string& doc, const std::string& heading) {
  const std::size_t start = doc.find("\n" + heading);
  if (start == std::string::npos) return {};
  const std::size_t end = doc.find("\n## ", start + 1);
  return doc.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

/// Every match of `pattern` (one per line) in `text`.
std::vector<std::smatch> Matches(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern, std::regex::multiline);
  std::vector<std::smatch> out;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it) {
    out.push_back(*it);
  }
  return out;
}

/// 1565.3 -> "1,565", as the prose writes counts.
std::string Count(double figure) {
  std::string digits = std::to_string(std::lround(figure));
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3) {
    digits.insert(static_cast<std::size_t>(i), ",");
  }
  return digits;
}

TEST(BenchDocs, TheTracingCostStatedIsTheBenchmarksOutput) {
  const std::string benchmarks = Read(HILTWIN_BENCHMARKS_DOC);
  const std::string tracing = Read(HILTWIN_TRACING_DOC);
  const std::string section = Section(benchmarks, "## Tracing cost");
  // hiltwin_bench_trace's lines: "  hiltwin:cycle instructions per call (callgrind, ...): idle
  // (peer) 7.0, recording 1565.3, extra 1558.3" and "  hiltwin:cycle tracepoint alone,
  // median (range) of 7 rounds: ..., extra 150.2 ns (120.0 to 190.1) per call (...)".
  const auto instructions = Matches(
      section, R"(^  hiltwin:cycle instructions per call \(callgrind[^)]*\): idle \(peer\) )"
               R"(([0-9.]+), recording ([0-9.]+), extra ([0-9.]+)$)");
  const auto time = Matches(section, R"(^  hiltwin:cycle tracepoint alone, median \(range\) of )"
                                     R"([0-9]+ rounds: .*, extra ([0-9.]+) ns \(([0-9.]+) to )"
                                     R"(([0-9.]+)\) per call)");
  ASSERT_EQ(instructions.size(), 1U) << "the benchmark's output in docs/BENCHMARKS.md";
  ASSERT_EQ(time.size(), 1U) << "the benchmark's output in docs/BENCHMARKS.md";
  const std::string per_event = Count(std::stod(instructions[0][2]));
  const std::string extra_ns = Count(std::stod(time[0][1])) + " ns";
  EXPECT_NE(tracing.find("**" + per_event + " instructions**"), std::string::npos) << per_event;
  EXPECT_NE(tracing.find("**" + extra_ns + "**"), std::string::npos) << extra_ns;
  EXPECT_NE(section.find("**" + per_event + " per recorded event**"), std::string::npos);
  EXPECT_NE(section.find("**" + extra_ns + " extra per recorded event**"), std::string::npos);
  EXPECT_NE(benchmarks.find("**+" + extra_ns + "**"), std::string::npos) << "the summary row";
}

TEST(BenchDocs, TheTelemetryCostStatedIsTheBenchmarksOutput) {
  const std::string benchmarks = Read(HILTWIN_BENCHMARKS_DOC);
  const std::string telemetry = Read(HILTWIN_TELEMETRY_DOC);
  const std::string section = Section(benchmarks, "## Telemetry");
  // hiltwin_bench_telemetry's instruction lines: "  udp: 922.7, difference +77.7".
  const auto lines = Matches(section, R"(^  (udp|dds|web): ([0-9.]+), difference \+([0-9.]+)$)");
  ASSERT_EQ(lines.size(), 3U) << "the benchmark's output in docs/BENCHMARKS.md";
  // The docs state one figure for the three sinks: their median, each within one of it.
  std::vector<double> per_sink;
  for (const auto& line : lines) per_sink.push_back(std::stod(line[3]));
  std::sort(per_sink.begin(), per_sink.end());
  const double median = per_sink[1];
  for (const double figure : per_sink) EXPECT_LE(std::fabs(figure - median), 1.0) << figure;
  const std::string added = Count(median);
  EXPECT_NE(telemetry.find("**" + added + " instructions per cycle**"), std::string::npos)
      << added;
  EXPECT_NE(section.find("**" + added + " instructions**"), std::string::npos) << added;
  EXPECT_NE(benchmarks.find("**+" + added + " instructions**"), std::string::npos)
      << "the summary row";
}

TEST(BenchDocs, TheLoopSpeedTableIsTheBenchmarksOutput) {
  const std::string benchmarks = Read(HILTWIN_BENCHMARKS_DOC);
  const std::string section = Section(benchmarks, "## Loop speed (issue 36)");
  // hiltwin_bench_cycle's table lines, e.g. "  whole virtual-clock cycle (no log)    5287.4
  // 100.0 %   <= 1,800  NOT met": name, instructions per cycle, share, target, verdict.
  const auto lines = Matches(section, R"(^  (\S.*?) +([0-9]+\.[0-9]) +([0-9]+\.[0-9]) % +)"
                                      R"((<= ([0-9,]+)|-)  (met|NOT met|-)$)");
  ASSERT_EQ(lines.size(), 8U) << "the benchmark's table in docs/BENCHMARKS.md";
  ASSERT_EQ(lines.back()[1].str().rfind("whole virtual-clock cycle", 0), 0U) << "last: whole";
  const double whole = std::stod(lines.back()[2]);
  for (const auto& line : lines) {
    const std::string name = line[1];
    const double figure = std::stod(line[2]);
    // The share and the verdict are the table's arithmetic of the printed figure: an edited
    // figure without its share, or a share from another run, fails here.
    EXPECT_NEAR(std::stod(line[3]), hiltwin::bench::SharePct(figure, whole), 0.06) << name;
    std::optional<double> target;
    if (line[5].matched) {
      std::string digits = line[5];
      digits.erase(std::remove(digits.begin(), digits.end(), ','), digits.end());
      target = std::stod(digits);
    }
    EXPECT_EQ(line[6].str(), hiltwin::bench::VerdictOf({name, figure, target})) << name;
    // The section's table states each figure in its first ("after") column as the prose writes
    // counts.
    EXPECT_NE(section.find("| " + name + " | **" + Count(figure) + "** |"), std::string::npos)
        << name << ": " << Count(figure);
  }
  EXPECT_NE(benchmarks.find("**" + Count(whole) + " instructions per cycle**"), std::string::npos)
      << "the summary row: " << Count(whole);
}

}  // namespace
