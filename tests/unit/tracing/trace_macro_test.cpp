// HILTWIN_TRACE as every module sees it: linked against hiltwin::tracing, so LTTng is compiled
// in exactly when the build option HILTWIN_WITH_LTTNG is on.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "fakes/alloc_counter.h"
#include "hiltwin/tracing/trace.h"

namespace hiltwin::tracing {
namespace {

int g_evaluations = 0;

std::uint64_t Counted(std::uint64_t value) {
  ++g_evaluations;
  return value;
}

bool LttngUstIsMapped() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    if (line.find("liblttng-ust.so") != std::string::npos) return true;
  }
  return false;
}

TEST(TraceMacro, CompiledInFollowsTheBuildOption) {
#if defined(HILTWIN_WITH_LTTNG)
  EXPECT_TRUE(kTracingCompiledIn);
  EXPECT_TRUE(LttngUstIsMapped()) << "the hiltwin provider should pull in liblttng-ust";
#else
  EXPECT_FALSE(kTracingCompiledIn);
  EXPECT_FALSE(LttngUstIsMapped());
#endif
}

TEST(TraceMacro, IsOneStatementUsableWithoutBraces) {
  bool flag = g_evaluations >= 0;
  int branch = 0;
  if (flag)
    HILTWIN_TRACE(io_error, std::uint64_t{1}, std::uint8_t{0});
  else
    HILTWIN_TRACE(io_error, std::uint64_t{2}, std::uint8_t{1});
  branch = flag ? 1 : 2;
  EXPECT_EQ(branch, 1);
}

TEST(TraceMacro, EvaluatesArgumentsAtMostOnceAndAllocatesNothing) {
  g_evaluations = 0;
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount counter;
    for (std::uint64_t k = 0; k < 100; ++k) {
      HILTWIN_TRACE(cycle, Counted(k), std::int64_t{1}, std::int64_t{2}, std::int64_t{3},
                    std::int64_t{4}, std::int64_t{0}, std::uint32_t{0}, std::uint8_t{0},
                    std::uint8_t{1});
      HILTWIN_TRACE(deadline_miss, k, std::int64_t{5});
    }
    allocations = counter.count();
  }
  // Without a recording session the tracepoint is off and its arguments are not evaluated;
  // if another process happens to record hiltwin:*, each call evaluates them once.
  EXPECT_LE(g_evaluations, 100);
  EXPECT_EQ(allocations, 0U);
}

}  // namespace
}  // namespace hiltwin::tracing
