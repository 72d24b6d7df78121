#include "hiltwin/kernel_glue/clock.h"

#include <gtest/gtest.h>

namespace hiltwin::kernel_glue {
namespace {

TEST(VirtualClock, SleepJumpsForwardButNeverBack) {
  VirtualClock clock(100);
  clock.SleepUntilNs(250);
  EXPECT_EQ(clock.NowNs(), 250);
  clock.SleepUntilNs(200);  // already past: returns at once, time unchanged
  EXPECT_EQ(clock.NowNs(), 250);
}

TEST(VirtualClock, SpendAndAdvanceAddExactly) {
  VirtualClock clock;
  clock.SpendNs(7);
  clock.AdvanceNs(3);
  clock.AdvanceNs(-5);  // ignored: time never runs back
  EXPECT_EQ(clock.NowNs(), 10);
  EXPECT_TRUE(clock.IsVirtual());
}

TEST(MonotonicClock, AbsoluteSleepReachesDeadline) {
  MonotonicClock clock;
  const TimeNs deadline_ns = clock.NowNs() + 2 * kNsPerMs;
  clock.SleepUntilNs(deadline_ns);
  EXPECT_GE(clock.NowNs(), deadline_ns);  // never early; lateness is not asserted (noisy VM)
  EXPECT_FALSE(clock.IsVirtual());
}

TEST(MonotonicClock, SpendBusyWaitsAtLeastTheDuration) {
  MonotonicClock clock;
  const TimeNs before_ns = clock.NowNs();
  clock.SpendNs(500 * kNsPerUs);
  EXPECT_GE(clock.NowNs() - before_ns, 500 * kNsPerUs);
}

TEST(PeriodFromRate, RoundsToNearestNanosecond) {
  EXPECT_EQ(PeriodNsFromRateHz(4000.0), 250'000);
  EXPECT_EQ(PeriodNsFromRateHz(3.0), 333'333'333);
  EXPECT_EQ(PeriodNsFromRateHz(50'000.0), 20'000);
}

}  // namespace
}  // namespace hiltwin::kernel_glue
