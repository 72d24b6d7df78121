#include "hiltwin/scheduler/overrun_policy.h"

namespace hiltwin::scheduler {

std::uint64_t NextReleaseIndex(OverrunPolicy policy, std::uint64_t cycle,
                               kernel_glue::TimeNs end_ns, kernel_glue::TimeNs t0_ns,
                               kernel_glue::TimeNs period_ns) noexcept {
  const std::uint64_t next = cycle + 1;
  if (policy == OverrunPolicy::kCatchUp) return next;
  // Skip: the first release j with t0 + j·period ≥ end, i.e. j = ceil((end - t0) / period).
  const kernel_glue::TimeNs since_t0_ns = end_ns - t0_ns;
  if (since_t0_ns <= 0) return next;
  const auto first_not_passed =
      static_cast<std::uint64_t>((since_t0_ns + period_ns - 1) / period_ns);
  return first_not_passed > next ? first_not_passed : next;
}

std::string_view ToString(OverrunPolicy policy) noexcept {
  return policy == OverrunPolicy::kCatchUp ? "catch-up" : "skip";
}

std::optional<OverrunPolicy> ParseOverrunPolicy(std::string_view text) noexcept {
  if (text == "catch-up") return OverrunPolicy::kCatchUp;
  if (text == "skip") return OverrunPolicy::kSkip;
  return std::nullopt;
}

}  // namespace hiltwin::scheduler
