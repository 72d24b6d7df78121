#pragma once
/// Deadline constraints the QoS monitor checks, how they are written on the command line, and
/// the documented defaults (docs/qos.md). Everything here runs at configuration time and may
/// throw std::invalid_argument with a message that says what was wrong and what is accepted.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::qos {

/// Longest window (in cycles) a window rule may span: 25 s at 4 kHz. The bit ring and the
/// met-cycle queue are sized by it, so it bounds memory (about 0.8 MB per rule at the limit).
constexpr std::uint32_t kMaxWindowCycles = 100'000;

/// The kinds of deadline constraint.
enum class RuleKind : std::uint8_t {
  kMkFirm,             ///< at least m deadlines met in any k consecutive cycles
  kMissesInWindow,     ///< at most n deadlines missed in any k consecutive cycles
  kConsecutiveMisses,  ///< at most n consecutive misses
  kMissRatio,          ///< overall miss ratio below max_miss_pct percent (thesis §3.8.2: 1 %)
};

/// One constraint. Fields that a kind does not use stay 0.
struct RuleSpec {
  RuleKind kind = RuleKind::kMkFirm;
  std::uint32_t m = 0;        ///< kMkFirm: deadlines that must be met per window
  std::uint32_t k = 0;        ///< kMkFirm, kMissesInWindow: window length in cycles
  std::uint32_t n = 0;        ///< kMissesInWindow, kConsecutiveMisses: misses allowed
  double max_miss_pct = 0.0;  ///< kMissRatio: the ratio must stay strictly below this

  friend bool operator==(const RuleSpec&, const RuleSpec&) = default;
};

/// "mk_firm", "misses_in_window", "max_consecutive_misses", "miss_ratio" (report `kind`).
[[nodiscard]] const char* ToString(RuleKind kind) noexcept;

/// Human-readable rule, e.g. "(9,10)-firm", "at most 2 misses in any 10 cycles",
/// "at most 3 consecutive misses", "miss ratio < 1 %".
[[nodiscard]] std::string Describe(const RuleSpec& rule);

/// Throws std::invalid_argument when the rule's parameters are out of range.
void Validate(const RuleSpec& rule);

/// Checked constructors; each throws std::invalid_argument naming the bad value.
[[nodiscard]] RuleSpec MakeMkRule(std::uint32_t m, std::uint32_t k);
[[nodiscard]] RuleSpec MakeMissesInWindowRule(std::uint32_t n, std::uint32_t k);
[[nodiscard]] RuleSpec MakeConsecutiveMissesRule(std::uint32_t n);
[[nodiscard]] RuleSpec MakeMissRatioRule(double max_miss_pct);

/// Parses "M:K" (e.g. "9:10", the `--qos` flag) into a kMkFirm rule. The message of the
/// std::invalid_argument it throws quotes the text and shows the accepted form; the caller
/// prefixes where the text came from (flag or file:line).
[[nodiscard]] RuleSpec ParseMkRule(std::string_view text);
/// Parses "N:K" (at most N misses in any K cycles) into a kMissesInWindow rule.
[[nodiscard]] RuleSpec ParseMissesInWindowRule(std::string_view text);

/// The documented defaults for the RELbot case (a 4 kHz twin under a 1 kHz controller):
/// miss ratio < 1 % (thesis §3.8.2) and the (3,4)-firm rule, i.e. DefaultRulesFor(4000, 1000).
[[nodiscard]] std::vector<RuleSpec> DefaultRules();

/// Defaults for any rate pair: miss ratio < 1 % and (k-1, k)-firm with
/// k = max(2, floor(twin_rate_hz / controller_rate_hz)): at most one missed twin update in any
/// span of one controller period (docs/qos.md explains why). Throws std::invalid_argument when
/// a rate is not finite and positive.
[[nodiscard]] std::vector<RuleSpec> DefaultRulesFor(double twin_rate_hz, double controller_rate_hz);

}  // namespace hiltwin::qos
