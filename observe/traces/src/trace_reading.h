#pragma once
// What the CTF reader and the timing-log reader share: the QoS rule as both inputs carry it
// (a kind code or name and integer parameters, the ratio in ppm) and the kind codes' range.

#include <cstdint>
#include <stdexcept>
#include <string>

#include "hiltwin/qos/rules.h"
#include "hiltwin/traces/timing_trace.h"
#include "hiltwin/tracing/trace_codes.h"

namespace hiltwin::analysis::detail {

/// Codes of qos::RuleKind; a code at or above it is from a newer hiltwin (or garbage).
inline constexpr std::uint64_t kRuleKindCount =
    static_cast<std::uint64_t>(qos::RuleKind::kMissRatio) + 1;

/// The rule hiltwin:qos_rule or a timing log's `rule=` line describes. `where` starts the
/// message of the TraceReadError thrown for an unknown kind or parameters the QoS monitor
/// would refuse (qos::Validate).
inline qos::RuleSpec DecodeRule(std::uint64_t kind, std::uint32_t m, std::uint32_t k,
                                std::uint32_t n, std::uint32_t max_miss_ppm,
                                const std::string& where) {
  if (kind >= kRuleKindCount) {
    throw TraceReadError(where + ": unknown QoS rule kind " + std::to_string(kind) +
                         " (known: 0 mk_firm to " + std::to_string(kRuleKindCount - 1) +
                         " miss_ratio); was it written by a newer hiltwin?");
  }
  qos::RuleSpec rule;
  rule.kind = static_cast<qos::RuleKind>(kind);
  rule.m = m;
  rule.k = k;
  rule.n = n;
  rule.max_miss_pct = static_cast<double>(max_miss_ppm) / tracing::kPpmPerPercent;
  try {
    qos::Validate(rule);
  } catch (const std::invalid_argument& e) {
    throw TraceReadError(where + ": " + e.what());
  }
  return rule;
}

}  // namespace hiltwin::analysis::detail
