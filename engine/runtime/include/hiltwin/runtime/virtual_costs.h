#pragma once
/// What a cycle costs on the virtual clock. The virtual clock runs the identical loop as fast
/// as possible, so by itself every step takes no time and no deadline is ever missed. Given
/// costs, it charges them: each sleep that waits wakes late by the next wake-up latency, each
/// step spends its compute time. A virtual run then shows the misses a real one with those
/// costs would, deterministically (`hiltwin tune --clock virtual` validates rates this way,
/// with measured or injected costs). Unlike --inject-overrun, which adds a fault to chosen
/// cycles, these model the machine on every cycle.

#include <vector>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::runtime {

/// Cost tables, replayed cyclically. Empty tables cost nothing. Values are >= 0.
struct VirtualCycleCosts {
  /// The n-th sleep that waits (the loop was idle at the release) wakes
  /// wake_latency_ns[n % size] after it. A release already passed wakes at once, as the real
  /// clock_nanosleep does.
  std::vector<kernel_glue::TimeNs> wake_latency_ns;
  /// Cycle k's step spends compute_ns[k % size] after the task's own step (k: release index).
  std::vector<kernel_glue::TimeNs> compute_ns;

  [[nodiscard]] bool empty() const noexcept {
    return wake_latency_ns.empty() && compute_ns.empty();
  }
};

}  // namespace hiltwin::runtime
