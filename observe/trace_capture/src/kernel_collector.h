#pragma once
// The collector thread: empties the instance's per-CPU ring buffers while the run goes on, so
// a long run at a high rate fits in buffers of a few MiB.

#include <sched.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/traces/kernel_events.h"
#include "kernel_event_decoder.h"
#include "tracefs_api.h"

namespace hiltwin::trace_capture {

struct KernelCollectorSpec {
  std::vector<int> cpus;            ///< the recorded CPUs, drained
  std::vector<int> collector_cpus;  ///< where the thread may run; empty: anywhere
  std::chrono::milliseconds period{100};
};

/// Starts `hiltwin-ktrace` (SCHED_OTHER, kernel_glue::NamedThread) at construction; it drains
/// every `period` through tracefs_iterate_raw_events, which reads trace_pipe_raw and so
/// consumes what it reads.
class KernelCollector {
 public:
  /// `tep` and `instance` must outlive the collector (or its Finish()).
  KernelCollector(tep_handle* tep, tracefs_instance* instance, const KernelCollectorSpec& spec);
  /// Finish() when not done yet.
  ~KernelCollector();
  KernelCollector(const KernelCollector&) = delete;
  KernelCollector& operator=(const KernelCollector&) = delete;

  /// Stops the thread after one last drain (turn recording off first, so it is the last)
  /// and hands over every event collected, in the order drained. Once only.
  [[nodiscard]] std::vector<analysis::KernelEvent> Finish();

 private:
  void Run();
  void Drain();
  static int OnRecord(tep_event* event, tep_record* record, int cpu, void* self);

  tep_handle* tep_;
  tracefs_instance* instance_;
  cpu_set_t cpus_{};
  std::chrono::milliseconds period_;
  KernelEventDecoder decoder_;
  std::vector<analysis::KernelEvent> events_;  // the thread's until it is joined
  std::uint64_t failed_drains_ = 0;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  kernel_glue::NamedThread thread_;  // last: starts once everything it uses exists
};

}  // namespace hiltwin::trace_capture
