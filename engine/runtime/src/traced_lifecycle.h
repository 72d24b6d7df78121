#pragma once
// Every lifecycle event of a session goes through here, so each state change is also a
// hiltwin:state_transition tracepoint (lifecycle knows nothing of tracing). RT-safe: the
// machine's Handle is, and the tracepoint costs a branch when no session records.

#include <cstdint>

#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/tracing/trace.h"

namespace hiltwin::runtime {

/// Offers `event`; `k` is the release it belongs to (the next one before the loop starts).
inline lifecycle::Transition HandleTraced(lifecycle::Lifecycle& lifecycle,
                                             lifecycle::Event event, std::uint64_t k) noexcept {
  const lifecycle::Transition t = lifecycle.Handle(event);
  if (t.outcome == lifecycle::Outcome::kTransitioned) {
    HILTWIN_TRACE(state_transition, k, static_cast<std::uint8_t>(t.from),
                  static_cast<std::uint8_t>(t.to), static_cast<std::uint8_t>(event));
  }
  return t;
}

}  // namespace hiltwin::runtime
