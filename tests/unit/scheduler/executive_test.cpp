#include "hiltwin/scheduler/executive.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::scheduler {
namespace {

using kernel_glue::VirtualClock;

/// 10 kHz: a legal period with round numbers for hand-made patterns.
constexpr TimeNs kP = 100'000;

/// A step that spends injected compute time on the virtual clock: pattern[k] ns in cycle k,
/// `default_ns` otherwise. Records the cycles it ran.
class InjectedTask final : public CyclicTask {
 public:
  InjectedTask(kernel_glue::Clock& clock, std::map<std::uint64_t, TimeNs> pattern,
               TimeNs default_ns = 0)
      : clock_(clock), pattern_(std::move(pattern)), default_ns_(default_ns) {}
  CycleAction Step(const CycleContext& context) noexcept override {
    ran.push_back(context.cycle);
    const auto it = pattern_.find(context.cycle);
    clock_.SpendNs(it == pattern_.end() ? default_ns_ : it->second);
    return context.cycle == stop_at ? CycleAction::kStop : CycleAction::kContinue;
  }
  std::vector<std::uint64_t> ran;
  std::uint64_t stop_at = ~std::uint64_t{0};

 private:
  kernel_glue::Clock& clock_;
  std::map<std::uint64_t, TimeNs> pattern_;
  TimeNs default_ns_;
};

class RecordingObserver final : public CycleObserver {
 public:
  CycleAction OnCycle(const TimingSample& sample) noexcept override {
    samples.push_back(sample);
    return sample.cycle == stop_at ? CycleAction::kStop : CycleAction::kContinue;
  }
  std::vector<TimingSample> samples;
  std::uint64_t stop_at = ~std::uint64_t{0};
};

/// Counts misses the way the QoS ledger does (a missed cycle plus each skipped release),
/// without allocating.
class MissCounter final : public CycleObserver {
 public:
  CycleAction OnCycle(const TimingSample& s) noexcept override {
    const std::uint64_t misses = (s.missed ? 1U : 0U) + s.releases_skipped;
    total += misses;
    run = s.missed ? run + misses : 0;
    longest = std::max(longest, run);
    return CycleAction::kContinue;
  }
  std::uint64_t total = 0;
  std::uint64_t run = 0;
  std::uint64_t longest = 0;
};

/// Checks the release grid without storing 10^6 samples.
class GridObserver final : public CycleObserver {
 public:
  GridObserver(const Executive& executive, TimeNs period_ns)
      : executive_(executive), period_ns_(period_ns) {}
  CycleAction OnCycle(const TimingSample& s) noexcept override {
    const TimeNs expected = executive_.t0_ns() + static_cast<TimeNs>(s.cycle) * period_ns_;
    if (s.release_ns != expected || s.wake_ns != s.release_ns || s.cycle != next_cycle_) ++errors;
    next_cycle_ = s.cycle + 1;
    last_release_ns = s.release_ns;
    return CycleAction::kContinue;
  }
  std::uint64_t errors = 0;
  TimeNs last_release_ns = 0;

 private:
  const Executive& executive_;
  TimeNs period_ns_;
  std::uint64_t next_cycle_ = 0;
};

ExecutiveConfig Config(TimeNs period_ns, std::uint64_t cycles,
                       OverrunPolicy policy = OverrunPolicy::kCatchUp) {
  ExecutiveConfig c;
  c.period_ns = period_ns;
  c.max_cycles = cycles;
  c.overrun_policy = policy;
  return c;
}

TEST(Executive, ReleaseTimesExactOverAMillionVirtualCyclesNoDrift) {
  // 3 kHz: the period (333333 ns) does not divide a second, so any accumulation
  // from "now" or rounding would show as drift.
  VirtualClock clock(12'345);
  const TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(3000.0);
  Executive executive(clock, Config(period_ns, 1'000'000));
  GridObserver grid(executive, period_ns);
  executive.AddObserver(grid);
  MissCounter misses;
  executive.AddObserver(misses);
  InjectedTask task(clock, {}, 1'000);  // 1 µs of compute per cycle
  EXPECT_EQ(executive.Run(task), StopCause::kCycleLimit);
  EXPECT_EQ(grid.errors, 0U);
  EXPECT_EQ(executive.t0_ns(), 12'345 + period_ns);
  EXPECT_EQ(grid.last_release_ns, executive.t0_ns() + 999'999 * period_ns);
  EXPECT_EQ(executive.stats().cycles_run, 1'000'000U);
  EXPECT_EQ(misses.total, 0U);
  EXPECT_EQ(executive.stats().compute.Summary().max_ns, 1'000);
  EXPECT_EQ(executive.stats().period_jitter.Summary().max_ns, 0);
}

TEST(Executive, MissDetectionWithShorterDeadline) {
  VirtualClock clock;
  ExecutiveConfig config = Config(kP, 10);
  config.deadline_ns = 60000;
  Executive executive(clock, config);
  RecordingObserver obs;
  executive.AddObserver(obs);
  MissCounter misses;
  executive.AddObserver(misses);
  // 60 µs is exactly at the deadline (met), 1 ns more misses, 99.999 µs misses but ends
  // before the next release.
  InjectedTask task(clock, {{2, 60000}, {3, 60001}, {7, 99999}});
  executive.Run(task);
  ASSERT_EQ(obs.samples.size(), 10U);
  std::vector<std::uint64_t> missed;
  for (const auto& s : obs.samples) {
    if (s.missed) missed.push_back(s.cycle);
  }
  EXPECT_EQ(missed, (std::vector<std::uint64_t>{3, 7}));
  EXPECT_EQ(misses.total, 2U);
  EXPECT_EQ(misses.longest, 1U);
  EXPECT_EQ(executive.stats().response.Summary().max_ns, 99999);
}

TEST(Executive, CatchUpRunsEveryReleaseLateAndJudgesEachByItsOwnDeadline) {
  VirtualClock clock;
  Executive executive(clock, Config(kP, 12, OverrunPolicy::kCatchUp));
  RecordingObserver obs;
  executive.AddObserver(obs);
  MissCounter misses;
  executive.AddObserver(misses);
  InjectedTask task(clock, {{5, 350000}});  // ends at r5 + 3.5 periods = r8 + half a period
  executive.Run(task);
  ASSERT_EQ(task.ran.size(), 12U);  // nothing skipped
  for (std::uint64_t k = 0; k < 12; ++k) EXPECT_EQ(task.ran[k], k);
  std::vector<std::uint64_t> missed;
  for (const auto& s : obs.samples) {
    if (s.missed) missed.push_back(s.cycle);
    EXPECT_EQ(s.releases_skipped, 0U);
  }
  // r6 and r7 start at r5 + 3.5P, after their deadlines (r6 + P, r7 + P); r8 meets r8 + P.
  EXPECT_EQ(missed, (std::vector<std::uint64_t>{5, 6, 7}));
  EXPECT_EQ(obs.samples[6].start_ns, obs.samples[5].end_ns);  // back to back
  EXPECT_EQ(obs.samples[6].wake_ns - obs.samples[6].release_ns, 250000);  // started behind
  // r6, r7 and r8 started behind because the model overran, not because the OS woke late:
  // the wake-latency statistics hold only the 9 cycles whose release found the loop asleep.
  EXPECT_EQ(executive.stats().wake_latency.Summary().count, 9U);
  EXPECT_EQ(executive.stats().wake_latency.Summary().max_ns, 0);
  EXPECT_EQ(executive.stats().response.Summary().max_ns, 350000);  // r5 itself
  EXPECT_EQ(misses.total, 3U);
  EXPECT_EQ(misses.longest, 3U);
  EXPECT_EQ(executive.stats().releases_skipped, 0U);
}

/// A virtual clock that counts the sleeps the executive enters, and those for a release that
/// had already passed (a system call for nothing on the real clock).
class SleepCountingClock final : public kernel_glue::Clock {
 public:
  [[nodiscard]] TimeNs NowNs() const noexcept override { return inner_.NowNs(); }
  void SleepUntilNs(TimeNs deadline_ns) noexcept override {
    ++sleeps;
    if (deadline_ns < inner_.NowNs()) ++sleeps_for_passed_releases;
    inner_.SleepUntilNs(deadline_ns);
  }
  void SpendNs(TimeNs duration_ns) noexcept override { inner_.SpendNs(duration_ns); }
  [[nodiscard]] bool IsVirtual() const noexcept override { return true; }
  int sleeps = 0;
  int sleeps_for_passed_releases = 0;

 private:
  VirtualClock inner_;
};

/// Which cycles slept: the clock's sleep count as each cycle ends.
class SleepObserver final : public CycleObserver {
 public:
  explicit SleepObserver(const SleepCountingClock& clock) : clock_(clock) {}
  CycleAction OnCycle(const TimingSample& sample) noexcept override {
    if (clock_.sleeps != seen_) slept.push_back(sample.cycle);
    seen_ = clock_.sleeps;
    return CycleAction::kContinue;
  }
  std::vector<std::uint64_t> slept;

 private:
  const SleepCountingClock& clock_;
  int seen_ = 0;
};

TEST(Executive, CatchUpCyclesEnterNoSleepFutureReleasesStillDo) {
  SleepCountingClock clock;
  Executive executive(clock, Config(kP, 30, OverrunPolicy::kCatchUp));
  SleepObserver observer(clock);
  executive.AddObserver(observer);
  RecordingObserver samples;
  executive.AddObserver(samples);
  // A stall of 5.5 periods in cycle 10: it ends after the releases of cycles 11 to 15.
  InjectedTask task(clock, {{10, 550'000}});
  EXPECT_EQ(executive.Run(task), StopCause::kCycleLimit);
  std::vector<std::uint64_t> expected;
  for (std::uint64_t k = 0; k < 30; ++k) {
    if (k < 11 || k > 15) expected.push_back(k);
  }
  EXPECT_EQ(observer.slept, expected);  // the five catch-up cycles slept not at all
  EXPECT_EQ(clock.sleeps_for_passed_releases, 0);
  EXPECT_EQ(clock.sleeps, 25);
  for (std::uint64_t k = 11; k <= 15; ++k) {  // each started the moment the one before ended
    EXPECT_EQ(samples.samples[k].wake_ns, samples.samples[k - 1].end_ns) << k;
    EXPECT_EQ(samples.samples[k].start_ns, samples.samples[k].wake_ns) << k;
  }
  EXPECT_EQ(samples.samples[16].wake_ns, samples.samples[16].release_ns);  // slept to it
  // Wake-up latency still holds only the cycles whose release found the loop asleep.
  EXPECT_EQ(executive.stats().wake_latency.Summary().count, 25U);
  EXPECT_EQ(executive.stats().response.Summary().max_ns, 550'000);
}

TEST(Executive, SkipReanchorsAndCountsSkippedReleasesAsMisses) {
  VirtualClock clock;
  Executive executive(clock, Config(kP, 12, OverrunPolicy::kSkip));
  RecordingObserver obs;
  executive.AddObserver(obs);
  MissCounter misses;
  executive.AddObserver(misses);
  InjectedTask task(clock, {{5, 350000}});
  executive.Run(task);
  EXPECT_EQ(task.ran, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5, 9, 10, 11}));
  ASSERT_EQ(obs.samples.size(), 9U);
  EXPECT_TRUE(obs.samples[5].missed);
  EXPECT_EQ(obs.samples[5].releases_skipped, 3U);  // r6, r7, r8 passed while busy
  EXPECT_FALSE(obs.samples[6].missed);
  EXPECT_EQ(obs.samples[6].release_ns, executive.t0_ns() + 9 * kP);  // phase kept
  EXPECT_EQ(obs.samples[6].wake_ns, obs.samples[6].release_ns);
  EXPECT_EQ(misses.total, 4U);
  EXPECT_EQ(misses.longest, 4U);
  EXPECT_EQ(executive.stats().releases, 12U);
  EXPECT_EQ(executive.stats().cycles_run, 9U);
}

TEST(Executive, SkipNeverRunsPastThePlannedCycles) {
  VirtualClock clock;
  Executive executive(clock, Config(kP, 8, OverrunPolicy::kSkip));
  MissCounter misses;
  executive.AddObserver(misses);
  InjectedTask task(clock, {{6, 1'000'000}});
  executive.Run(task);
  EXPECT_EQ(task.ran.back(), 6U);
  EXPECT_EQ(executive.stats().releases, 8U);  // r7 skipped, nothing beyond the plan
  EXPECT_EQ(misses.total, 2U);
}

TEST(Executive, StopsOnTaskObserverAndStopFlag) {
  {
    VirtualClock clock;
    Executive executive(clock, Config(kP, 100));
    InjectedTask task(clock, {});
    task.stop_at = 4;
    EXPECT_EQ(executive.Run(task), StopCause::kTaskStopped);
    EXPECT_EQ(executive.stats().cycles_run, 5U);  // the stopping cycle is complete and counted
  }
  {
    VirtualClock clock;
    Executive executive(clock, Config(kP, 100));
    RecordingObserver obs;
    obs.stop_at = 7;
    executive.AddObserver(obs);
    InjectedTask task(clock, {});
    EXPECT_EQ(executive.Run(task), StopCause::kObserverStopped);
    EXPECT_EQ(executive.stats().cycles_run, 8U);
  }
  {
    VirtualClock clock;
    Executive executive(clock, Config(kP, 0));  // unbounded: only the flag ends it
    static int calls = 0;
    calls = 0;
    executive.SetStopCheck([]() noexcept { return ++calls > 20; });
    InjectedTask task(clock, {});
    EXPECT_EQ(executive.Run(task), StopCause::kStopRequested);
    EXPECT_EQ(executive.stats().cycles_run, 20U);
  }
}

TEST(Executive, RecentSamplesKeepsTheLatestInOrder) {
  VirtualClock clock;
  ExecutiveConfig config = Config(kP, 10);
  config.recent_samples_capacity = 4;
  Executive executive(clock, config);
  InjectedTask task(clock, {});
  executive.Run(task);
  const auto recent = executive.RecentSamples();
  ASSERT_EQ(recent.size(), 4U);
  EXPECT_EQ(recent.front().cycle, 6U);
  EXPECT_EQ(recent.back().cycle, 9U);
}

TEST(Executive, NoHeapAllocationInsideTheLoop) {
  VirtualClock clock;
  Executive executive(clock, Config(kP, 50'000));
  MissCounter misses;  // observers that allocate would be the caller's fault; this one does not
  executive.AddObserver(misses);
  class QuietTask final : public CyclicTask {
   public:
    explicit QuietTask(kernel_glue::Clock& c) : clock_(c) {}
    CycleAction Step(const CycleContext& ctx) noexcept override {
      clock_.SpendNs(ctx.cycle % 97 == 0 ? 150000 : 1000);  // some misses: the miss path too
      return CycleAction::kContinue;
    }
   private:
    kernel_glue::Clock& clock_;
  } task(clock);
  std::uint64_t allocations = 0;
  {
    test::ScopedAllocationCount count;
    executive.Run(task);
    allocations = count.count();
  }
  EXPECT_EQ(allocations, 0U) << "malloc counted: " << test::MallocIsCounted();
  EXPECT_GT(misses.total, 0U);  // the miss path really ran
}

TEST(Executive, IoTimeIsReportedApartFromComputeTime) {
  // A step of 30 µs of which the task says 12 µs were I/O: compute is the other 18 µs.
  class IoTask final : public CyclicTask {
   public:
    explicit IoTask(kernel_glue::Clock& c) : clock_(c) {}
    CycleAction Step(const CycleContext& ctx) noexcept override {
      SetIoNsOfLastStep(12'000 + static_cast<TimeNs>(ctx.cycle));
      clock_.SpendNs(30'000);
      return CycleAction::kContinue;
    }
   private:
    kernel_glue::Clock& clock_;
  };
  VirtualClock clock;
  Executive executive(clock, Config(kP, 5));
  RecordingObserver obs;
  executive.AddObserver(obs);
  IoTask task(clock);
  executive.Run(task);
  ASSERT_EQ(obs.samples.size(), 5U);
  EXPECT_EQ(obs.samples[3].io_ns, 12'003);
  EXPECT_EQ(executive.stats().io.Summary().min_ns, 12'000);
  EXPECT_EQ(executive.stats().io.Summary().max_ns, 12'004);
  EXPECT_EQ(executive.stats().compute.Summary().max_ns, 18'000);
  EXPECT_EQ(executive.stats().compute.Summary().min_ns, 30'000 - 12'004);
  EXPECT_EQ(executive.stats().response.Summary().max_ns, 30'000);
}

TEST(Executive, AllocationCounterCanFail) {
  // Guards the guard: the counter must see an allocation when there is one.
  test::ScopedAllocationCount count;
  auto* leak_free = new std::vector<int>(100);
  delete leak_free;
  EXPECT_GE(count.count(), 1U);
}

TEST(Executive, RejectsBadConfiguration) {
  VirtualClock clock;
  EXPECT_THROW(Executive(clock, Config(10, 1)), std::invalid_argument);  // 100 MHz
  ExecutiveConfig late = Config(kP, 1);
  late.deadline_ns = kP + 1;
  EXPECT_THROW(Executive(clock, late), std::invalid_argument);
  EXPECT_THROW(ValidateRateHz(0.0), std::invalid_argument);
  EXPECT_THROW(ValidateRateHz(50'001.0), std::invalid_argument);
  EXPECT_THROW(ValidateRateHz(std::nan("")), std::invalid_argument);
  EXPECT_NO_THROW(ValidateRateHz(1.0));
  EXPECT_NO_THROW(ValidateRateHz(50'000.0));
  Executive ok(clock, Config(kP, 1));
  RecordingObserver obs;
  for (std::size_t i = 0; i < Executive::kMaxObservers; ++i) ok.AddObserver(obs);
  EXPECT_THROW(ok.AddObserver(obs), std::length_error);
}

}  // namespace
}  // namespace hiltwin::scheduler
