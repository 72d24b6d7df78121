// The figures the benchmarks print: the spread over rounds (bench_stats.h) and the instruction
// counts (callgrind_count.h), down to one counted run of a probe under valgrind.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "fakes/test_paths.h"

namespace hiltwin::bench {
namespace {

TEST(BenchSpread, IsTheMedianAndTheRange) {
  const Spread spread = SpreadOf({112.0, 98.5, 140.25, 101.0, 130.0});
  EXPECT_DOUBLE_EQ(spread.median, 112.0);
  EXPECT_DOUBLE_EQ(spread.min, 98.5);
  EXPECT_DOUBLE_EQ(spread.max, 140.25);
  EXPECT_EQ(FormatSpread(spread, "ns"), "112.0 ns (98.5 to 140.2)");
  EXPECT_EQ(FormatSpread(SpreadOf({7.0}), "instructions", 0), "7 instructions (7 to 7)");
  EXPECT_EQ(FormatSpread(SpreadOf({-35.5, 27.0, 77.7}), "ns"), "27.0 ns (-35.5 to 77.7)");
}

TEST(BenchSpread, OfNothingIsAnError) {
  EXPECT_THROW(static_cast<void>(SpreadOf({})), std::invalid_argument);
}

// The head and the tail of a file callgrind 3.19 wrote with --collect-atstart=no.
constexpr const char* kCallgrindFile =
    "# callgrind format\nversion: 1\ncreator: callgrind-3.19.0\npid: 25588\n"
    "cmd:  ./probe 12000\npart: 1\n\ndesc: I1 cache: \ndesc: Timerange: Basic block 0 - 420\n"
    "\npositions: line\nevents: Ir\nsummary: 96136556\n\n\nob=(1) /usr/lib/libc.so.6\n"
    "fl=(1) ???\nfn=(1) clock_gettime@@GLIBC_2.17\n0 16\n\ntotals: 96136556\n";

TEST(CallgrindInstructions, ReadsTheTotalsIrColumn) {
  EXPECT_EQ(CallgrindInstructions(kCallgrindFile), 96'136'556U);
  // Several events: Ir's own column, wherever it stands.
  EXPECT_EQ(CallgrindInstructions("events: Dr Ir Dw\nfn=(1) f\n0 1 2 3\ntotals: 40 30 20\n"), 30U);
  // An older callgrind writes summary: only.
  EXPECT_EQ(CallgrindInstructions("events: Ir\nsummary: 1234\n"), 1234U);
}

TEST(CallgrindInstructions, RefusesAFileWithoutAReadableTotal) {
  EXPECT_EQ(CallgrindInstructions(""), std::nullopt);
  EXPECT_EQ(CallgrindInstructions("events: Ir\nfn=(1) f\n0 5\n"), std::nullopt);  // cut short
  EXPECT_EQ(CallgrindInstructions("events: Dr\ntotals: 5\n"), std::nullopt);       // no Ir
  EXPECT_EQ(CallgrindInstructions("events: Dr Ir\ntotals: 5\n"), std::nullopt);    // no column
  EXPECT_EQ(CallgrindInstructions("events: Ir\ntotals: -5\n"), std::nullopt);
  EXPECT_EQ(CallgrindInstructions("events: Ir\ntotals: 12x\n"), std::nullopt);
  EXPECT_EQ(CallgrindInstructions("events: Ir\ntotals: 99999999999999999999\n"), std::nullopt);
}

TEST(InstructionsPerItem, CancelsWhatBothRunsShare) {
  // 5 per item, and 10,000 of set-up in both runs.
  EXPECT_DOUBLE_EQ(InstructionsPerItem(2'000, 10'000 + 2'000 * 5, 12'000, 10'000 + 12'000 * 5),
                   5.0);
  EXPECT_THROW(static_cast<void>(InstructionsPerItem(12'000, 1, 2'000, 2)),
               std::invalid_argument);
}

/// Why callgrind cannot count the probe here; empty when it can.
std::string WhyNoCallgrind() {
#if defined(HILTWIN_UNDER_SANITIZER)
  return "a sanitizer's runtime and valgrind do not run in one process";
#elif defined(HILTWIN_UNDER_EMULATOR)
  return "the probe is built for another architecture (run under an emulator)";
#else
  const bool found = kernel_glue::RunProcess({"sh", "-c", "command -v valgrind"},
                                             {.out = kernel_glue::OutputTarget::Discard(),
                                              .err = kernel_glue::OutputTarget::Discard()})
                         .status.Success();
  return found ? "" : "valgrind is not installed (apt-get install valgrind)";
#endif
}

TEST(CountInstructions, CountsTheBracketOfTheCallingThreadOnly) {
  if (const std::string why = WhyNoCallgrind(); !why.empty()) GTEST_SKIP() << why;
  const std::string probe = test::BesideTest(HILTWIN_COUNT_PROBE);
  const std::uint64_t few = CountInstructions({probe, "100000"});
  const std::uint64_t many = CountInstructions({probe, "300000"});
  const double per_iteration = InstructionsPerItem(100'000, few, 300'000, many);
  // An empty loop is an increment, a compare and a branch (maybe unrolled): a few instructions.
  EXPECT_GE(per_iteration, 1.0);
  EXPECT_LE(per_iteration, 5.0);
  // The same loop while another thread spins outside the bracket: the spinner is not
  // counted, since the count is per thread, which lets a benchmark count its loop thread
  // alone. A counted spinner would add at least one turn of its loop (1000 iterations, some
  // 3000 instructions). The bracketed thread's own count moves a little: its yield's path in
  // the C library and the kernel differs when another thread is runnable (under 100 on a
  // busy machine, 838 on an idle one).
  constexpr std::uint64_t kOwnPathSlack = 2'000;
  const std::uint64_t spinning = CountInstructions({probe, "300000", "spin"});
  EXPECT_LT(spinning > many ? spinning - many : many - spinning, kOwnPathSlack)
      << spinning << " " << many;
}

TEST(CountInstructions, SaysSoWhenNothingWasBracketed) {
  if (const std::string why = WhyNoCallgrind(); !why.empty()) GTEST_SKIP() << why;
  const std::string probe = test::BesideTest(HILTWIN_COUNT_PROBE);
  try {
    static_cast<void>(CountInstructions({probe, "1000", "none"}));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("counted nothing"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hiltwin::bench
