#pragma once
// What the wire's two-side tests wait for: a bus whose peer is up (it has polled after its
// set-up, so its presence and heartbeat count).

#include <chrono>
#include <thread>

#include "hiltwin/io/wire_bus.h"

namespace hiltwin::io {

/// Polls every 5 ms until the peer is up, at most 10 s (a loaded machine's fork and set-up);
/// true when it is.
inline bool PollUntilUp(WireBus& bus) {
  using Wall = std::chrono::steady_clock;
  const Wall::time_point deadline = Wall::now() + std::chrono::seconds(10);
  while (bus.Poll().result != BusResult::kOk && Wall::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return bus.Poll().result == BusResult::kOk;
}

}  // namespace hiltwin::io
