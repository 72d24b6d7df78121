#pragma once
// Private to runs: the measuring half of `hiltwin tune` (tune.h) and the typed options every
// one of its runs is built from.

#include <vector>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/tune.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runs/twin_run.h"
#include "hiltwin/scheduler/timing_stats.h"
#include "hiltwin/tuning/tuning_report.h"

namespace hiltwin::app {

/// `run`'s options for one of tune's runs of the twin: the mock board playing --input at the
/// controller rate, no progress line (tune draws its own), tune's priority and CPUs.
[[nodiscard]] TwinRunOptions TwinOptionsFor(const TuneOptions& o, double rate_hz, double seconds,
                                            bool virtual_clock);

/// The model step's cost: the summary (the run report's percentiles) and every sample in the
/// order taken, for the virtual clock to replay.
struct StepCost {
  scheduler::TimingSummary summary;
  std::vector<kernel_glue::TimeNs> samples_ns;
};

/// Times RelbotModel::Step alone (twin's parameters and integrator, the step of `rate_hz`),
/// `kStepWarmup` steps and then `kStepSamples` timed ones, driven by twin's input profile so
/// every branch of the castor friction is taken. Only the configuration of `twin` is used.
[[nodiscard]] StepCost MeasureStepCost(const Twin& twin, double rate_hz);

/// An injected step cost: one sample, every figure equal to it.
[[nodiscard]] StepCost InjectedStepCost(kernel_glue::TimeNs ns);

/// A summary whose every figure is `ns` (an injected cost).
[[nodiscard]] scheduler::TimingSummary ConstantSummary(kernel_glue::TimeNs ns);

/// The loop's own work per cycle: the twin run flat out on the virtual clock for
/// `kOverheadCycles` cycles (executive, board exchange, QoS ledger, tracepoints, the step),
/// wall time per cycle minus the step's mean cost. Never below 0.
[[nodiscard]] double MeasureLoopOverheadNs(const TwinRunOptions& t, double step_mean_ns);

/// Wake-up latency at t's rate on the real clock: a session of t's duration whose task does
/// nothing, so only the OS's share is measured, at tune's priority and CPUs.
[[nodiscard]] scheduler::TimingSummary MeasureWakeLatency(const TwinRunOptions& t);

/// The doctor findings that decide timing (CPU governor, SCHED_FIFO, virtualisation, steal
/// time) that are not ok, with what to do.
[[nodiscard]] std::vector<analysis::TuneWarning> MachineWarnings();

}  // namespace hiltwin::app
