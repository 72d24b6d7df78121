#pragma once
/// The kernel's side of a traced run: scheduler, interrupt and page-fault events of the loop's
/// CPUs, recorded from tracefs on CLOCK_MONOTONIC (trace_clock "mono") by
/// trace_capture/kernel_recorder.h, kept in DIR/kernel_events.csv beside the LTTng trace, and
/// read back here for the cause of every late cycle (cause_attribution.h).
///
/// File format (one header row, then one row per event in time order; empty cells where a
/// field does not apply (each kind below lists its fields), read back as the default; comm and
/// name never contain commas or line breaks — the writer replaces them with '_'; address in
/// hex with 0x):
///   time_ns,cpu,event,pid,comm,prio,next_pid,next_comm,next_prio,prev_state,target_cpu,irq,name,
///   address
/// and DIR/kernel_tasks.csv, the threads seen, with their policy when it could be read:
///   pid,comm,policy,rt_priority
/// The first line of kernel_events.csv is a comment
///   "# hiltwin kernel events 2 cpus=<comma list> lost=<count>",
/// then (version 2, when the recorder knew it) the kernel's preemption model at record time
///   "# preemption <model> | <how it was told>"
/// ('|' and line breaks in either part become '_'). Version 1 files, without that line, are
/// still read (the model is then not known).

#include <cstdint>
#include <string>
#include <vector>

namespace hiltwin::analysis {

enum class KernelEventKind : std::uint8_t {
  kSchedSwitch,       ///< pid/comm/prio: prev; next_*: next; prev_state
  kSchedWakeup,       ///< pid/comm/prio: the woken task; target_cpu: where it will run
  kIrqEntry,          ///< irq, name (irq_handler_entry)
  kIrqExit,           ///< irq (irq_handler_exit)
  kLocalTimerEntry,   ///< the local APIC timer interrupt
  kLocalTimerExit,
  kSoftirqEntry,      ///< irq = vector number, name = vector name
  kSoftirqExit,
  kPageFaultUser,     ///< pid/comm: the faulting task (the CPU's current), address
};
/// "sched_switch", "sched_wakeup", "irq_handler_entry", "irq_handler_exit",
/// "local_timer_entry", "local_timer_exit", "softirq_entry", "softirq_exit", "page_fault_user".
[[nodiscard]] const char* ToString(KernelEventKind kind) noexcept;

struct KernelEvent {
  std::int64_t time_ns = 0;  ///< CLOCK_MONOTONIC
  int cpu = 0;
  KernelEventKind kind = KernelEventKind::kSchedSwitch;
  int pid = 0;
  std::string comm;
  int prio = 0;              ///< kernel prio: < 100 is real-time (rt_priority = 99 - prio)
  int next_pid = 0;
  std::string next_comm;
  int next_prio = 0;
  std::int64_t prev_state = 0;  ///< sched_switch: 0 = prev was still runnable (preempted)
  int target_cpu = -1;
  int irq = -1;
  std::string name;          ///< irq handler or softirq vector name
  std::uint64_t address = 0;

  friend bool operator==(const KernelEvent&, const KernelEvent&) = default;
};

/// A thread seen in the recording, with its scheduling class as read at the end of the
/// recording (policy empty when the thread was gone by then).
struct KernelTask {
  int pid = 0;
  std::string comm;
  std::string policy;  ///< "SCHED_FIFO", "SCHED_RR", "SCHED_OTHER", ... or empty
  int rt_priority = 0;

  friend bool operator==(const KernelTask&, const KernelTask&) = default;
};

struct KernelTrace {
  std::vector<int> cpus;  ///< CPUs recorded
  std::vector<KernelEvent> events;  ///< in time order
  std::vector<KernelTask> tasks;  ///< by pid; not pid 0 (the idle task is no thread to ask)
  std::uint64_t lost_events = 0;    ///< the ring buffer's overruns, when the recorder knew
  /// The kernel's preemption model when recorded ("PREEMPT_NONE", "PREEMPT", "PREEMPT_RT",
  /// ..., "unknown"), and how it was told (kernel_glue::FindPreemptionModel); both empty
  /// when the recording does not say.
  std::string preemption_model;
  std::string preemption_source;

  friend bool operator==(const KernelTrace&, const KernelTrace&) = default;
};

/// Writes DIR/kernel_events.csv and DIR/kernel_tasks.csv; throws std::runtime_error naming the
/// file on a write error.
void WriteKernelTrace(const std::string& dir, const KernelTrace& trace);

/// Reads them back; throws TraceReadError (timing_trace.h) naming file and line on bad input.
[[nodiscard]] KernelTrace ReadKernelTrace(const std::string& dir);

/// Whether DIR holds a kernel recording (kernel_events.csv exists).
[[nodiscard]] bool HasKernelTrace(const std::string& dir);

}  // namespace hiltwin::analysis
