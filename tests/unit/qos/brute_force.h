#pragma once
// An independent, deliberately naive QoS checker: every figure is recomputed from the whole
// history at every step (windows recounted from scratch, the distance to failure found by
// appending misses one by one and re-checking). Percentages are compared in exact integer
// arithmetic (P is given in half percent), so no floating-point rounding is shared with the
// monitor under test.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "hiltwin/qos/monitor.h"

namespace hiltwin::qos::test {

struct BruteStatus {
  bool violated = false;
  std::uint64_t violations = 0;
  std::optional<std::uint64_t> first_violation_cycle;
  std::uint32_t min_met_in_window = 0;
  std::uint32_t max_misses_in_window = 0;
  std::uint32_t distance_to_failure = kNeverFails;
};

class BruteForce {
 public:
  BruteForce(std::vector<RuleSpec> rules, std::uint64_t grace_cycles, std::uint64_t planned)
      : rules_(std::move(rules)), grace_(grace_cycles), status_(rules_.size()) {
    judged_plan_ = planned > grace_ ? planned - grace_ : 0;
    for (std::size_t i = 0; i < rules_.size(); ++i) {
      if (IsWindow(rules_[i])) status_[i].min_met_in_window = rules_[i].k;
      status_[i].distance_to_failure = Distance(rules_[i], seq_);
    }
  }

  // Mirrors QosMonitor::Record; `distance` = false skips the (slow) distance recomputation.
  bool Record(std::uint64_t cycle, bool missed, bool distance = true) {
    if (cycle < grace_) return aborted_;
    seq_.push_back(missed);
    cycles_.push_back(cycle);
    if (missed) ++misses_;  // a running total; every window below is recounted from scratch
    const std::uint64_t misses = misses_;
    for (std::size_t i = 0; i < rules_.size(); ++i) {
      const RuleSpec& rule = rules_[i];
      BruteStatus& status = status_[i];
      if (rule.kind == RuleKind::kMissRatio) {
        status.violated = RatioFails(rule, misses, seq_.size());
        status.violations = status.violated ? 1 : 0;
        if (judged_plan_ > 0 && misses >= Budget(rule) && !status.first_violation_cycle) {
          status.first_violation_cycle = cycle;
          Abort();
        }
      } else {
        if (IsWindow(rule)) {
          const std::uint32_t window_misses = WindowMisses(seq_, seq_.size() - 1, rule.k);
          status.max_misses_in_window = std::max(status.max_misses_in_window, window_misses);
          status.min_met_in_window = rule.k - status.max_misses_in_window;
        }
        if (FailsAtEnd(rule, seq_)) {
          status.violated = true;
          ++status.violations;
          if (!status.first_violation_cycle) status.first_violation_cycle = cycle;
          Abort();
        }
      }
      if (distance) status.distance_to_failure = Distance(rule, seq_);
    }
    return aborted_;
  }

  void SetAbortPolicy(bool abort) { abort_policy_ = abort; }
  [[nodiscard]] const std::vector<BruteStatus>& status() const { return status_; }
  [[nodiscard]] std::uint64_t misses() const { return misses_; }
  [[nodiscard]] std::uint64_t cycles() const { return seq_.size(); }
  [[nodiscard]] std::uint64_t max_consecutive() const {
    std::uint64_t best = 0;
    std::uint64_t run = 0;
    for (bool m : seq_) {
      run = m ? run + 1 : 0;
      best = std::max(best, run);
    }
    return best;
  }
  [[nodiscard]] Verdict verdict() const {
    if (aborted_) return Verdict::kAborted;
    for (const auto& s : status_) {
      if (s.violated) return Verdict::kFlagged;
    }
    return Verdict::kPass;
  }
  [[nodiscard]] std::uint32_t min_distance() const {
    std::uint32_t best = kNeverFails;
    for (const auto& s : status_) best = std::min(best, s.distance_to_failure);
    return best;
  }

 private:
  static bool IsWindow(const RuleSpec& rule) {
    return rule.kind == RuleKind::kMkFirm || rule.kind == RuleKind::kMissesInWindow;
  }
  static std::uint32_t Allowed(const RuleSpec& rule) {
    return rule.kind == RuleKind::kMkFirm ? rule.k - rule.m : rule.n;
  }
  // Misses among cycles end-k+1 .. end; indices below 0 are the met pre-history.
  static std::uint32_t WindowMisses(const std::vector<bool>& seq, std::size_t end,
                                    std::uint32_t k) {
    std::uint32_t count = 0;
    for (std::uint32_t back = 0; back < k && back <= end; ++back) {
      if (seq[end - back]) ++count;
    }
    return count;
  }
  // Does the window (or run) ending at the last cycle violate a non-ratio rule?
  static bool FailsAtEnd(const RuleSpec& rule, const std::vector<bool>& seq) {
    if (seq.empty()) return false;
    if (IsWindow(rule)) return WindowMisses(seq, seq.size() - 1, rule.k) > Allowed(rule);
    // Consecutive: the last n+1 cycles all missed (pre-history is met).
    const std::uint64_t need = std::uint64_t{rule.n} + 1;
    if (seq.size() < need) return false;
    for (std::uint64_t back = 0; back < need; ++back) {
      if (!seq[seq.size() - 1 - back]) return false;
    }
    return true;
  }
  static std::uint64_t HalfPct(const RuleSpec& rule) {
    return static_cast<std::uint64_t>(rule.max_miss_pct * 2.0);  // tests use multiples of 0.5
  }
  static bool RatioFails(const RuleSpec& rule, std::uint64_t misses, std::uint64_t cycles) {
    return cycles > 0 && misses * 200 >= HalfPct(rule) * cycles;
  }
  std::uint64_t Budget(const RuleSpec& rule) const {
    for (std::uint64_t m = 1;; ++m) {
      if (RatioFails(rule, m, judged_plan_)) return m;
    }
  }
  std::uint32_t Distance(const RuleSpec& rule, const std::vector<bool>& seq) const {
    const std::uint64_t misses = misses_;
    if (rule.kind == RuleKind::kMissRatio) {
      if (judged_plan_ > 0) {
        const std::uint64_t budget = Budget(rule);
        return static_cast<std::uint32_t>(budget > misses ? budget - misses : 0);
      }
      // At 100 % the test (M + j)·200 >= 200·(T + j) does not depend on j, so j <= 1 decides.
      // Otherwise test limits are at most 50 % and runs shorter than 20,000 cycles, so a
      // failure comes within 100,000 misses.
      const std::uint64_t cap = HalfPct(rule) >= 200 ? 2 : 100'000;
      for (std::uint64_t j = 0; j < cap; ++j) {
        if (RatioFails(rule, misses + j, seq.size() + j)) return static_cast<std::uint32_t>(j);
      }
      return kNeverFails;
    }
    if (FailsAtEnd(rule, seq)) return 0;
    // Only the last window (or run) can matter, so extend a copy of that tail.
    const std::size_t keep =
        std::min<std::size_t>(seq.size(), IsWindow(rule) ? rule.k : rule.n + 1);
    std::vector<bool> extended(seq.end() - static_cast<std::ptrdiff_t>(keep), seq.end());
    for (std::uint32_t j = 1;; ++j) {
      extended.push_back(true);
      if (FailsAtEnd(rule, extended)) return j;
    }
  }
  void Abort() {
    if (abort_policy_) aborted_ = true;
  }

  std::vector<RuleSpec> rules_;
  std::uint64_t grace_;
  std::uint64_t judged_plan_ = 0;
  std::vector<BruteStatus> status_;
  std::vector<bool> seq_;
  std::vector<std::uint64_t> cycles_;
  std::uint64_t misses_ = 0;
  bool abort_policy_ = false;
  bool aborted_ = false;
};

}  // namespace hiltwin::qos::test
