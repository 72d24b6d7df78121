#include "hiltwin/kernel_glue/clock.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <thread>

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

std::atomic<int> g_sleep_interruptions{0};
void CountSleepInterruption(int /*signal*/) { g_sleep_interruptions.fetch_add(1); }

TEST(MonotonicClock, AbsoluteSleepResumesAfterASignalInterruptsIt) {
  // A handler without SA_RESTART makes clock_nanosleep return EINTR; the sleep must resume
  // towards the same absolute deadline instead of returning early.
  struct sigaction action {};
  action.sa_handler = CountSleepInterruption;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  struct sigaction previous {};
  ASSERT_EQ(sigaction(SIGUSR1, &action, &previous), 0);
  g_sleep_interruptions = 0;

  MonotonicClock clock;
  const TimeNs deadline_ns = clock.NowNs() + 200 * kNsPerMs;
  std::atomic<bool> asleep{false};
  TimeNs woke_ns = 0;
  std::thread sleeper([&] {
    asleep = true;
    clock.SleepUntilNs(deadline_ns);
    woke_ns = clock.NowNs();
  });
  while (!asleep) std::this_thread::yield();
  for (int i = 0; i < 5; ++i) {  // several interruptions, all well before the deadline
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    pthread_kill(sleeper.native_handle(), SIGUSR1);
  }
  sleeper.join();
  sigaction(SIGUSR1, &previous, nullptr);
  EXPECT_GE(g_sleep_interruptions.load(), 1);
  EXPECT_GE(woke_ns, deadline_ns);
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
