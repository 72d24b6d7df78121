#pragma once
// Private to the analysis module: what else ran on the loop's CPUs, as slices for the Perfetto
// export, so the culprit of a late cycle is seen beside the loop's cycles in ui.perfetto.dev.
//
// Bounded: only the recorded CPUs the loop thread used (its pin, and every CPU a sched_switch
// moved it on or off), only the stretch [from, to] of the traced cycles; the idle task and the
// loop thread get no slices. So there is at most one slice per sched_switch and per interrupt
// recorded on those CPUs in that stretch.

#include <cstdint>
#include <string>
#include <vector>

#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis::detail {

/// A thread on a CPU from begin to end.
struct ThreadSlice {
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  int pid = 0;
  int cpu = 0;
  int prio = 0;  ///< kernel prio (< 100: real-time)
};

/// An interrupt handler's run (hard irq, local timer or softirq), entry to exit.
struct IrqSlice {
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  int cpu = 0;
  std::string name;  ///< "eth0 (irq 42)", "local_timer", "softirq TIMER"
};

struct KernelTracks {
  std::vector<int> cpus;              ///< the loop's recorded CPUs, ascending
  std::vector<ThreadSlice> threads;   ///< by begin
  std::vector<IrqSlice> irqs;         ///< by begin
  /// Per pid of `threads`, the first comm seen; with its policy from the task table.
  struct Thread {
    int pid = 0;
    std::string comm;
    std::string policy;  ///< "" when the task table does not know it
    int rt_priority = 0;
  };
  std::vector<Thread> names;  ///< by pid
};

/// The other threads' runs and the interrupts on the loop's CPUs, clipped to [from_ns, to_ns].
/// A thread's run goes from the sched_switch that brings it in to the one that takes it off.
/// When a switch takes off a thread that no traced switch brought in (the kernel does not
/// always trace the switch out of the idle task), its run is rebuilt from its last wake-up
/// since the previous switch on that CPU, else from that switch: the rule the causes use
/// (cause_attribution.h). An interrupt exit without its entry, or an entry without its exit,
/// gives no slice.
[[nodiscard]] KernelTracks LoopCpuTracks(const KernelTrace& kernel, const LoopThread& loop,
                                         std::int64_t from_ns, std::int64_t to_ns);

}  // namespace hiltwin::analysis::detail
