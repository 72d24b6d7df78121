#include "hiltwin/qos/monitor.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hiltwin::qos {
namespace {

// The one definition of "the ratio rule fails" used by the live check, the abort budget and
// the distance, so that they can never disagree by a rounding step.
bool RatioFails(std::uint64_t misses, std::uint64_t cycles, double max_miss_pct) noexcept {
  return cycles > 0 &&
         static_cast<double>(misses) * 100.0 >= max_miss_pct * static_cast<double>(cycles);
}

std::uint32_t ClampDistance(std::uint64_t distance) noexcept {
  return distance >= kNeverFails ? kNeverFails : static_cast<std::uint32_t>(distance);
}

// Fewest misses that make the ratio fail over `cycles` cycles (>= 1 because pct > 0).
std::uint64_t MissBudget(std::uint64_t cycles, double max_miss_pct) noexcept {
  auto budget =
      static_cast<std::uint64_t>(std::ceil(max_miss_pct * static_cast<double>(cycles) / 100.0));
  budget = std::clamp<std::uint64_t>(budget, 1, cycles);
  while (budget > 1 && RatioFails(budget - 1, cycles, max_miss_pct)) --budget;
  while (budget < cycles && !RatioFails(budget, cycles, max_miss_pct)) ++budget;
  return budget;
}

}  // namespace

const char* ToString(ViolationPolicy policy) noexcept {
  switch (policy) {
    case ViolationPolicy::kFlag:
      return "flag";
    case ViolationPolicy::kAbort:
      return "abort";
  }
  return "unknown";
}

ViolationPolicy ParseViolationPolicy(std::string_view text) {
  if (text == "flag") return ViolationPolicy::kFlag;
  if (text == "abort") return ViolationPolicy::kAbort;
  throw std::invalid_argument("'" + std::string(text) +
                              "' is not a violation policy: expected flag (finish the run, "
                              "verdict FLAGGED) or abort (stop at the first violation)");
}

const char* ToString(Verdict verdict) noexcept {
  switch (verdict) {
    case Verdict::kPass:
      return "PASS";
    case Verdict::kFlagged:
      return "FLAGGED";
    case Verdict::kAborted:
      return "ABORTED";
  }
  return "UNKNOWN";
}

void Validate(const QosConfig& config) {
  for (std::size_t i = 0; i < config.rules.size(); ++i) {
    try {
      Validate(config.rules[i]);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument("QoS rule " + std::to_string(i + 1) + ": " + error.what());
    }
  }
}

QosMonitor::QosMonitor(const QosConfig& config) : config_(config) {
  Validate(config_);
  judged_plan_ = config_.planned_cycles > config_.grace_cycles
                     ? config_.planned_cycles - config_.grace_cycles
                     : 0;
  status_.reserve(config_.rules.size());
  engines_.reserve(config_.rules.size());
  std::uint32_t max_k = 1;
  std::uint32_t min_distance = kNeverFails;
  for (const RuleSpec& rule : config_.rules) {
    RuleStatus status;
    status.spec = rule;
    Engine engine;
    engine.kind = rule.kind;
    switch (rule.kind) {
      case RuleKind::kMkFirm:
      case RuleKind::kMissesInWindow: {
        const std::uint32_t must_meet = rule.kind == RuleKind::kMkFirm ? rule.m : rule.k - rule.n;
        engine.k = rule.k;
        engine.allowed_misses = rule.k - must_meet;
        engine.met_ring.resize(must_meet);
        for (std::uint32_t i = 0; i < must_meet; ++i) {
          engine.met_ring[i] = static_cast<std::int64_t>(i) - static_cast<std::int64_t>(must_meet);
        }
        status.min_met_in_window = rule.k;
        status.distance_to_failure = engine.allowed_misses + 1;
        max_k = std::max(max_k, rule.k);
        break;
      }
      case RuleKind::kConsecutiveMisses:
        engine.allowed_misses = rule.n;
        status.distance_to_failure = rule.n + 1;
        break;
      case RuleKind::kMissRatio:
        engine.max_miss_pct = rule.max_miss_pct;
        if (rule.max_miss_pct < 100.0) {
          engine.ratio_per_cycle = rule.max_miss_pct / (100.0 - rule.max_miss_pct);
          engine.ratio_per_miss = 100.0 / (100.0 - rule.max_miss_pct);
        }
        engine.miss_budget = judged_plan_ > 0 ? MissBudget(judged_plan_, rule.max_miss_pct) : 0;
        status.distance_to_failure = RatioDistance(engine);
        break;
    }
    min_distance = std::min(min_distance, status.distance_to_failure);
    status_.push_back(status);
    engines_.push_back(std::move(engine));
  }
  const std::uint64_t capacity_bits =
      std::max<std::uint64_t>(64, std::bit_ceil(std::uint64_t{max_k}));
  ring_words_.assign(capacity_bits / 64, 0);
  ring_mask_ = capacity_bits - 1;
  rest_after_ = max_k;
  unplanned_ratio_ = std::any_of(engines_.begin(), engines_.end(), [](const Engine& engine) {
    return engine.kind == RuleKind::kMissRatio && engine.miss_budget == 0;
  });
  live_distance_.store(min_distance, std::memory_order_relaxed);
}

bool QosMonitor::Bit(std::uint64_t index) const noexcept {
  const std::uint64_t slot = index & ring_mask_;
  return ((ring_words_[slot >> 6] >> (slot & 63)) & 1U) != 0;
}

void QosMonitor::SetBit(std::uint64_t index, bool value) noexcept {
  const std::uint64_t slot = index & ring_mask_;
  const std::uint64_t shift = slot & 63;
  std::uint64_t& word = ring_words_[slot >> 6];
  word = (word & ~(std::uint64_t{1} << shift)) | (std::uint64_t{value} << shift);
}

void QosMonitor::MarkViolation(std::size_t rule, std::uint64_t cycle) noexcept {
  RuleStatus& status = status_[rule];
  status.violated = true;
  ++status.violations;
  if (!status.first_violation_cycle) status.first_violation_cycle = cycle;
  if (config_.policy == ViolationPolicy::kAbort && !aborted_) {
    aborted_ = true;
    abort_cycle_ = cycle;
    abort_rule_ = rule;
  }
}

std::uint32_t QosMonitor::RatioDistance(const Engine& engine) const noexcept {
  if (engine.miss_budget > 0) return BudgetDistance(engine);
  // No plan: the ratio is judged over the cycles run so far. Smallest j >= 1 with
  // (M + j)·100 >= P·(T + j), i.e. j >= (P·T - 100·M) / (100 - P).
  const double pct = engine.max_miss_pct;
  const std::uint64_t m = misses_;
  const std::uint64_t t = judged_cycles_;
  if (RatioFails(m, t, pct)) return 0;
  if (t == 0) return 1;                  // one miss out of one cycle is 100 %
  if (pct >= 100.0) return kNeverFails;  // "below 100 %" fails only if every cycle missed
  // Closed form, then corrected by the exact test (rounding can put it one off either way).
  // ceil() by truncation: a libm call here would cost more than the rest of Record().
  const double need = engine.ratio_per_cycle * static_cast<double>(t) -
                      engine.ratio_per_miss * static_cast<double>(m);
  if (!(need < static_cast<double>(kNeverFails))) return kNeverFails;
  std::uint64_t j = need <= 1.0 ? 1 : static_cast<std::uint64_t>(need);
  if (static_cast<double>(j) < need) ++j;
  while (j > 1 && RatioFails(m + j - 1, t + j - 1, pct)) --j;
  while (!RatioFails(m + j, t + j, pct) && j < kNeverFails) ++j;
  return ClampDistance(j);
}

[[gnu::always_inline]] inline bool QosMonitor::UpdateWindowRule(Engine& engine, RuleStatus& status, std::uint64_t t,
                                  bool missed) noexcept {
  // Cycle t - k leaves the window (before the first k judged cycles it is the met
  // pre-history); the ring still holds it because its capacity is >= k.
  const bool leaving = t >= engine.k && Bit(t - engine.k);
  engine.misses_in_window += (missed ? 1U : 0U);
  engine.misses_in_window -= (leaving ? 1U : 0U);
  if (!missed) {
    engine.met_ring[engine.met_head] = static_cast<std::int64_t>(t);
    engine.met_head = engine.met_head + 1 == engine.met_ring.size() ? 0 : engine.met_head + 1;
  }
  // The m-th most recent met cycle p stays in the window for k - (t - p) - 1 more
  // misses; the window ending at t + j fails first at j = p + k - t (DBP).
  const std::int64_t distance = engine.met_ring[engine.met_head] +
                                static_cast<std::int64_t>(engine.k) - static_cast<std::int64_t>(t);
  status.distance_to_failure = distance > 0 ? static_cast<std::uint32_t>(distance) : 0;
  if (engine.misses_in_window > status.max_misses_in_window) {
    status.max_misses_in_window = engine.misses_in_window;
    status.min_met_in_window = engine.k - engine.misses_in_window;
  }
  return engine.misses_in_window > engine.allowed_misses;
}

[[gnu::always_inline]] inline void QosMonitor::UpdateRatioRule(const Engine& engine, RuleStatus& status, std::size_t rule,
                                 std::uint64_t cycle) noexcept {
  status.violated = RatioFails(misses_, judged_cycles_, engine.max_miss_pct);
  status.violations = status.violated ? 1 : 0;
  if (engine.miss_budget > 0 && misses_ >= engine.miss_budget && !status.first_violation_cycle) {
    // The planned run can no longer end below the limit.
    status.first_violation_cycle = cycle;
    if (config_.policy == ViolationPolicy::kAbort && !aborted_) {
      aborted_ = true;
      abort_cycle_ = cycle;
      abort_rule_ = rule;
    }
  }
  // With a plan (every timed run) the distance is the budget left: no call for it.
  status.distance_to_failure =
      engine.miss_budget > 0 ? BudgetDistance(engine) : RatioDistance(engine);
}

bool QosMonitor::AtRest() const noexcept {
  if (met_run_ < rest_after_ || unplanned_ratio_) return false;
  for (std::size_t i = 0; i < engines_.size(); ++i) {
    if (engines_[i].kind == RuleKind::kMissRatio && status_[i].violated) return false;
  }
  return true;
}

void QosMonitor::LeaveRest() noexcept {
  quiet_ = false;
  // Every bit a window can still read (the last rest_after_ judged cycles) is a met one.
  std::fill(ring_words_.begin(), ring_words_.end(), 0);
  // The m most recent met cycles are the last m judged ones (m <= k <= rest_after_), oldest
  // first; only the order from met_head on is ever read.
  const auto last = static_cast<std::int64_t>(judged_cycles_) - 1;
  for (Engine& engine : engines_) {
    const std::size_t m = engine.met_ring.size();
    for (std::size_t i = 0; i < m; ++i) {
      engine.met_ring[i] = last - static_cast<std::int64_t>(m - 1 - i);
    }
    engine.met_head = 0;
  }
}

bool QosMonitor::RecordInFull(std::uint64_t cycle, bool missed) noexcept {
  if (quiet_) LeaveRest();
  run_all_ = missed ? run_all_ + 1 : 0;
  max_run_all_ = std::max(max_run_all_, run_all_);
  if (cycle < config_.grace_cycles) {
    ++grace_seen_;
    if (missed) ++grace_misses_;
    live_releases_.store(releases_recorded(), std::memory_order_relaxed);
    live_all_misses_.store(all_misses(), std::memory_order_relaxed);
    return aborted_;
  }
  const std::uint64_t t = judged_cycles_;  // judged index of this cycle
  ++judged_cycles_;
  misses_ += missed ? 1U : 0U;
  run_ = missed ? run_ + 1 : 0;
  max_run_ = std::max(max_run_, run_);
  met_run_ = missed ? 0 : met_run_ + 1;

  std::uint32_t min_distance = kNeverFails;
  bool any_violated = false;
  const std::size_t rules = engines_.size();
  for (std::size_t i = 0; i < rules; ++i) {
    Engine& engine = engines_[i];
    RuleStatus& status = status_[i];
    bool violated_now = false;
    switch (engine.kind) {
      case RuleKind::kMkFirm:
      case RuleKind::kMissesInWindow:
        violated_now = UpdateWindowRule(engine, status, t, missed);
        break;
      case RuleKind::kConsecutiveMisses:
        violated_now = run_ > engine.allowed_misses;
        status.distance_to_failure =
            violated_now ? 0 : ClampDistance(engine.allowed_misses + 1 - run_);
        break;
      case RuleKind::kMissRatio:
        // A met cycle can only lower the ratio: a rule that holds still holds, its budget and
        // distance (under a plan) are unchanged, so only a miss or a violated rule is worked.
        if (missed || status.violated || engine.miss_budget == 0) {
          UpdateRatioRule(engine, status, i, cycle);
        }
        break;
    }
    if (violated_now) MarkViolation(i, cycle);
    any_violated = any_violated || status.violated;
    min_distance = std::min(min_distance, status.distance_to_failure);
  }
  SetBit(t, missed);
  quiet_ = !missed && AtRest();

  live_releases_.store(releases_recorded(), std::memory_order_relaxed);
  live_all_misses_.store(all_misses(), std::memory_order_relaxed);
  live_cycles_.store(judged_cycles_, std::memory_order_relaxed);
  live_misses_.store(misses_, std::memory_order_relaxed);
  live_distance_.store(min_distance, std::memory_order_relaxed);
  live_verdict_.store(
      aborted_ ? Verdict::kAborted : (any_violated ? Verdict::kFlagged : Verdict::kPass),
      std::memory_order_relaxed);
  return aborted_;
}

Verdict QosMonitor::verdict() const noexcept {
  if (aborted_) return Verdict::kAborted;
  for (const RuleStatus& status : status_) {
    if (status.violated) return Verdict::kFlagged;
  }
  return Verdict::kPass;
}

double QosMonitor::miss_pct() const noexcept {
  if (judged_cycles_ == 0) return 0.0;
  return static_cast<double>(misses_) * 100.0 / static_cast<double>(judged_cycles_);
}

double QosMonitor::all_miss_pct() const noexcept {
  const std::uint64_t releases = releases_recorded();
  if (releases == 0) return 0.0;
  return static_cast<double>(all_misses()) * 100.0 / static_cast<double>(releases);
}

LiveQos QosMonitor::Live() const noexcept {
  return LiveQos{.releases = live_releases_.load(std::memory_order_relaxed),
                 .deadline_misses = live_all_misses_.load(std::memory_order_relaxed),
                 .cycles_judged = live_cycles_.load(std::memory_order_relaxed),
                 .misses = live_misses_.load(std::memory_order_relaxed),
                 .distance_to_failure = live_distance_.load(std::memory_order_relaxed),
                 .verdict = live_verdict_.load(std::memory_order_relaxed)};
}

}  // namespace hiltwin::qos
