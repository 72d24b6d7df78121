#pragma once
// Private to the analysis module: why a late cycle was late, read from the kernel's events
// (kernel_events.h). The index is built once, O(events log events); each question is a few
// binary searches plus the events inside the window, so traces of millions of events and
// thousands of late cycles stay quick.
//
// The rules (docs and the report's readers rely on them):
//  * The loop thread's state is followed through sched_switch (in: running on that CPU; out
//    with prev_state 0: runnable, preempted; out otherwise: sleeping) and sched_wakeup
//    (sleeping: runnable on target_cpu). Before its first event the state is unknown and the
//    CPU is the loop's pin (LoopThread::cpu); an unknown stretch counts as runnable.
//  * Window: [release, end of the step] ([release, wake] for a wake-up-only notable cycle).
//    Inside it the loop wants a CPU except while it sleeps voluntarily after its wake-up (an
//    I/O wait): the sleep it is in at the release is the wait for this release, so a late
//    wake-up is part of the delay.
//  * preempted: another thread (not pid 0, not the loop) ran on the loop's CPU while the loop
//    was runnable; duration = that overlap less the interrupts taken meanwhile (theirs, not
//    the thread's), summed per thread. Policy and rt priority from kernel_tasks.csv, else
//    from the prio of its sched_switch (< 0: SCHED_DEADLINE; < 100: "SCHED_FIFO/RR" with rt
//    priority 99 − prio; otherwise SCHED_OTHER).
//  * non_preemptible: the same, for a thread whose prio at its sched_switch ranks below a
//    real-time loop's (SCHED_OTHER, or a lower rt priority): the scheduler would have
//    preempted it at the wake-up, so it held the CPU in a kernel section that could not be
//    preempted (all of the kernel on PREEMPT_NONE). The evidence names the kernel's
//    preemption model as recorded (KernelTrace::preemption_model).
//  * interrupt: irq_handler, local_timer and softirq entry→exit on the loop's CPU while the
//    loop wanted it; duration = overlap, summed per name (handler, "local_timer", vector).
//    Entries or exits without their partner are dropped and counted in the warnings.
//  * page_fault: page_fault_user events of the loop thread inside the window. Each is charged
//    the time to the next kernel event on its CPU, at most kPageFaultChargeMaxNs (100 µs: a
//    transparent huge page is zeroed in about that); when that next event is the loop blocking
//    (a major fault waiting for I/O), the blocked time inside the window instead.
//  * own_compute: the step's compute above the run's compute p99.9; duration = compute −
//    compute p50, less the time the candidates above took inside the step (an interrupt
//    or a fault during the step is theirs, not the model's).
//  * invisible: excess = response − p50 response (wake-up-only: latency − p50 latency). When
//    the candidates above explain less than half of it (or nothing at all), the rest is
//    invisible to the guest (hypervisor steal, SMI; below 100 µs on an idle CPU the evidence
//    also names a deep idle state's exit); duration = excess − explained.
//  * Dominant cause = the candidate with the largest duration (ties: the order above).
//  * backlog (decided by the caller from the cycles, BacklogBehind): a cycle released before
//    its predecessor's end waited that long behind it. Its own part, [predecessor's end, end]
//    with excess = excess − wait, is attributed as above; unless that cause outlasts the
//    wait, the cycle is the backlog of the stall its predecessor was (or was behind), and
//    carries that stall's k, class and culprit.
//  * not_recorded: the window lies outside the kernel recording, or on a CPU it did not record.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/jitter/jitter_report.h"
#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis::detail {

/// Longest time one page fault is charged when the loop did not block in it.
inline constexpr std::int64_t kPageFaultChargeMaxNs = 100'000;

/// The stretch of one cycle to explain, and what is normal for the run.
struct CauseWindow {
  std::int64_t begin_ns = 0;       ///< the release
  std::int64_t end_ns = 0;         ///< end of the step (wake-up-only: the wake)
  std::int64_t step_begin_ns = 0;  ///< start of the step
  std::int64_t step_end_ns = 0;    ///< end of the step
  std::int64_t compute_ns = 0;
  std::int64_t excess_ns = 0;      ///< the delay: response (latency) above its p50
  bool wake_only = false;          ///< only the wake-up was late: no own-compute candidate
  std::int64_t compute_p50_ns = 0;
  std::int64_t compute_p999_ns = 0;
};

struct KernelIndex;

class CauseAttributor {
 public:
  /// Indexes `kernel` for the thread `loop.tid` (pinned, or first seen, on `loop.cpu`).
  CauseAttributor(const KernelTrace& kernel, const LoopThread& loop);
  ~CauseAttributor();
  CauseAttributor(const CauseAttributor&) = delete;
  CauseAttributor& operator=(const CauseAttributor&) = delete;

  /// The dominant cause of the delay in `window`, with its evidence line.
  [[nodiscard]] Cause Attribute(const CauseWindow& window) const;
  /// What the index had to drop or guess (unmatched interrupt entries/exits, ...).
  [[nodiscard]] std::vector<std::string> Warnings() const;

 private:
  std::unique_ptr<const KernelIndex> index_;
};

/// A cycle that waited `waited_ns` behind its predecessor, whose delay was the stall of cycle
/// `stall_k` with the cause `stall` (never itself a backlog).
[[nodiscard]] Cause BacklogBehind(const Cause& stall, std::uint64_t stall_k,
                                  std::int64_t waited_ns);

/// Per class, the notable cycles it is dominant in and the misses among them, a backlog
/// cycle under its stall's class and culprit; most first.
[[nodiscard]] std::vector<CauseCount> RankCauses(const std::vector<NotableCycle>& notable);

/// How a culprit is named in the ranking: "rt-hog (pid 4242)", "local_timer", "CPU 1".
[[nodiscard]] std::string CulpritName(const Cause& cause);

}  // namespace hiltwin::analysis::detail
