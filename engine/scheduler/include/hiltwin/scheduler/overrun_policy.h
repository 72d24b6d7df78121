#pragma once
/// What the executive does after a cycle that ran past one or more later release times.
///
/// - kCatchUp: run every release, back to back, until the loop is on time again. Model time
///   stays equal to wall time (the twin integrates every step); the late cycles are misses
///   whenever they end after their own deadline.
/// - kSkip: re-anchor to the first release at or after the end of the late cycle. The
///   releases that passed while the loop was busy never run and each counts as a deadline
///   miss; phase is kept (releases stay on the t0 + k·period grid), model time falls behind.
///
/// Either way releases stay on the absolute grid t0 + k·period: nothing is ever re-timed
/// from "now", so the loop cannot drift (ros2_control's sleeping policies, OROCOS ORO_WAIT_ABS).

#include <cstdint>
#include <optional>
#include <string_view>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::scheduler {

enum class OverrunPolicy { kCatchUp, kSkip };

/// Index of the next release to run after cycle `cycle` ended at `end_ns`.
/// Releases with index in (cycle, result) were skipped (only ever non-empty for kSkip).
[[nodiscard]] std::uint64_t NextReleaseIndex(OverrunPolicy policy, std::uint64_t cycle,
                                             kernel_glue::TimeNs end_ns,
                                             kernel_glue::TimeNs t0_ns,
                                             kernel_glue::TimeNs period_ns) noexcept;

/// "catch-up" / "skip".
[[nodiscard]] std::string_view ToString(OverrunPolicy policy) noexcept;
/// Parses "catch-up" or "skip"; std::nullopt for anything else.
[[nodiscard]] std::optional<OverrunPolicy> ParseOverrunPolicy(std::string_view text) noexcept;

}  // namespace hiltwin::scheduler
