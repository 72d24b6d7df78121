#pragma once
/// Records the kernel's scheduler, interrupt and page-fault events of chosen CPUs from tracefs
/// (through libtracefs), on CLOCK_MONOTONIC (trace_clock "mono") so they line up with the
/// loop's own time stamps, in a tracefs instance of its own (the system's top-level tracing
/// settings are left alone). A collector thread (SCHED_OTHER, on CPUs the loop does not use)
/// drains the per-CPU buffers while the run goes on; Stop() writes DIR/kernel_events.csv and
/// DIR/kernel_tasks.csv (traces/kernel_events.h), with the kernel's preemption model as it was
/// found at the start (kernel_glue::FindKernelPreemption). Control side only.

#include <string>
#include <vector>

#include "hiltwin/traces/kernel_events.h"

namespace hiltwin::trace_capture {

struct KernelRecorderConfig {
  std::string output_dir;
  std::vector<int> cpus;            ///< CPUs to record; empty: every online CPU
  std::vector<int> collector_cpus;  ///< where the collector thread may run; empty: any
  int buffer_kb_per_cpu = 16384;    ///< tracefs ring per CPU
  bool may_mount = true;            ///< mount tracefs at /sys/kernel/tracing when it is not
  int drain_period_ms = 100;        ///< how often the collector empties the per-CPU buffers
};

class KernelRecorder {
 public:
  /// Checks access (mounting tracefs when allowed), creates the instance, sets the clock,
  /// enables sched_switch, sched_wakeup, irq_handler_entry/exit, softirq_entry/exit,
  /// local_timer_entry/exit and page_fault_user on `cpus`, and starts recording. Throws
  /// CaptureError saying what was refused and what to do (run as root, or make tracefs
  /// readable).
  explicit KernelRecorder(const KernelRecorderConfig& config);
  /// Stops and removes the instance if Stop() was not called.
  ~KernelRecorder();
  KernelRecorder(const KernelRecorder&) = delete;
  KernelRecorder& operator=(const KernelRecorder&) = delete;

  /// Stops recording, drains what is left, reads the policy of every thread seen, writes the
  /// two files, removes the instance and returns what it wrote. Idempotent.
  const analysis::KernelTrace& Stop();

  /// Empty when this process may record the kernel here; otherwise why not and what to do
  /// (tracefs_access.h). Mounts tracefs when it is not mounted and `may_mount`.
  [[nodiscard]] static std::string WhyCannotRecord(bool may_mount = true);

 private:
  struct State;
  State* state_ = nullptr;  // pimpl: libtracefs types stay out of the header
};

}  // namespace hiltwin::trace_capture
