// HILTWIN_TRACE with LTTng compiled out (HILTWIN_WITH_LTTNG absent): this executable does not
// link hiltwin::tracing or LTTng, so if the disabled twin emitted any code or symbol it would
// not link.
#if defined(HILTWIN_WITH_LTTNG)
#error "this translation unit must be built without HILTWIN_WITH_LTTNG"
#endif

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "hiltwin/tracing/trace.h"

namespace {

int g_evaluations = 0;

std::uint64_t Counted(std::uint64_t value) {
  ++g_evaluations;
  return value;
}

TEST(TraceMacroDisabled, ReportsNotCompiledIn) {
  EXPECT_FALSE(hiltwin::tracing::kTracingCompiledIn);
}

TEST(TraceMacroDisabled, NeverEvaluatesItsArguments) {
  g_evaluations = 0;
  for (std::uint64_t k = 0; k < 10; ++k) {
    HILTWIN_TRACE(cycle, Counted(k), 1, 2, 3, 4, 0, 0);
    HILTWIN_TRACE(qos, Counted(k), 5, 0);
    HILTWIN_TRACE(no_such_event_is_fine_when_disabled, Counted(k));
  }
  EXPECT_EQ(g_evaluations, 0);
}

TEST(TraceMacroDisabled, IsOneStatementUsableWithoutBraces) {
  int branch = 0;
  if (g_evaluations == 0)
    HILTWIN_TRACE(mark, 1, 2);
  else
    HILTWIN_TRACE(mark, 3, 4);
  branch = 1;
  EXPECT_EQ(branch, 1);
}

TEST(TraceMacroDisabled, LoadsNoLttngLibrary) {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    EXPECT_EQ(line.find("liblttng-ust"), std::string::npos) << line;
  }
}

}  // namespace
