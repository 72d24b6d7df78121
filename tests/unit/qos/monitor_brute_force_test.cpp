// QosMonitor against the from-scratch checker in brute_force.h, on random and adversarial
// miss sequences, for every rule kind, with and without a plan and a grace period.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "brute_force.h"
#include "hiltwin/qos/monitor.h"

namespace hiltwin::qos {
namespace {

// Shorter where every instruction costs several: instrumented, or emulated (arm64 under qemu).
#if defined(HILTWIN_UNDER_SANITIZER) || defined(HILTWIN_UNDER_EMULATOR)
constexpr std::size_t kLength = 1500;
#else
constexpr std::size_t kLength = 4000;
#endif

using Sequence = std::vector<bool>;

Sequence Bernoulli(double p, std::size_t length, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution miss(p);
  Sequence seq(length);
  for (std::size_t i = 0; i < length; ++i) seq[i] = miss(rng);
  return seq;
}

// Quiet stretches (geometric, mean `gap`) broken by bursts of 1..max_burst misses.
Sequence Bursts(double gap, std::uint32_t max_burst, std::size_t length, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::geometric_distribution<std::uint32_t> quiet(1.0 / gap);
  std::uniform_int_distribution<std::uint32_t> burst(1, max_burst);
  Sequence seq;
  while (seq.size() < length) {
    for (std::uint32_t i = quiet(rng); i > 0 && seq.size() < length; --i) seq.push_back(false);
    for (std::uint32_t i = burst(rng); i > 0 && seq.size() < length; --i) seq.push_back(true);
  }
  return seq;
}

// A miss every `period` cycles, starting at `phase`.
Sequence Periodic(std::size_t period, std::size_t phase, std::size_t length) {
  Sequence seq(length);
  for (std::size_t i = phase; i < length; i += period) seq[i] = true;
  return seq;
}

// The densest pattern a window rule allows (k-m misses, then m mets, repeated): every window
// holds exactly k-m misses. At `break_at` one extra miss tips exactly one window over.
Sequence Saturating(std::uint32_t m, std::uint32_t k, std::size_t length, std::size_t break_at) {
  Sequence seq(length);
  for (std::size_t i = 0; i < length; ++i) seq[i] = (i % k) < (k - m);
  if (break_at < length) seq[break_at] = true;
  return seq;
}

struct Case {
  std::string name;
  std::vector<RuleSpec> rules;
  Sequence seq;
};

std::uint32_t MaxWindow(const std::vector<RuleSpec>& rules) {
  std::uint32_t k = 1;
  for (const auto& r : rules) k = std::max(k, r.k);
  return k;
}

// Feeds one sequence to both checkers and compares every figure after every cycle.
void RunAndCompare(const Case& c, std::uint64_t grace, std::uint64_t planned, bool abort) {
  SCOPED_TRACE(c.name + " grace=" + std::to_string(grace) + " planned=" + std::to_string(planned) +
               (abort ? " abort" : " flag"));
  QosMonitor monitor(QosConfig{.rules = c.rules,
                               .grace_cycles = grace,
                               .policy = abort ? ViolationPolicy::kAbort : ViolationPolicy::kFlag,
                               .planned_cycles = planned});
  test::BruteForce brute(c.rules, grace, planned);
  brute.SetAbortPolicy(abort);
  const std::uint32_t max_k = MaxWindow(c.rules);
  // The brute-force distance is O(k^2); check it at every cycle for short windows only.
  const std::size_t distance_every = max_k <= 16 ? 1 : (max_k <= 130 ? 7 : 97);
  for (std::size_t i = 0; i < c.seq.size(); ++i) {
    const bool check_distance = i % distance_every == 0 || i + 1 == c.seq.size();
    const bool stop = monitor.Record(i, c.seq[i]);
    const bool brute_stop = brute.Record(i, c.seq[i], check_distance);
    ASSERT_EQ(stop, brute_stop) << "cycle " << i;
    ASSERT_EQ(monitor.verdict(), brute.verdict()) << "cycle " << i;
    ASSERT_EQ(monitor.misses(), brute.misses()) << "cycle " << i;
    ASSERT_EQ(monitor.cycles_recorded(), brute.cycles()) << "cycle " << i;
    for (std::size_t r = 0; r < c.rules.size(); ++r) {
      const RuleStatus& got = monitor.rules()[r];
      const test::BruteStatus& want = brute.status()[r];
      SCOPED_TRACE("rule " + Describe(c.rules[r]) + " cycle " + std::to_string(i));
      ASSERT_EQ(got.violated, want.violated);
      ASSERT_EQ(got.violations, want.violations);
      ASSERT_EQ(got.first_violation_cycle, want.first_violation_cycle);
      ASSERT_EQ(got.min_met_in_window, want.min_met_in_window);
      ASSERT_EQ(got.max_misses_in_window, want.max_misses_in_window);
      if (check_distance) {
        ASSERT_EQ(got.distance_to_failure, want.distance_to_failure);
      }
    }
    if (check_distance) {
      ASSERT_EQ(monitor.DistanceToFailure(), brute.min_distance()) << "cycle " << i;
      ASSERT_EQ(monitor.Live().distance_to_failure, brute.min_distance()) << "cycle " << i;
    }
    if (stop) {
      ASSERT_EQ(monitor.abort_cycle(), std::optional<std::uint64_t>(i))
          << "abort fires at the exact violating cycle";
      break;  // the caller stops here
    }
  }
  EXPECT_EQ(monitor.max_consecutive_misses(), brute.max_consecutive());
}

std::vector<Case> Cases() {
  const std::vector<RuleSpec> mixed = {MakeMkRule(9, 10), MakeConsecutiveMissesRule(2),
                                       MakeMissRatioRule(1.0)};
  const std::vector<RuleSpec> defaults = DefaultRules();
  const std::vector<RuleSpec> k1 = {MakeMkRule(1, 1)};
  const std::vector<RuleSpec> hard = {MakeMkRule(5, 5), MakeMissRatioRule(0.5)};
  const std::vector<RuleSpec> k1000 = {MakeMkRule(950, 1000), MakeMissesInWindowRule(3, 64),
                                       MakeConsecutiveMissesRule(0)};
  const std::vector<RuleSpec> loose = {MakeMissesInWindowRule(1, 2), MakeMkRule(1, 3),
                                       MakeMissRatioRule(50.0)};
  const std::vector<RuleSpec> words = {MakeMkRule(63, 64), MakeMkRule(60, 65),
                                       MakeMkRule(120, 128)};
  const std::vector<RuleSpec> ratio = {MakeMissRatioRule(2.5), MakeConsecutiveMissesRule(5),
                                       MakeMissRatioRule(100.0)};
  const std::size_t n = kLength;
  std::vector<Case> cases = {
      {"mixed/bernoulli 2%", mixed, Bernoulli(0.02, n, 1)},
      {"mixed/bernoulli 30%", mixed, Bernoulli(0.3, n, 2)},
      {"mixed/bursts", mixed, Bursts(60, 4, n, 3)},
      {"mixed/periodic 10", mixed, Periodic(10, 3, n)},
      {"mixed/periodic 9", mixed, Periodic(9, 0, n)},
      {"mixed/saturating", mixed, Saturating(9, 10, n, n / 2)},
      {"default/bernoulli 1%", defaults, Bernoulli(0.01, n, 4)},
      {"default/periodic 4", defaults, Periodic(4, 1, n)},
      {"default/periodic 3", defaults, Periodic(3, 2, n)},
      {"default/bursts", defaults, Bursts(200, 3, n, 5)},
      {"k1/bernoulli", k1, Bernoulli(0.1, n, 6)},
      {"m=k/bernoulli", hard, Bernoulli(0.05, n, 7)},
      {"m=k/periodic 5", hard, Periodic(5, 4, n)},
      {"k1000/bernoulli 3%", k1000, Bernoulli(0.03, 3 * n, 8)},
      {"k1000/bernoulli 6%", k1000, Bernoulli(0.06, 3 * n, 9)},
      {"k1000/bursts", k1000, Bursts(400, 30, 3 * n, 10)},
      {"k1000/saturating", k1000, Saturating(950, 1000, 3 * n, 2 * n + 17)},
      // Met runs longer than the longest window put the monitor at rest; the bursts after
      // them must find the miss bits and met rings as if every cycle had been worked.
      {"k1000/rests", k1000, Bursts(1500, 40, 4 * n, 16)},
      {"loose/bernoulli 50%", loose, Bernoulli(0.5, n, 11)},
      {"loose/periodic 2", loose, Periodic(2, 1, n)},
      {"words/bernoulli", words, Bernoulli(0.03, n, 12)},
      {"words/saturating 64", words, Saturating(63, 64, n, n - 100)},
      {"words/saturating 128", words, Saturating(120, 128, n, 3 * n / 4)},
      {"words/rests", words, Bursts(200, 70, n, 17)},
      {"ratio/bernoulli 2%", ratio, Bernoulli(0.02, n, 13)},
      {"ratio/bursts", ratio, Bursts(150, 7, n, 14)},
      {"ratio/all missed", ratio, Sequence(300, true)},
      {"mixed/all met", mixed, Sequence(n, false)},
  };
  return cases;
}

TEST(QosBruteForce, FlagPolicyMatchesOnEveryCycle) {
  for (const Case& c : Cases()) {
    RunAndCompare(c, 0, 0, false);
    RunAndCompare(c, 0, c.seq.size(), false);
  }
}

TEST(QosBruteForce, GracePeriodMatches) {
  for (const Case& c : Cases()) {
    RunAndCompare(c, 5, c.seq.size(), false);
    RunAndCompare(c, 1001, 0, false);
  }
}

TEST(QosBruteForce, AbortPolicyStopsAtTheFirstViolation) {
  for (const Case& c : Cases()) {
    RunAndCompare(c, 0, 0, true);
    RunAndCompare(c, 0, c.seq.size(), true);
    RunAndCompare(c, 7, c.seq.size(), true);
  }
}

TEST(QosBruteForce, ManyShortRandomSequencesOnSmallWindows) {
  // Exhaustive-ish sweep of small (m,k) and n, with the distance checked at every cycle.
  std::mt19937 rng(2024);
  for (std::uint32_t k = 1; k <= 6; ++k) {
    for (std::uint32_t m = 1; m <= k; ++m) {
      for (std::uint32_t trial = 0; trial < 4; ++trial) {
        const double p = 0.05 + 0.2 * trial;
        Case c{"m=" + std::to_string(m) + " k=" + std::to_string(k),
               {MakeMkRule(m, k), MakeMissesInWindowRule(k - m, k + 1),
                MakeConsecutiveMissesRule(k - m)},
               Bernoulli(p, 200, static_cast<std::uint32_t>(rng()))};
        RunAndCompare(c, 0, 0, false);
        RunAndCompare(c, 3, 200, true);
      }
    }
  }
}

}  // namespace
}  // namespace hiltwin::qos
