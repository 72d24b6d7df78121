#include "hiltwin/qos/rules.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <system_error>

namespace hiltwin::qos {
namespace {

std::string Quote(std::string_view text) { return "'" + std::string(text) + "'"; }

// Parses "A:B" (two whole numbers, nothing else) into first and second.
bool ParsePair(std::string_view text, std::uint32_t& first, std::uint32_t& second) {
  const auto colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0 || colon + 1 >= text.size()) return false;
  const auto parse = [](std::string_view part, std::uint32_t& value) {
    const char* begin = part.data();
    const char* end = part.data() + part.size();
    const auto [ptr, ec] = std::from_chars(begin, end, value);
    return ec == std::errc() && ptr == end;
  };
  return parse(text.substr(0, colon), first) && parse(text.substr(colon + 1), second);
}

const std::string kMkForm =
    "expected M:K (at least M of any K consecutive deadlines met), whole "
    "numbers with 1 <= M <= K <= " +
    std::to_string(kMaxWindowCycles) + ", e.g. 9:10";
const std::string kNkForm =
    "expected N:K (at most N misses in any K consecutive cycles), whole "
    "numbers with 0 <= N < K <= " +
    std::to_string(kMaxWindowCycles) + ", e.g. 1:10";

std::string FormatPct(double pct) {
  std::string text = std::to_string(pct);  // fixed, 6 decimals; trim trailing zeros
  while (!text.empty() && text.back() == '0') text.pop_back();
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text;
}

}  // namespace

const char* ToString(RuleKind kind) noexcept {
  switch (kind) {
    case RuleKind::kMkFirm:
      return "mk_firm";
    case RuleKind::kMissesInWindow:
      return "misses_in_window";
    case RuleKind::kConsecutiveMisses:
      return "max_consecutive_misses";
    case RuleKind::kMissRatio:
      return "miss_ratio";
  }
  return "unknown";
}

std::string Describe(const RuleSpec& rule) {
  switch (rule.kind) {
    case RuleKind::kMkFirm:
      return "(" + std::to_string(rule.m) + "," + std::to_string(rule.k) + ")-firm";
    case RuleKind::kMissesInWindow:
      return "at most " + std::to_string(rule.n) + " misses in any " + std::to_string(rule.k) +
             " cycles";
    case RuleKind::kConsecutiveMisses:
      return "at most " + std::to_string(rule.n) + " consecutive misses";
    case RuleKind::kMissRatio:
      return "miss ratio < " + FormatPct(rule.max_miss_pct) + " %";
  }
  return "unknown rule";
}

void Validate(const RuleSpec& rule) {
  const auto window = [&](const char* what) {
    if (rule.k == 0 || rule.k > kMaxWindowCycles) {
      throw std::invalid_argument(
          std::string(what) + ": window K = " + std::to_string(rule.k) +
          " is out of range; use 1 <= K <= " + std::to_string(kMaxWindowCycles));
    }
  };
  switch (rule.kind) {
    case RuleKind::kMkFirm:
      window("(m,k) rule");
      if (rule.m == 0 || rule.m > rule.k) {
        throw std::invalid_argument("(m,k) rule (" + std::to_string(rule.m) + "," +
                                    std::to_string(rule.k) + "): M must satisfy 1 <= M <= K");
      }
      return;
    case RuleKind::kMissesInWindow:
      window("misses-in-window rule");
      if (rule.n >= rule.k) {
        throw std::invalid_argument("misses-in-window rule " + std::to_string(rule.n) + ":" +
                                    std::to_string(rule.k) +
                                    ": N must be below K (N >= K can never be violated)");
      }
      return;
    case RuleKind::kConsecutiveMisses:
      if (rule.n == UINT32_MAX) {
        throw std::invalid_argument("consecutive-misses rule: N = " + std::to_string(rule.n) +
                                    " is too large; use N < " + std::to_string(UINT32_MAX));
      }
      return;
    case RuleKind::kMissRatio:
      if (!std::isfinite(rule.max_miss_pct) || rule.max_miss_pct <= 0.0 ||
          rule.max_miss_pct > 100.0) {
        throw std::invalid_argument("miss-ratio rule: " + std::to_string(rule.max_miss_pct) +
                                    " % is out of range; use a percentage with 0 < P <= 100, "
                                    "e.g. 1 (the thesis's rule of thumb)");
      }
      return;
  }
  throw std::invalid_argument("unknown rule kind");
}

RuleSpec MakeMkRule(std::uint32_t m, std::uint32_t k) {
  RuleSpec rule{.kind = RuleKind::kMkFirm, .m = m, .k = k};
  Validate(rule);
  return rule;
}

RuleSpec MakeMissesInWindowRule(std::uint32_t n, std::uint32_t k) {
  RuleSpec rule{.kind = RuleKind::kMissesInWindow, .k = k, .n = n};
  Validate(rule);
  return rule;
}

RuleSpec MakeConsecutiveMissesRule(std::uint32_t n) {
  RuleSpec rule{.kind = RuleKind::kConsecutiveMisses, .n = n};
  Validate(rule);
  return rule;
}

RuleSpec MakeMissRatioRule(double max_miss_pct) {
  RuleSpec rule{.kind = RuleKind::kMissRatio, .max_miss_pct = max_miss_pct};
  Validate(rule);
  return rule;
}

RuleSpec ParseMkRule(std::string_view text) {
  std::uint32_t m = 0;
  std::uint32_t k = 0;
  if (!ParsePair(text, m, k)) {
    throw std::invalid_argument(Quote(text) + " is not an (m,k) rule: " + kMkForm);
  }
  if (k == 0 || k > kMaxWindowCycles || m == 0 || m > k) {
    throw std::invalid_argument(Quote(text) + " is out of range: " + kMkForm);
  }
  return MakeMkRule(m, k);
}

RuleSpec ParseMissesInWindowRule(std::string_view text) {
  std::uint32_t n = 0;
  std::uint32_t k = 0;
  if (!ParsePair(text, n, k)) {
    throw std::invalid_argument(Quote(text) + " is not a misses-in-window rule: " + kNkForm);
  }
  if (k == 0 || k > kMaxWindowCycles || n >= k) {
    throw std::invalid_argument(Quote(text) + " is out of range: " + kNkForm);
  }
  return MakeMissesInWindowRule(n, k);
}

std::vector<RuleSpec> DefaultRules() { return DefaultRulesFor(4000.0, 1000.0); }

std::vector<RuleSpec> DefaultRulesFor(double twin_rate_hz, double controller_rate_hz) {
  if (!std::isfinite(twin_rate_hz) || twin_rate_hz <= 0.0 || !std::isfinite(controller_rate_hz) ||
      controller_rate_hz <= 0.0) {
    throw std::invalid_argument("default QoS rules need finite positive rates, got twin " +
                                std::to_string(twin_rate_hz) + " Hz and controller " +
                                std::to_string(controller_rate_hz) + " Hz");
  }
  // A small tolerance so that 4000/1000 computed in floating point still gives exactly 4.
  const double ratio = std::floor(twin_rate_hz / controller_rate_hz + 1e-9);
  const double clamped = std::min(std::max(ratio, 2.0), static_cast<double>(kMaxWindowCycles));
  const auto k = static_cast<std::uint32_t>(clamped);
  return {MakeMissRatioRule(1.0), MakeMkRule(k - 1, k)};
}

}  // namespace hiltwin::qos
