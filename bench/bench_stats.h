#pragma once
// Figures the benchmarks share: the median, the minimum and the spread over rounds (rounds
// alternate between a figure and its peer, so both see the same machine), nanoseconds per item,
// and the step benchmarks' two arguments. The RELbot's openloop duties and the timed RELbot step loop
// are in relbot_duty_samples.h.

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hiltwin::bench {

inline double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

inline double MinOf(const std::vector<double>& values) {
  return *std::min_element(values.begin(), values.end());
}

/// A figure over rounds: its median and the range it moved in, so a reader sees how far one
/// round's figure can be trusted on a busy machine.
struct Spread {
  double median = 0.0;
  double min = 0.0;
  double max = 0.0;
};

/// The spread of `values`; throws std::invalid_argument when there are none.
inline Spread SpreadOf(const std::vector<double>& values) {
  if (values.empty()) throw std::invalid_argument("SpreadOf: no values");
  return {Median(values), MinOf(values), *std::max_element(values.begin(), values.end())};
}

/// "112.6 ns (98.1 to 140.2)": the median, then the minimum and maximum, `decimals` after the
/// point ("to", since either may be negative).
inline std::string FormatSpread(const Spread& spread, const char* unit, int decimals = 1) {
  char text[96];
  std::snprintf(text, sizeof text, "%.*f %s (%.*f to %.*f)", decimals, spread.median, unit,
                decimals, spread.min, decimals, spread.max);
  return text;
}

using BenchClock = std::chrono::steady_clock;

/// Nanoseconds per item between two readings of the clock.
inline double NsPer(BenchClock::time_point start, BenchClock::time_point end, long items) {
  return std::chrono::duration<double, std::nano>(end - start).count() /
         static_cast<double>(items);
}

struct StepsAndRounds {
  long steps = 1'000'000;  ///< timed steps per round and variant
  int rounds = 9;          ///< rounds; each runs every variant once, in turn
};

/// The step benchmarks' arguments, [steps_per_round] [rounds] (argv[1], argv[2]); nothing, with
/// the usage on stderr, when either is not a positive number. `more` names further arguments.
inline std::optional<StepsAndRounds> ParseStepsAndRounds(int argc, char** argv,
                                                         const char* more = "") {
  StepsAndRounds parsed;
  if (argc > 1) parsed.steps = std::strtol(argv[1], nullptr, 10);
  if (argc > 2) parsed.rounds = std::atoi(argv[2]);
  if (parsed.steps <= 0 || parsed.rounds <= 0) {
    std::fprintf(stderr, "usage: %s [steps_per_round > 0] [rounds > 0]%s\n", argv[0], more);
    return std::nullopt;
  }
  return parsed;
}

}  // namespace hiltwin::bench
