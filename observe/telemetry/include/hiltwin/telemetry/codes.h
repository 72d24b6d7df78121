#pragma once
/// The verdict and the lifecycle state as numbers, for tools that plot numbers only
/// (PlotJuggler drops strings): Timing's verdict_code and state_code, the JSON record's
/// verdict_code and state_code. The codes are the enums' own values, so the enums are the one
/// place that defines them; ros2/hiltwin_msgs/msg/Timing.msg's constants and docs/telemetry.md's
/// table repeat them, and a test holds both to the enums.

#include <cstdint>

#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/qos/monitor.h"

namespace hiltwin::telemetry {

/// PASS 0, FLAGGED 1, ABORTED 2.
[[nodiscard]] constexpr std::uint8_t VerdictCode(qos::Verdict verdict) noexcept {
  return static_cast<std::uint8_t>(verdict);
}

/// init 0, ready 1, run 2, paused 3, stopping 4, stopped 5, error 6, safe_stop 7.
[[nodiscard]] constexpr std::uint8_t StateCode(lifecycle::State state) noexcept {
  return static_cast<std::uint8_t>(state);
}

}  // namespace hiltwin::telemetry
