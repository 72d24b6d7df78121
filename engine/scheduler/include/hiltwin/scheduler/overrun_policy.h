#pragma once
/// What the executive does after a cycle that ran past one or more later release times.
///
/// - kCatchUp: run every release, back to back, until the loop is on time again; a release
///   that has passed is not slept for (clock_nanosleep on a passed time still waits for a
///   timer interrupt: ~12 µs on a VM). Model time stays equal to wall time (the twin
///   integrates every step); the late cycles are misses whenever they end after their own
///   deadline.
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
/// Inline: the loop asks every cycle, and under catch-up the answer is just cycle + 1.
[[nodiscard]] inline std::uint64_t NextReleaseIndex(OverrunPolicy policy, std::uint64_t cycle,
                                                    kernel_glue::TimeNs end_ns,
                                                    kernel_glue::TimeNs t0_ns,
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

/// "catch-up" / "skip".
[[nodiscard]] std::string_view ToString(OverrunPolicy policy) noexcept;
/// Parses "catch-up" or "skip"; std::nullopt for anything else.
[[nodiscard]] std::optional<OverrunPolicy> ParseOverrunPolicy(std::string_view text) noexcept;

}  // namespace hiltwin::scheduler
