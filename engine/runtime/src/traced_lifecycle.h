#pragma once
// Every lifecycle event of a session goes through here, so each state change is also a
// hiltwin:state_transition tracepoint (statemachine knows nothing of tracing). RT-safe: the
// machine's Handle is, and the tracepoint costs a branch when no session records.

#include <cstdint>

#include "hiltwin/statemachine/lifecycle.h"
#include "hiltwin/tracing/trace.h"

namespace hiltwin::runtime {

/// Offers `event`; `k` is the release it belongs to (the next one before the loop starts).
inline statemachine::Transition HandleTraced(statemachine::Lifecycle& lifecycle,
                                             statemachine::Event event, std::uint64_t k) noexcept {
  const statemachine::Transition t = lifecycle.Handle(event);
  if (t.outcome == statemachine::Outcome::kTransitioned) {
    HILTWIN_TRACE(state_transition, k, static_cast<std::uint8_t>(t.from),
                  static_cast<std::uint8_t>(t.to), static_cast<std::uint8_t>(event));
  }
  return t;
}

}  // namespace hiltwin::runtime
