#pragma once
// The openloop profile's duties sampled at 1 kHz over one period: the input every RELbot step
// benchmark drives the model with (a 4 kHz step uses sample k / 4), and the timed loop of
// RelbotModel::Step over them that those benchmarks share.

#include <vector>

#include "bench_stats.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_model.h"

namespace hiltwin::bench {

inline std::vector<app::Duty> OpenLoopDutiesAt1kHz() {
  const app::InputProfile profile = app::OpenLoopProfile();
  std::vector<app::Duty> samples(static_cast<std::size_t>(profile.period_s() * 1000.0));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i] = profile.At(static_cast<double>(i) * 1e-3);
  }
  return samples;
}

/// ns per RelbotModel::Step from a reset model, driven by `duty` (sample k / 4); the wheel
/// position is added to `sink` so that the steps stay observable.
inline double TimeRelbotSteps(app::RelbotModel& model, const std::vector<app::Duty>& duty,
                              long steps, volatile double& sink) {
  model.Reset();
  const auto start = BenchClock::now();
  for (long k = 0; k < steps; ++k) {
    const app::Duty& d = duty[static_cast<std::size_t>(k / 4) % duty.size()];
    model.Step(d.left, d.right);
  }
  const auto end = BenchClock::now();
  sink = sink + model.Outputs().wheel_left_m;
  return NsPer(start, end, steps);
}

}  // namespace hiltwin::bench
