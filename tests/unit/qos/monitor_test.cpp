// Hand-made QoS cases at window boundaries, the grace period, the abort policy, the miss-ratio
// plan, the live distance to failure, and the no-allocation guarantee of Record().

#include "hiltwin/qos/monitor.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "fakes/alloc_counter.h"

namespace hiltwin::qos {
namespace {

QosConfig Config(std::vector<RuleSpec> rules, ViolationPolicy policy = ViolationPolicy::kFlag,
                 std::uint64_t planned = 0, std::uint64_t grace = 0) {
  return QosConfig{.rules = std::move(rules),
                   .grace_cycles = grace,
                   .policy = policy,
                   .planned_cycles = planned};
}

// Records cycles 0..length-1, missing exactly those listed; returns the first cycle at which
// Record() asked to stop (or length).
std::uint64_t Feed(QosMonitor& monitor, std::uint64_t length,
                   std::initializer_list<std::uint64_t> misses) {
  for (std::uint64_t cycle = 0; cycle < length; ++cycle) {
    bool missed = false;
    for (std::uint64_t m : misses) missed = missed || m == cycle;
    if (monitor.Record(cycle, missed)) return cycle;
  }
  return length;
}

TEST(QosWindow, TwoMissesExactlyKApartNeverShareAWindow) {
  QosMonitor monitor(Config({MakeMkRule(9, 10)}));
  Feed(monitor, 40, {0, 10, 20, 30});
  const RuleStatus& rule = monitor.rules()[0];
  EXPECT_FALSE(rule.violated);
  EXPECT_EQ(rule.violations, 0U);
  EXPECT_EQ(rule.min_met_in_window, 9U);
  EXPECT_EQ(monitor.verdict(), Verdict::kPass);
}

TEST(QosWindow, TwoMissesKMinusOneApartViolateAtTheSecond) {
  QosMonitor monitor(Config({MakeMkRule(9, 10)}));
  Feed(monitor, 40, {5, 14});
  const RuleStatus& rule = monitor.rules()[0];
  EXPECT_TRUE(rule.violated);
  EXPECT_EQ(rule.violations, 1U);  // only the window [5, 14] holds both
  EXPECT_EQ(rule.first_violation_cycle, std::optional<std::uint64_t>(14));
  EXPECT_EQ(rule.min_met_in_window, 8U);
  EXPECT_EQ(rule.max_misses_in_window, 2U);
  EXPECT_EQ(monitor.verdict(), Verdict::kFlagged);
}

TEST(QosWindow, ABurstOfThreeBreaksTenWindows) {
  // docs/qos.md: every window ending at 21..30 holds at least two of the misses 20, 21, 22.
  QosMonitor monitor(Config({MakeMkRule(9, 10)}));
  Feed(monitor, 60, {20, 21, 22});
  EXPECT_EQ(monitor.rules()[0].violations, 10U);
  EXPECT_EQ(monitor.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(21));
  EXPECT_EQ(monitor.rules()[0].min_met_in_window, 7U);
}

TEST(QosWindow, HistoryBeforeTheFirstCycleCountsAsMet) {
  // (1,2): the first cycle missed is fine (its window includes a met pre-history cycle); two
  // misses in a row at the start violate at cycle 1, not earlier.
  QosMonitor one(Config({MakeMkRule(1, 2)}));
  Feed(one, 5, {0});
  EXPECT_FALSE(one.rules()[0].violated);
  QosMonitor two(Config({MakeMkRule(1, 2)}));
  Feed(two, 5, {0, 1});
  EXPECT_EQ(two.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(1));
  EXPECT_EQ(two.rules()[0].violations, 1U);
}

TEST(QosWindow, KEqualsOneAndMEqualsKRejectEveryMiss) {
  QosMonitor k1(Config({MakeMkRule(1, 1)}));
  Feed(k1, 20, {3, 4, 17});
  EXPECT_EQ(k1.rules()[0].violations, 3U);
  EXPECT_EQ(k1.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(3));
  EXPECT_EQ(k1.rules()[0].min_met_in_window, 0U);

  QosMonitor hard(Config({MakeMkRule(5, 5)}));
  Feed(hard, 20, {7});
  EXPECT_EQ(hard.rules()[0].violations, 5U);  // windows ending at 7..11 all hold the miss
  EXPECT_EQ(hard.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(7));
}

TEST(QosWindow, WindowOfAThousandCountsAcrossRingWraps) {
  QosMonitor monitor(Config({MakeMkRule(998, 1000)}));
  // Misses at 1500, 2498, 2499: only the window [1500, 2499] holds all three; the next one,
  // [1501, 2500], has two again. Cycle indices run far past the ring's capacity.
  for (std::uint64_t cycle = 0; cycle < 5000; ++cycle) {
    const bool missed = cycle == 1500 || cycle == 2498 || cycle == 2499;
    ASSERT_FALSE(monitor.Record(cycle, missed));
  }
  EXPECT_TRUE(monitor.rules()[0].violated);
  EXPECT_EQ(monitor.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(2499));
  EXPECT_EQ(monitor.rules()[0].violations, 1U);
  EXPECT_EQ(monitor.rules()[0].min_met_in_window, 997U);
}

TEST(QosWindow, MissesInWindowIsTheComplementOfMk) {
  QosMonitor monitor(Config({MakeMissesInWindowRule(1, 4), MakeMkRule(3, 4)}));
  Feed(monitor, 30, {2, 5, 9, 12, 13});
  EXPECT_EQ(monitor.rules()[0].violated, monitor.rules()[1].violated);
  EXPECT_EQ(monitor.rules()[0].violations, monitor.rules()[1].violations);
  EXPECT_EQ(monitor.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(5));
  EXPECT_EQ(monitor.rules()[0].violations, 5U);  // windows ending 5, 12, 13, 14, 15
}

TEST(QosConsecutive, CountsRunsLongerThanN) {
  QosMonitor monitor(Config({MakeConsecutiveMissesRule(2)}));
  Feed(monitor, 30, {1, 2, 10, 11, 12, 13, 20, 21});
  EXPECT_TRUE(monitor.rules()[0].violated);
  EXPECT_EQ(monitor.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(12));
  EXPECT_EQ(monitor.rules()[0].violations, 2U);  // runs of 3 ending at 12 and 13
  EXPECT_EQ(monitor.max_consecutive_misses(), 4U);

  QosMonitor none(Config({MakeConsecutiveMissesRule(0)}));
  Feed(none, 10, {9});
  EXPECT_EQ(none.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(9));
}

TEST(QosRatio, BelowMeansStrictlyBelow) {
  // 9 misses in 1000 cycles: 0.9 % < 1 % passes; 10: exactly 1 % is not below 1 %.
  QosMonitor nine(Config({MakeMissRatioRule(1.0)}));
  for (std::uint64_t c = 0; c < 1000; ++c) (void)nine.Record(c, c % 100 == 50 && c < 900);
  EXPECT_EQ(nine.misses(), 9U);
  EXPECT_EQ(nine.verdict(), Verdict::kPass);
  EXPECT_DOUBLE_EQ(nine.miss_pct(), 0.9);

  QosMonitor ten(Config({MakeMissRatioRule(1.0)}));
  for (std::uint64_t c = 0; c < 1000; ++c) (void)ten.Record(c, c % 100 == 50);
  EXPECT_EQ(ten.verdict(), Verdict::kFlagged);
  EXPECT_EQ(ten.rules()[0].violations, 1U);
  EXPECT_FALSE(ten.rules()[0].first_violation_cycle.has_value());  // no plan given
}

TEST(QosRatio, AbortFiresWhenThePlannedRunCanNoLongerPass) {
  // Planned 1000 cycles at < 1 %: the 10th miss makes the planned run fail whatever follows.
  QosMonitor monitor(Config({MakeMissRatioRule(1.0)}, ViolationPolicy::kAbort, 1000));
  std::uint64_t stopped_at = 0;
  std::uint64_t misses = 0;
  for (std::uint64_t c = 0; c < 1000; ++c) {
    const bool missed = c % 7 == 3;
    misses += missed ? 1 : 0;
    if (monitor.Record(c, missed)) {
      stopped_at = c;
      break;
    }
  }
  EXPECT_EQ(misses, 10U);
  EXPECT_EQ(stopped_at, 66U);  // misses at 3, 10, ..., 66 (the 10th)
  EXPECT_EQ(monitor.verdict(), Verdict::kAborted);
  EXPECT_EQ(monitor.abort_cycle(), std::optional<std::uint64_t>(66));
  EXPECT_EQ(monitor.abort_rule(), std::optional<std::size_t>(0));
  EXPECT_EQ(monitor.rules()[0].first_violation_cycle, std::optional<std::uint64_t>(66));
}

TEST(QosRatio, AShortRunIsJudgedOverTheCyclesActuallyRun) {
  // Planned 1000, stopped after 100 with 2 misses: 2 % over what ran -> FLAGGED, not ABORTED
  // (the budget of 10 misses for the planned run was never used up).
  QosMonitor monitor(Config({MakeMissRatioRule(1.0)}, ViolationPolicy::kAbort, 1000));
  EXPECT_EQ(Feed(monitor, 100, {40, 80}), 100U);
  EXPECT_EQ(monitor.verdict(), Verdict::kFlagged);
  EXPECT_TRUE(monitor.rules()[0].violated);
  EXPECT_FALSE(monitor.abort_cycle().has_value());
  EXPECT_EQ(monitor.rules()[0].distance_to_failure, 8U);  // 10 - 2 misses to the abort
}

TEST(QosRatio, BudgetUsesTheSameRoundingAsTheFinalJudgement) {
  // 1.1 % of 1000 is 11 misses (1100 vs 1100.0000000000002 would disagree if rounded apart).
  QosMonitor monitor(Config({MakeMissRatioRule(1.1)}, ViolationPolicy::kAbort, 1000));
  std::uint64_t stop = 1000;
  for (std::uint64_t c = 0; c < 1000; ++c) {
    if (monitor.Record(c, c < 11)) {
      stop = c;
      break;
    }
  }
  EXPECT_EQ(stop, 10U);
  QosMonitor flag(Config({MakeMissRatioRule(1.1)}));
  for (std::uint64_t c = 0; c < 1000; ++c) (void)flag.Record(c, c < 11);
  EXPECT_EQ(flag.verdict(), Verdict::kFlagged);
}

TEST(QosGrace, StartUpCyclesAreCountedApartAndJudgedByNoRule) {
  QosMonitor monitor(
      Config({MakeMkRule(9, 10), MakeConsecutiveMissesRule(0)}, ViolationPolicy::kAbort, 0, 50));
  for (std::uint64_t c = 0; c < 50; ++c) ASSERT_FALSE(monitor.Record(c, true));
  for (std::uint64_t c = 50; c < 200; ++c) ASSERT_FALSE(monitor.Record(c, false));
  EXPECT_EQ(monitor.grace_cycles_seen(), 50U);
  EXPECT_EQ(monitor.grace_misses(), 50U);
  EXPECT_EQ(monitor.cycles_recorded(), 150U);
  EXPECT_EQ(monitor.misses(), 0U);
  EXPECT_EQ(monitor.verdict(), Verdict::kPass);
  // The first judged miss is judged against a met history, not the grace misses.
  EXPECT_TRUE(monitor.Record(200, true));  // consecutive(0) fails at once
  EXPECT_EQ(monitor.abort_cycle(), std::optional<std::uint64_t>(200));
  EXPECT_FALSE(monitor.rules()[0].violated);
}

TEST(QosAbort, StopsAtTheExactCycleAndKeepsSayingStop) {
  QosMonitor monitor(
      Config({MakeMkRule(9, 10), MakeMissRatioRule(1.0)}, ViolationPolicy::kAbort, 40'000));
  EXPECT_EQ(Feed(monitor, 40'000, {40'000 - 1, 100, 104, 5000}), 104U);
  EXPECT_EQ(monitor.verdict(), Verdict::kAborted);
  EXPECT_EQ(monitor.abort_rule(), std::optional<std::size_t>(0));
  EXPECT_EQ(monitor.cycles_recorded(), 105U);
  EXPECT_TRUE(monitor.Record(105, false));  // a caller that goes on is told again
  EXPECT_EQ(monitor.Live().verdict, Verdict::kAborted);
}

TEST(QosAbort, FlagPolicyNeverAsksToStop) {
  QosMonitor monitor(Config({MakeMkRule(1, 2)}));
  for (std::uint64_t c = 0; c < 100; ++c) ASSERT_FALSE(monitor.Record(c, true));
  EXPECT_EQ(monitor.verdict(), Verdict::kFlagged);
  EXPECT_EQ(monitor.rules()[0].violations, 99U);
}

TEST(QosDistance, HandComputedValues) {
  QosMonitor monitor(Config({MakeMkRule(9, 10)}));
  EXPECT_EQ(monitor.DistanceToFailure(), 2U);  // two misses in a row would make 2 in 10
  (void)monitor.Record(0, true);
  EXPECT_EQ(monitor.DistanceToFailure(), 1U);
  for (std::uint64_t c = 1; c <= 8; ++c) (void)monitor.Record(c, false);
  EXPECT_EQ(monitor.DistanceToFailure(), 1U);  // the miss at 0 is still in the next window
  (void)monitor.Record(9, false);
  EXPECT_EQ(monitor.DistanceToFailure(), 2U);  // it slides out with the next cycle

  QosMonitor run(Config({MakeConsecutiveMissesRule(3)}));
  EXPECT_EQ(run.DistanceToFailure(), 4U);
  (void)run.Record(0, true);
  (void)run.Record(1, true);
  EXPECT_EQ(run.DistanceToFailure(), 2U);
  (void)run.Record(2, true);
  (void)run.Record(3, true);
  EXPECT_EQ(run.DistanceToFailure(), 0U);  // violated right now

  QosMonitor ratio(Config({MakeMissRatioRule(1.0)}));  // no plan: over cycles so far
  for (std::uint64_t c = 0; c < 990; ++c) (void)ratio.Record(c, false);
  EXPECT_EQ(ratio.DistanceToFailure(), 10U);  // 10/1000 = 1 %

  EXPECT_EQ(QosMonitor(Config({})).DistanceToFailure(), kNeverFails);
  EXPECT_EQ(QosMonitor(Config({MakeMissRatioRule(100.0)})).DistanceToFailure(), 1U);
}

TEST(QosLive, ReadableFromAnotherThreadWhileRecording) {
  QosMonitor monitor(Config(DefaultRules()));
  std::atomic<bool> done{false};
  std::uint64_t last_seen = 0;
  bool monotonic = true;
  std::thread reader([&] {
    while (!done.load()) {
      const LiveQos live = monitor.Live();
      monotonic = monotonic && live.cycles_judged >= last_seen;
      last_seen = live.cycles_judged;
    }
  });
  for (std::uint64_t c = 0; c < 200'000; ++c) (void)monitor.Record(c, c % 1000 == 0);
  done.store(true);
  reader.join();
  EXPECT_TRUE(monotonic);
  const LiveQos live = monitor.Live();
  EXPECT_EQ(live.cycles_judged, 200'000U);
  EXPECT_EQ(live.misses, 200U);
  EXPECT_EQ(live.verdict, Verdict::kPass);
  EXPECT_EQ(live.distance_to_failure, 2U);  // (3,4) after three met cycles: 2 misses to fail
}

TEST(QosAllocation, RecordNeverAllocates) {
  QosMonitor monitor(
      Config({MakeMkRule(950, 1000), MakeMissesInWindowRule(3, 64), MakeConsecutiveMissesRule(5),
              MakeMissRatioRule(1.0), MakeMissRatioRule(2.0)},
             ViolationPolicy::kFlag, 100'000, 10));
  std::mt19937 rng(7);
  std::bernoulli_distribution miss(0.05);
  std::vector<bool> seq(100'000);
  for (std::size_t i = 0; i < seq.size(); ++i) seq[i] = miss(rng);
  std::uint64_t stops = 0;
  {
    test::ScopedAllocationCount count;
    for (std::uint64_t c = 0; c < seq.size(); ++c) stops += monitor.Record(c, seq[c]) ? 1U : 0U;
    (void)monitor.Live();
    (void)monitor.verdict();
    EXPECT_EQ(count.count(), 0U);
  }
  EXPECT_EQ(stops, 0U);
  EXPECT_EQ(monitor.verdict(), Verdict::kFlagged);
}

TEST(QosConfig, RejectsBadRulesWithTheRuleNumber) {
  QosConfig config =
      Config({MakeMkRule(9, 10), RuleSpec{.kind = RuleKind::kMkFirm, .m = 11, .k = 10}});
  try {
    QosMonitor monitor(config);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("QoS rule 2"), std::string::npos) << error.what();
  }
}

static_assert(noexcept(std::declval<QosMonitor&>().Record(0, false)));
static_assert(noexcept(std::declval<const QosMonitor&>().Live()));

TEST(QosStrings, VerdictAndPolicy) {
  EXPECT_STREQ(ToString(Verdict::kPass), "PASS");
  EXPECT_STREQ(ToString(Verdict::kFlagged), "FLAGGED");
  EXPECT_STREQ(ToString(Verdict::kAborted), "ABORTED");
  EXPECT_STREQ(ToString(ViolationPolicy::kFlag), "flag");
  EXPECT_EQ(ParseViolationPolicy("abort"), ViolationPolicy::kAbort);
  EXPECT_EQ(ParseViolationPolicy("flag"), ViolationPolicy::kFlag);
  EXPECT_THROW((void)ParseViolationPolicy("Abort"), std::invalid_argument);
}

}  // namespace
}  // namespace hiltwin::qos
