// The kernel recorder's collector thread.
#include "kernel_collector.h"

#include <spdlog/spdlog.h>

#include <new>

namespace hiltwin::trace_capture {
namespace {

// At 20 kHz the loop's CPU produces about 100k events/s; 64 Ki per 100 ms drain is the usual
// size, reserved once so the first seconds do not reallocate over and over.
constexpr std::size_t kInitialEvents = 1U << 16U;

}  // namespace

KernelCollector::KernelCollector(tep_handle* tep, tracefs_instance* instance,
                                 const KernelCollectorSpec& spec)
    : tep_(tep), instance_(instance), period_(spec.period), decoder_(tep) {
  CPU_ZERO(&cpus_);
  for (int cpu : spec.cpus) CPU_SET(static_cast<std::size_t>(cpu), &cpus_);
  events_.reserve(kInitialEvents);
  thread_ = kernel_glue::NamedThread({.name = "hiltwin-ktrace", .cpus = spec.collector_cpus},
                                     [this] { Run(); });
}

KernelCollector::~KernelCollector() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.Join();
}

std::vector<analysis::KernelEvent> KernelCollector::Finish() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.Join();
  if (failed_drains_ > 0) {
    spdlog::warn("kernel recording: {} drains of the tracefs buffers failed or were cut short",
                 failed_drains_);
  }
  return std::move(events_);
}

void KernelCollector::Run() {
  for (;;) {
    bool stopping = false;
    {
      std::unique_lock lock(mutex_);
      stopping = wake_.wait_for(lock, period_, [this] { return stop_; });
    }
    Drain();  // once more after the stop request: what was recorded until tracing went off
    if (stopping) return;
  }
}

void KernelCollector::Drain() {
  // Non-blocking reads of each CPU's trace_pipe_raw, merged by time; returns when all are
  // empty. The pages read are gone from the ring buffer, which is what keeps it from filling.
  if (tracefs_iterate_raw_events(tep_, instance_, &cpus_, static_cast<int>(sizeof cpus_), &OnRecord,
                                 this) != 0) {
    ++failed_drains_;
  }
}

int KernelCollector::OnRecord(tep_event* event, tep_record* record, int cpu, void* self) {
  auto* collector = static_cast<KernelCollector*>(self);
  try {
    collector->decoder_.Decode(event, record, cpu, collector->events_);
  } catch (const std::bad_alloc&) {  // must not cross libtracefs's C frames
    ++collector->failed_drains_;
    return 1;  // stop this drain; the next one tries again
  }
  return 0;  // go on
}

}  // namespace hiltwin::trace_capture
