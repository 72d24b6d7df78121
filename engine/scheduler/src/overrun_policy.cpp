#include "hiltwin/scheduler/overrun_policy.h"

namespace hiltwin::scheduler {

std::string_view ToString(OverrunPolicy policy) noexcept {
  return policy == OverrunPolicy::kCatchUp ? "catch-up" : "skip";
}

std::optional<OverrunPolicy> ParseOverrunPolicy(std::string_view text) noexcept {
  if (text == "catch-up") return OverrunPolicy::kCatchUp;
  if (text == "skip") return OverrunPolicy::kSkip;
  return std::nullopt;
}

}  // namespace hiltwin::scheduler
