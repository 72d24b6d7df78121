// The kernel recorder: access check, its own tracefs instance, the collector thread, and at
// the end the two files of traces/kernel_events.h.
#include "hiltwin/trace_capture/kernel_recorder.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>

#include "hiltwin/kernel_glue/rt_probe.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/tracefs_access.h"
#include "kernel_collector.h"
#include "kernel_tasks.h"
#include "tracefs_api.h"
#include "tracefs_instance.h"

namespace hiltwin::trace_capture {
namespace {

struct TepFree {
  void operator()(tep_handle* tep) const noexcept { tep_free(tep); }
};
using TepHandle = std::unique_ptr<tep_handle, TepFree>;

// The formats of the recorder's event systems only: parsing every system of a modern kernel
// takes far longer and could fail on an event nobody asked for.
TepHandle LoadFormats() {
  static const char* const kSystems[] = {"sched", "irq", "irq_vectors", "exceptions", nullptr};
  TepHandle tep(tracefs_local_events_system(nullptr, kSystems));
  if (!tep) throw CaptureError("tracefs: cannot read the event formats of this kernel");
  return tep;
}

std::string CpuListText(const std::vector<int>& cpus) {
  std::string text;
  for (int cpu : cpus) text += (text.empty() ? "" : ",") + std::to_string(cpu);
  return text;
}

// The configured CPUs, sorted, each online; every online CPU when none is given.
std::vector<int> CpusToRecord(std::vector<int> wanted) {
  std::vector<int> online = OnlineCpus();
  if (wanted.empty()) return online;
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  for (int cpu : wanted) {
    if (std::find(online.begin(), online.end(), cpu) == online.end()) {
      throw CaptureError("cannot record CPU " + std::to_string(cpu) + ": it is not online " +
                         "(online: " + CpuListText(online) + ")");
    }
  }
  return wanted;
}

void SortByTime(std::vector<analysis::KernelEvent>& events) {
  // Each drain merges the CPUs by time, but a later drain can hold one CPU's events from
  // before the previous drain's last event of another CPU.
  std::stable_sort(events.begin(), events.end(),
                   [](const analysis::KernelEvent& a, const analysis::KernelEvent& b) {
                     return a.time_ns < b.time_ns;
                   });
}

}  // namespace

// Declaration order is teardown order reversed: the collector (which reads through the
// instance and the formats) goes first.
struct KernelRecorder::State {
  State(const KernelRecorderConfig& recorder_config, std::vector<int> recorded_cpus)
      : config(recorder_config),
        cpus(std::move(recorded_cpus)),
        instance("hiltwin_" + std::to_string(::getpid())) {}

  KernelRecorderConfig config;
  std::vector<int> cpus;
  TracefsInstance instance;
  TepHandle tep;
  std::unique_ptr<KernelCollector> collector;
  analysis::KernelTrace trace;
  bool stopped = false;
};

KernelRecorder::KernelRecorder(const KernelRecorderConfig& config) {
  const std::string refused = WhyCannotRecord(config.may_mount);
  if (!refused.empty()) throw CaptureError("cannot record the kernel's events: " + refused);
  std::filesystem::create_directories(config.output_dir);
  auto state = std::make_unique<State>(config, CpusToRecord(config.cpus));
  // Named now, as the kernel runs during the recording: whether a thread the loop outranks
  // could have been preempted in the kernel depends on it (cause_attribution.h).
  const kernel_glue::KernelPreemption preemption = kernel_glue::FindKernelPreemption();
  state->trace.preemption_model = preemption.model;
  state->trace.preemption_source = preemption.source;
  state->instance.Configure(state->cpus, config.buffer_kb_per_cpu);
  state->instance.EnableEvents();
  state->tep = LoadFormats();
  state->instance.SetRecording(true);
  state->collector = std::make_unique<KernelCollector>(
      state->tep.get(), state->instance.get(),
      KernelCollectorSpec{.cpus = state->cpus,
                          .collector_cpus = config.collector_cpus,
                          .period = std::chrono::milliseconds(config.drain_period_ms)});
  state_ = state.release();
}

KernelRecorder::~KernelRecorder() {
  if (state_ == nullptr) return;
  // Recording off first, so the collector's last drain is short; the State's members then
  // join the collector and remove the instance, without throwing.
  if (!state_->stopped) tracefs_trace_off(state_->instance.get());
  delete state_;
}

const analysis::KernelTrace& KernelRecorder::Stop() {
  State& state = *state_;
  if (state.stopped) return state.trace;
  state.stopped = true;
  state.instance.SetRecording(false);
  analysis::KernelTrace& trace = state.trace;
  trace.events = state.collector->Finish();
  trace.cpus = state.cpus;
  trace.lost_events = state.instance.LostEvents(state.cpus);
  state.instance.Destroy();  // everything is read: give the kernel its buffers back now
  SortByTime(trace.events);
  FillMissingComms(trace.events);
  trace.tasks = TasksSeen(trace.events);  // after the run: the policies the threads ended with
  analysis::WriteKernelTrace(state.config.output_dir, trace);
  return trace;
}

std::string KernelRecorder::WhyCannotRecord(bool may_mount) {
  return ExplainTracefsAccess(ProbeTracefs(may_mount));
}

}  // namespace hiltwin::trace_capture
