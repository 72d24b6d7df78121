#include "hiltwin/scheduler/overrun_policy.h"

#include <gtest/gtest.h>

namespace hiltwin::scheduler {
namespace {

TEST(OverrunPolicy, CatchUpAlwaysRunsTheNextRelease) {
  EXPECT_EQ(NextReleaseIndex(OverrunPolicy::kCatchUp, 5, 1'000'000'000, 0, 1000), 6U);
}

TEST(OverrunPolicy, SkipJumpsToFirstReleaseNotYetPassed) {
  // t0 = 100, period 1000: release(k) = 100 + 1000k.
  EXPECT_EQ(NextReleaseIndex(OverrunPolicy::kSkip, 5, 5'600, 100, 1000), 6U);   // on time
  EXPECT_EQ(NextReleaseIndex(OverrunPolicy::kSkip, 5, 6'100, 100, 1000), 6U);   // exactly at r6
  EXPECT_EQ(NextReleaseIndex(OverrunPolicy::kSkip, 5, 6'101, 100, 1000), 7U);   // r6 passed
  EXPECT_EQ(NextReleaseIndex(OverrunPolicy::kSkip, 5, 8'600, 100, 1000), 9U);   // r6..r8 passed
}

TEST(OverrunPolicy, ParsesAndPrints) {
  EXPECT_EQ(ParseOverrunPolicy("skip"), OverrunPolicy::kSkip);
  EXPECT_EQ(ParseOverrunPolicy("catch-up"), OverrunPolicy::kCatchUp);
  EXPECT_FALSE(ParseOverrunPolicy("catchup").has_value());
  EXPECT_EQ(ToString(OverrunPolicy::kSkip), "skip");
}

}  // namespace
}  // namespace hiltwin::scheduler
