#pragma once
/// What another thread may ask of a running session (RunSession::Post): signal forwarding, the
/// telemetry sinks' command topics, tests. Carried to the loop by a lockfree::CommandQueue.

#include <cstdint>

namespace hiltwin::runtime {

enum class SessionCommand : std::uint8_t { kStop, kPause, kResume };

}  // namespace hiltwin::runtime
