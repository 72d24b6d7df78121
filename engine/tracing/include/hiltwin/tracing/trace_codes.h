#pragma once
/// The integer codes the `hiltwin` tracepoints and the timing log carry, beside those that are
/// another module's enums (qos::RuleKind for qos_rule.kind, lifecycle::State and
/// lifecycle::Event for state_transition). Readers map them back and refuse unknown codes.

#include <cstdint>

namespace hiltwin::tracing {

/// hiltwin:io_error.kind: what the board exchange of a cycle reported.
enum class IoErrorKind : std::uint8_t {
  kHeldInputs = 0,   ///< a corrupted or missed frame: the task held its inputs
  kFault = 1,        ///< an I/O fault: the run stops
  kPeerAbsent = 2,   ///< wire: no peer process attached this cycle
  kPulseLimit = 3,   ///< an encoder changed by more than one period's pulses
};
inline constexpr std::uint8_t kIoErrorKindCount = 4;

/// "held_inputs", "fault", "peer_absent", "pulse_limit"; "unknown" otherwise.
[[nodiscard]] constexpr const char* ToString(IoErrorKind kind) noexcept {
  switch (kind) {
    case IoErrorKind::kHeldInputs: return "held_inputs";
    case IoErrorKind::kFault: return "fault";
    case IoErrorKind::kPeerAbsent: return "peer_absent";
    case IoErrorKind::kPulseLimit: return "pulse_limit";
  }
  return "unknown";
}

/// hiltwin:qos_rule.max_miss_ppm: a miss-ratio limit in parts per million (1 % = 10000).
inline constexpr double kPpmPerPercent = 10'000.0;

}  // namespace hiltwin::tracing
