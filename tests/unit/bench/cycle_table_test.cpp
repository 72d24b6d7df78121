// The table hiltwin_bench_cycle prints (bench/cycle/cycle_table.h): each component's share of
// the whole cycle and its verdict against its target, in the format docs/BENCHMARKS.md quotes;
// and the benchmark's bracketed runs, natively, so a change to what it measures (a component's
// API, the log's columns, the writer's output) breaks here rather than on the next measurement.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "cycle/cycle_table.h"
#include "fakes/test_paths.h"
#include "hiltwin/kernel_glue/process.h"

namespace hiltwin::bench {
namespace {

TEST(CycleTable, ShareIsOfTheWholeCycle) {
  EXPECT_DOUBLE_EQ(SharePct(1321.75, 5287.0), 25.0);
  EXPECT_DOUBLE_EQ(SharePct(5287.0, 5287.0), 100.0);
  // The log writer works on another thread: its share may exceed the loop's whole cycle.
  EXPECT_DOUBLE_EQ(SharePct(4580.0, 2290.0), 200.0);
  EXPECT_THROW(static_cast<void>(SharePct(1.0, 0.0)), std::invalid_argument);
}

TEST(CycleTable, VerdictIsMetUpToTheTarget) {
  EXPECT_STREQ(VerdictOf({"whole", 1800.0, 1800.0}), "met");
  EXPECT_STREQ(VerdictOf({"whole", 1799.9, 1800.0}), "met");
  EXPECT_STREQ(VerdictOf({"whole", 1800.1, 1800.0}), "NOT met");
  EXPECT_STREQ(VerdictOf({"model", 812.0, std::nullopt}), "-");
}

TEST(CycleTable, GroupsTargetsAsTheDocsWriteThem) {
  EXPECT_EQ(Grouped(1800.0), "1,800");
  EXPECT_EQ(Grouped(2500.4), "2,500");
  EXPECT_EQ(Grouped(999.0), "999");
  EXPECT_EQ(Grouped(1234567.0), "1,234,567");
  EXPECT_EQ(Grouped(-1800.0), "-1,800");
}

TEST(CycleTable, PrintsOneLinePerComponentWithShareTargetAndVerdict) {
  const std::vector<CycleComponent> rows = {{"model step", 811.96, std::nullopt},
                                            {"log writer per row", 4580.0, 2500.0},
                                            {"whole cycle", 1600.0, 1800.0}};
  const std::vector<std::string> lines = FormatCycleTable(rows, 1600.0, "instructions");
  ASSERT_EQ(lines.size(), 4U);
  EXPECT_EQ(lines[0], "  component                                      instructions    share"
                      "     target  verdict");
  EXPECT_EQ(lines[1], "  model step                                            812.0    50.7 %"
                      "          -  -");
  EXPECT_EQ(lines[2], "  log writer per row                                   4580.0   286.2 %"
                      "   <= 2,500  NOT met");
  EXPECT_EQ(lines[3], "  whole cycle                                          1600.0   100.0 %"
                      "   <= 1,800  met");
}

kernel_glue::ProcessResult RunBench(const std::vector<std::string>& args) {
  std::vector<std::string> command = {test::BesideTest(HILTWIN_CYCLE_BENCH)};
  command.insert(command.end(), args.begin(), args.end());
  return kernel_glue::RunProcess(command, {.out = kernel_glue::OutputTarget::Discard(),
                                           .err = kernel_glue::OutputTarget::Capture()});
}

TEST(CycleBench, EveryComponentRunsItsBracketedRun) {
  if (std::string(HILTWIN_CYCLE_BENCH).empty()) GTEST_SKIP() << "built without the benchmarks";
  // Each checks its own run: the whole cycle runs every cycle, the log has the 15 columns the
  // table names and the writer's file equals the run's log, QoS does not stop a clean run.
  for (const char* component : {"model", "executive", "exchange", "qos", "histogram", "producer",
                                "writer", "whole"}) {
    const kernel_glue::ProcessResult result = RunBench({"--count", component, "200"});
    EXPECT_TRUE(result.status.Success()) << component << ": " << result.status.Describe() << "\n"
                                         << result.err;
  }
  const kernel_glue::ProcessResult unknown = RunBench({"--count", "nothing", "200"});
  EXPECT_EQ(unknown.status.code, 2);
  EXPECT_NE(unknown.err.find("components: model executive"), std::string::npos) << unknown.err;
}

}  // namespace
}  // namespace hiltwin::bench
