#pragma once
/// The QoS monitor: the run's one miss ledger. It records one met/missed flag per release (the
/// grace period apart) and keeps, for every rule, whether
/// it is violated, how many windows violate it, the first violating cycle, the worst window and
/// the live distance to failure. Record() is O(rules) = O(1) per cycle, allocation-free,
/// lock-free and never throws; all memory is taken in the constructor. Semantics: docs/qos.md.
///
/// Threading: one thread calls Record() (the real-time loop); any thread may call Live().
/// Everything else is read by the owning thread, or by others after the loop has stopped.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "hiltwin/qos/rules.h"

namespace hiltwin::qos {

/// What the monitor does at a violation.
enum class ViolationPolicy : std::uint8_t {
  kFlag,   ///< keep running; the verdict becomes FLAGGED (exit 3)
  kAbort,  ///< Record() returns true at the first violation; the verdict is ABORTED (exit 4)
};

/// "flag" / "abort".
[[nodiscard]] const char* ToString(ViolationPolicy policy) noexcept;
/// Parses "flag" or "abort"; throws std::invalid_argument quoting the text otherwise.
[[nodiscard]] ViolationPolicy ParseViolationPolicy(std::string_view text);

/// The run's QoS outcome.
enum class Verdict : std::uint8_t {
  kPass,     ///< no rule violated
  kFlagged,  ///< a rule was violated; the run completed but its results are unreliable
  kAborted,  ///< policy abort stopped the run at the first violation
};

/// "PASS" / "FLAGGED" / "ABORTED" (the run report's `verdict`).
[[nodiscard]] const char* ToString(Verdict verdict) noexcept;

/// Distance to failure meaning "no number of misses can violate any rule".
constexpr std::uint32_t kNeverFails = UINT32_MAX;

struct QosConfig {
  std::vector<RuleSpec> rules;     ///< may be empty (the verdict is then always PASS)
  std::uint64_t grace_cycles = 0;  ///< releases with index < this are not judged
  ViolationPolicy policy = ViolationPolicy::kFlag;
  /// Releases the run plans (cycles_planned of the report); 0 = until stopped. Lets policy
  /// abort stop as soon as the miss-ratio rule can no longer pass over the planned run.
  std::uint64_t planned_cycles = 0;
};

/// Throws std::invalid_argument naming the first bad rule.
void Validate(const QosConfig& config);

/// Where one rule stands. Window figures count only windows that end at a judged cycle;
/// cycles before the first judged one count as met.
struct RuleStatus {
  RuleSpec spec;
  bool violated = false;         ///< window rules: ever violated; ratio: over cycles so far
  std::uint64_t violations = 0;  ///< violating windows (ratio: 1 when violated, else 0)
  /// Release index where the rule first failed. Window rules: the end of the first violating
  /// window. Ratio: the cycle at which misses reached max_miss_pct of the planned cycles
  /// (unset when there is no plan or the plan's budget was never used up).
  std::optional<std::uint64_t> first_violation_cycle;
  std::uint32_t min_met_in_window = 0;     ///< window rules: fewest met in any window
  std::uint32_t max_misses_in_window = 0;  ///< window rules: most misses in any window
  /// Consecutive misses from now on that would violate the rule (0: violated right now).
  std::uint32_t distance_to_failure = kNeverFails;
};

/// Figures any thread may read while the loop runs (each field is one relaxed atomic load).
struct LiveQos {
  std::uint64_t releases = 0;         ///< every release recorded, grace period included
  std::uint64_t deadline_misses = 0;  ///< misses among them, grace period included
  std::uint64_t cycles_judged = 0;    ///< releases after the grace period
  std::uint64_t misses = 0;           ///< misses among the judged releases
  std::uint32_t distance_to_failure = kNeverFails;  ///< minimum over the rules
  Verdict verdict = Verdict::kPass;                 ///< verdict if the run ended now
};

class QosMonitor {
 public:
  /// Validates the configuration (throws std::invalid_argument) and allocates all memory.
  explicit QosMonitor(const QosConfig& config);

  /// Records release `cycle` (call once per release, in increasing order, skipped releases
  /// included as misses). Returns true when the caller must stop now: policy abort and a rule
  /// has been violated (this cycle or earlier). Releases with index < grace_cycles are counted
  /// apart and judged by no rule.
  [[nodiscard]] bool Record(std::uint64_t cycle, bool missed) noexcept {
    // At rest (see quiet_) a met cycle moves only the counts of cycles: every rule's figure,
    // the distance and the verdict are what they were. Cycles come in increasing order, so a
    // monitor at rest is past the grace period.
    if (quiet_ && !missed) [[likely]] {
      ++judged_cycles_;
      live_releases_.store(releases_recorded(), std::memory_order_relaxed);
      live_cycles_.store(judged_cycles_, std::memory_order_relaxed);
      return aborted_;
    }
    return RecordInFull(cycle, missed);
  }

  /// PASS, FLAGGED or ABORTED for the cycles recorded so far (final once recording stops).
  [[nodiscard]] Verdict verdict() const noexcept;
  /// One entry per configured rule, in configuration order.
  [[nodiscard]] std::span<const RuleStatus> rules() const noexcept { return status_; }
  /// Judged cycles (after the grace period) and their misses.
  [[nodiscard]] std::uint64_t cycles_recorded() const noexcept { return judged_cycles_; }
  [[nodiscard]] std::uint64_t misses() const noexcept { return misses_; }
  [[nodiscard]] std::uint64_t max_consecutive_misses() const noexcept { return max_run_; }
  /// Every release recorded (grace period included) and the misses among them.
  [[nodiscard]] std::uint64_t releases_recorded() const noexcept { return grace_seen_ + judged_cycles_; }
  [[nodiscard]] std::uint64_t all_misses() const noexcept { return grace_misses_ + misses_; }
  /// Longest run of consecutive misses over every release, grace period included.
  [[nodiscard]] std::uint64_t max_consecutive_all_misses() const noexcept { return max_run_all_; }
  /// Percentage of all recorded releases missed, grace period included.
  [[nodiscard]] double all_miss_pct() const noexcept;
  /// Percentage of judged cycles missed (0 before the first judged cycle).
  [[nodiscard]] double miss_pct() const noexcept;
  /// Releases inside the grace period and how many of them missed (reported, not judged).
  [[nodiscard]] std::uint64_t grace_cycles_seen() const noexcept { return grace_seen_; }
  [[nodiscard]] std::uint64_t grace_misses() const noexcept { return grace_misses_; }
  /// Release at which policy abort fired, and the index (into rules()) of the rule that fired.
  [[nodiscard]] std::optional<std::uint64_t> abort_cycle() const noexcept { return abort_cycle_; }
  [[nodiscard]] std::optional<std::size_t> abort_rule() const noexcept { return abort_rule_; }
  [[nodiscard]] const QosConfig& config() const noexcept { return config_; }

  /// Minimum distance to failure over the rules; safe to call from any thread.
  [[nodiscard]] std::uint32_t DistanceToFailure() const noexcept {
    return live_distance_.load(std::memory_order_relaxed);
  }
  /// Live figures; safe to call from any thread.
  [[nodiscard]] LiveQos Live() const noexcept;

 private:
  struct Engine {
    RuleKind kind = RuleKind::kMkFirm;
    std::uint32_t k = 0;               // window rules: window length
    std::uint32_t allowed_misses = 0;  // window rules: k - m; consecutive: n
    std::uint32_t misses_in_window = 0;
    // Window rules: ring of the judged indices of the m most recent met cycles, oldest at
    // met_head. Pre-filled with -m..-1 (history before the first cycle counts as met).
    std::vector<std::int64_t> met_ring;
    std::size_t met_head = 0;
    double max_miss_pct = 0.0;      // ratio: the limit
    double ratio_per_cycle = 0.0;   // ratio without plan: P / (100 - P)
    double ratio_per_miss = 0.0;    // ratio without plan: 100 / (100 - P)
    std::uint64_t miss_budget = 0;  // ratio: fewest misses that fail it over the plan (0: none)
  };

  /// Record() of a cycle that may change a figure: a miss, or any cycle while not at rest.
  [[nodiscard]] bool RecordInFull(std::uint64_t cycle, bool missed) noexcept;
  /// Whether the figures are at rest after this judged cycle (quiet_).
  [[nodiscard]] bool AtRest() const noexcept;
  /// Puts back what cycles at rest did not write: the miss bits and the window rules' rings.
  void LeaveRest() noexcept;
  [[nodiscard]] bool Bit(std::uint64_t index) const noexcept;
  void SetBit(std::uint64_t index, bool value) noexcept;
  void MarkViolation(std::size_t rule, std::uint64_t cycle) noexcept;
  /// Window rules ((m,k)-firm, misses in window) after judged cycle `t`; true if violated now.
  bool UpdateWindowRule(Engine& engine, RuleStatus& status, std::uint64_t t, bool missed) noexcept;
  void UpdateRatioRule(const Engine& engine, RuleStatus& status, std::size_t rule,
                       std::uint64_t cycle) noexcept;
  [[nodiscard]] std::uint32_t RatioDistance(const Engine& engine) const noexcept;
  /// The ratio rule's distance under a plan: the misses its budget has left.
  [[nodiscard]] std::uint32_t BudgetDistance(const Engine& engine) const noexcept {
    const std::uint64_t left = engine.miss_budget > misses_ ? engine.miss_budget - misses_ : 0;
    return left >= kNeverFails ? kNeverFails : static_cast<std::uint32_t>(left);
  }

  QosConfig config_;
  std::vector<RuleStatus> status_;
  std::vector<Engine> engines_;
  std::vector<std::uint64_t> ring_words_;  // miss bits of the latest judged cycles
  std::uint64_t ring_mask_ = 0;            // capacity (a power of two, >= 64) - 1
  std::uint64_t judged_cycles_ = 0;
  std::uint64_t misses_ = 0;
  std::uint64_t run_ = 0;  // current run of consecutive judged misses
  std::uint64_t max_run_ = 0;
  std::uint64_t run_all_ = 0;  // current run of consecutive misses, grace period included
  std::uint64_t max_run_all_ = 0;
  std::uint64_t grace_seen_ = 0;
  std::uint64_t grace_misses_ = 0;
  std::uint64_t judged_plan_ = 0;  // planned_cycles - grace_cycles (0: no plan)
  bool aborted_ = false;
  // At rest: the last rest_after_ judged cycles met (the longest window, at least 1) and every
  // ratio rule holds under a plan. A met cycle then changes no rule's figure: windows hold no
  // miss and their distance is k - m + 1, a consecutive rule's run is 0, a holding planned
  // ratio keeps its budget. Such cycles skip the rules and write neither the miss bits nor the
  // met rings; LeaveRest rebuilds both, as the last rest_after_ cycles all met.
  bool quiet_ = false;
  bool unplanned_ratio_ = false;  // a ratio rule without a plan: its distance moves every cycle
  std::uint64_t met_run_ = 0;     // current run of consecutive judged met cycles
  std::uint64_t rest_after_ = 1;
  std::optional<std::uint64_t> abort_cycle_;
  std::optional<std::size_t> abort_rule_;

  std::atomic<std::uint64_t> live_releases_{0};
  std::atomic<std::uint64_t> live_all_misses_{0};
  std::atomic<std::uint64_t> live_cycles_{0};
  std::atomic<std::uint64_t> live_misses_{0};
  std::atomic<std::uint32_t> live_distance_{kNeverFails};
  std::atomic<Verdict> live_verdict_{Verdict::kPass};
};

}  // namespace hiltwin::qos
