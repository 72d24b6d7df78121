#pragma once
// The openloop profile's duties sampled at 1 kHz over one period: the input every RELbot step
// benchmark drives the model with (a 4 kHz step uses sample k / 4).

#include <vector>

#include "hiltwin/relbot/input_profile.h"

namespace hiltwin::bench {

inline std::vector<app::Duty> OpenLoopDutiesAt1kHz() {
  const app::InputProfile profile = app::OpenLoopProfile();
  std::vector<app::Duty> samples(static_cast<std::size_t>(profile.period_s() * 1000.0));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i] = profile.At(static_cast<double>(i) * 1e-3);
  }
  return samples;
}

}  // namespace hiltwin::bench
