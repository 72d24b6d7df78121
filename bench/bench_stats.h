#pragma once
// Figures the benchmarks share: the median and the minimum over rounds (rounds alternate
// between a figure and its peer, so both see the same machine), and the RELbot's openloop
// duties as the benches drive the model with them.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace hiltwin::bench {

inline double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

inline double MinOf(const std::vector<double>& values) {
  return *std::min_element(values.begin(), values.end());
}

}  // namespace hiltwin::bench
