#pragma once
// Constructed machines for the tuning tests: every figure chosen so the bounds are exact.

#include <cstdint>

#include "hiltwin/tuning/tuning.h"

namespace hiltwin::analysis::fixtures {

/// A machine with the given loop overhead, step compute (mean and p99.9) and wake-up latency
/// p99.9, measured at 1 kHz and 4 kHz (the worst at 4 kHz).
inline TimingMeasurements Machine(double overhead_ns, double compute_mean_ns,
                                  std::int64_t compute_p999_ns, std::int64_t latency_p999_ns) {
  TimingMeasurements m;
  m.loop_overhead_ns = overhead_ns;
  m.step_compute.count = 10'000;
  m.step_compute.mean_ns = compute_mean_ns;
  m.step_compute.p99_ns = compute_p999_ns;
  m.step_compute.p999_ns = compute_p999_ns;
  m.step_compute.max_ns = compute_p999_ns + 1'000;
  LatencyAtRate low{1000.0, {}};
  low.wake_latency.p99_ns = latency_p999_ns / 4;
  low.wake_latency.p999_ns = latency_p999_ns / 2;
  low.wake_latency.max_ns = latency_p999_ns;
  LatencyAtRate high{4000.0, {}};
  high.wake_latency.p99_ns = latency_p999_ns / 2;
  high.wake_latency.p999_ns = latency_p999_ns;
  high.wake_latency.max_ns = 2 * latency_p999_ns;
  m.wake_latency = {low, high};
  return m;
}

/// The thesis example (§3.8.2): overhead 35 us, compute 85 us, a small latency.
inline TimingMeasurements ThesisMachine() { return Machine(35'000.0, 85'000.0, 90'000, 10'000); }

}  // namespace hiltwin::analysis::fixtures
