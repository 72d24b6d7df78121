#pragma once
// Private to the analysis module: the jitter report's figures from a trace's cycles, fed
// exactly as the executive feeds the run report's (engine/scheduler/src/executive.cpp Account) and
// counted exactly as the QoS ledger counts misses (engine/runtime/src/cycle_runner.cpp RecordQos).

#include <cstdint>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/scheduler/timing_stats.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis::detail {

/// The four TimingStats of the run report, replayed from the trace.
struct CycleStats {
  scheduler::TimingStats latency;        ///< wake − release, when the loop slept at the release
  scheduler::TimingStats period_jitter;  ///< start-to-start − period, between neighbours
  scheduler::TimingStats compute;        ///< end − start − io
  scheduler::TimingStats response;       ///< end − release
  /// Per cycle of the trace: whether its latency went into `latency` (the loop was asleep at
  /// the release; the executive leaves catch-up cycles out).
  std::vector<bool> latency_recorded;
  /// Places where k jumped by more than the previous cycle's skipped releases (events lost),
  /// and how many cycles the jumps left out.
  std::uint64_t gaps = 0;
  std::uint64_t cycles_missing = 0;
};

/// Replays the executive's accounting over every cycle of the trace.
[[nodiscard]] CycleStats AccumulateCycleStats(const TimingTrace& trace);

/// The report's view of one TimingStats: summary and non-empty bins.
[[nodiscard]] Distribution MakeDistribution(const char* name, const scheduler::TimingStats& stats);

/// Misses over the judged releases (each judged cycle's own release, then its skipped ones),
/// bursts and the window rules' windows. Windows slide over the sequence of judged releases,
/// as the QoS monitor's do (a paused stretch in between does not count).
[[nodiscard]] MissClusters ClusterMisses(const TimingTrace& trace);

}  // namespace hiltwin::analysis::detail
