// Chrome trace-event JSON (the "JSON trace format" ui.perfetto.dev and chrome://tracing open):
// one complete slice per cycle from start to end, the wake-up latency as a counter at each
// release, misses as instant events (with the cause the report gave them). With the kernel
// recorded, a second process "kernel" beside the loop's: a track per other thread that ran on
// the loop's CPUs (slices while it ran) and a track per such CPU of its interrupts
// (kernel_tracks.h), so the culprit of a late cycle lies under it. Written by hand, event by
// event, so a run of millions of cycles does not build a document tree first.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hiltwin/jitter/jitter_outputs.h"
#include "hiltwin/report_kit/time_units.h"
#include "kernel_tracks.h"

namespace hiltwin::analysis {
namespace {

using detail::Us;

enum class EventKind : std::uint8_t { kLatency, kCycle, kMiss, kSkipped, kThreadRun, kIrqRun };

// One event to write: what, which (a cycle, or a kernel slice), when (µs).
struct PendingEvent {
  double ts_us = 0.0;
  EventKind kind = EventKind::kCycle;
  std::uint32_t skipped = 0;  // kSkipped: which of the cycle's skipped releases (1..)
  std::size_t index = 0;      // into trace.cycles, tracks.threads or tracks.irqs
};

// The kernel's tracks go in a process of their own, with a pid no Linux thread has (pid_max is
// at most 2^22); each thread keeps its own pid as tid, each CPU's interrupts get one above it.
constexpr int kKernelPid = 1 << 22;
int IrqTid(int cpu) { return kKernelPid + 1 + cpu; }

// A JSON string literal; bytes that are not UTF-8 (a thread's name) become U+FFFD.
std::string JsonString(const std::string& text) {
  return nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::vector<PendingEvent> EventsInTimeOrder(const TimingTrace& trace,
                                            const detail::KernelTracks& tracks) {
  std::vector<PendingEvent> events;
  events.reserve(trace.cycles.size() * 2 + tracks.threads.size() + tracks.irqs.size());
  for (std::size_t i = 0; i < trace.cycles.size(); ++i) {
    const scheduler::TimingSample& s = trace.cycles[i].sample;
    events.push_back({Us(s.release_ns), EventKind::kLatency, 0, i});
    events.push_back({Us(s.start_ns), EventKind::kCycle, 0, i});
    if (s.missed) events.push_back({Us(s.end_ns), EventKind::kMiss, 0, i});
    for (std::uint32_t j = 1; j <= s.releases_skipped; ++j) {
      const std::int64_t release_ns = s.release_ns + static_cast<std::int64_t>(j) * trace.period_ns;
      events.push_back({Us(release_ns), EventKind::kSkipped, j, i});
    }
  }
  for (std::size_t i = 0; i < tracks.threads.size(); ++i) {
    events.push_back({Us(tracks.threads[i].begin_ns), EventKind::kThreadRun, 0, i});
  }
  for (std::size_t i = 0; i < tracks.irqs.size(); ++i) {
    events.push_back({Us(tracks.irqs[i].begin_ns), EventKind::kIrqRun, 0, i});
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const PendingEvent& a, const PendingEvent& b) { return a.ts_us < b.ts_us; });
  return events;
}

struct Ids {
  int pid = 1;
  int tid = 1;
};

// A "process_name" or "thread_name" metadata event.
void WriteName(std::ofstream& out, const char* what, int pid, int tid, const std::string& name) {
  char line[160];
  std::snprintf(line, sizeof line,
                "{\"name\":\"%s\",\"ph\":\"M\",\"pid\":%d,\"tid\":%d,\"args\":{\"name\":", what,
                pid, tid);
  out << line << JsonString(name) << "}}";
}

void WriteMetadata(std::ofstream& out, const Ids& ids) {
  WriteName(out, "process_name", ids.pid, ids.tid, "hiltwin (pid " + std::to_string(ids.pid) + ")");
  out << ",\n";
  WriteName(out, "thread_name", ids.pid, ids.tid, "loop (tid " + std::to_string(ids.tid) + ")");
}

// "rt-hog (pid 4242, SCHED_FIFO 95)", "kworker/1:1 (pid 57)".
std::string ThreadTrackName(const detail::KernelTracks::Thread& t) {
  std::string name = t.comm + " (pid " + std::to_string(t.pid);
  if (!t.policy.empty()) name += ", " + t.policy;
  if (t.policy == "SCHED_FIFO" || t.policy == "SCHED_RR") {
    name += " " + std::to_string(t.rt_priority);
  }
  return name + ")";
}

void WriteKernelMetadata(std::ofstream& out, const detail::KernelTracks& tracks) {
  if (tracks.threads.empty() && tracks.irqs.empty()) return;
  std::string cpus;
  for (const int cpu : tracks.cpus) cpus += (cpus.empty() ? "" : ", ") + std::to_string(cpu);
  out << ",\n";
  WriteName(out, "process_name", kKernelPid, kKernelPid,
            "kernel: other threads and interrupts on the loop's CPU" +
                std::string(tracks.cpus.size() == 1 ? " " : "s ") + cpus);
  for (const detail::KernelTracks::Thread& t : tracks.names) {
    out << ",\n";
    WriteName(out, "thread_name", kKernelPid, t.pid, ThreadTrackName(t));
  }
  for (const int cpu : tracks.cpus) {
    out << ",\n";
    WriteName(out, "thread_name", kKernelPid, IrqTid(cpu),
              "interrupts on CPU " + std::to_string(cpu));
  }
}

// "\"preempted\",\"evidence\":\"...\"" for a notable cycle, from the report.
std::string CauseArgs(const JitterReport& report, std::uint64_t k) {
  const auto it = std::lower_bound(report.notable.begin(), report.notable.end(), k,
                                   [](const NotableCycle& n, std::uint64_t key) { return n.k < key; });
  if (it == report.notable.end() || it->k != k) return "\"none\",\"evidence\":\"\"";
  return nlohmann::json(ToString(it->cause.cause)).dump() + ",\"evidence\":" +
         JsonString(it->cause.evidence);
}

void WriteCycleEvent(std::ofstream& out, const PendingEvent& e, const JitterReport& report,
                     const TimingTrace& trace, const Ids& ids) {
  const scheduler::TimingSample& s = trace.cycles[e.index].sample;
  const auto k = static_cast<unsigned long long>(s.cycle);
  char line[512];
  switch (e.kind) {
    case EventKind::kLatency:
      std::snprintf(line, sizeof line,
                    "{\"name\":\"wake-up latency [us]\",\"ph\":\"C\",\"ts\":%.3f,\"pid\":%d,"
                    "\"args\":{\"latency_us\":%.3f}}",
                    e.ts_us, ids.pid, Us(s.wake_ns - s.release_ns));
      break;
    case EventKind::kCycle:
      std::snprintf(line, sizeof line,
                    "{\"name\":\"cycle\",\"cat\":\"hiltwin\",\"ph\":\"X\",\"ts\":%.3f,\"dur\":%.3f,"
                    "\"pid\":%d,\"tid\":%d,\"args\":{\"k\":%llu,\"latency_ns\":%lld,"
                    "\"compute_ns\":%lld,\"io_ns\":%lld,\"response_ns\":%lld,\"missed\":%s}}",
                    e.ts_us, Us(s.end_ns - s.start_ns), ids.pid, ids.tid, k,
                    static_cast<long long>(s.wake_ns - s.release_ns),
                    static_cast<long long>(s.end_ns - s.start_ns - s.io_ns),
                    static_cast<long long>(s.io_ns), static_cast<long long>(s.end_ns - s.release_ns),
                    s.missed ? "true" : "false");
      break;
    case EventKind::kMiss:
      std::snprintf(line, sizeof line,
                    "{\"name\":\"deadline miss\",\"cat\":\"hiltwin\",\"ph\":\"i\",\"s\":\"t\","
                    "\"ts\":%.3f,\"pid\":%d,\"tid\":%d,\"args\":{\"k\":%llu,\"lateness_ns\":%lld,"
                    "\"releases_skipped\":%u,\"cause\":",
                    e.ts_us, ids.pid, ids.tid, k,
                    static_cast<long long>(s.end_ns - s.release_ns - trace.deadline_ns),
                    s.releases_skipped);
      out << line << CauseArgs(report, s.cycle) << "}}";
      return;
    case EventKind::kSkipped:
      std::snprintf(line, sizeof line,
                    "{\"name\":\"skipped release\",\"cat\":\"hiltwin\",\"ph\":\"i\",\"s\":\"t\","
                    "\"ts\":%.3f,\"pid\":%d,\"tid\":%d,\"args\":{\"k\":%llu}}",
                    e.ts_us, ids.pid, ids.tid, k + e.skipped);
      break;
    case EventKind::kThreadRun:
    case EventKind::kIrqRun:
      return;  // WriteKernelEvent's
  }
  out << line;
}

// A slice of the kernel's tracks: a thread's run ("rt-hog on CPU 1") or an interrupt's.
void WriteKernelEvent(std::ofstream& out, const PendingEvent& e,
                      const detail::KernelTracks& tracks) {
  std::string name;
  std::int64_t dur_ns = 0;
  int tid = 0;
  int cpu = 0;
  std::string args;
  if (e.kind == EventKind::kThreadRun) {
    const detail::ThreadSlice& t = tracks.threads[e.index];
    const auto who = std::lower_bound(
        tracks.names.begin(), tracks.names.end(), t.pid,
        [](const detail::KernelTracks::Thread& n, int pid) { return n.pid < pid; });
    name = (who != tracks.names.end() ? who->comm : std::to_string(t.pid)) + " on CPU " +
           std::to_string(t.cpu);
    dur_ns = t.end_ns - t.begin_ns;
    tid = t.pid;
    cpu = t.cpu;
    args = ",\"kernel_prio\":" + std::to_string(t.prio);
  } else {
    const detail::IrqSlice& x = tracks.irqs[e.index];
    name = x.name;
    dur_ns = x.end_ns - x.begin_ns;
    tid = IrqTid(x.cpu);
    cpu = x.cpu;
  }
  char line[200];
  std::snprintf(line, sizeof line,
                "\"cat\":\"kernel\",\"ph\":\"X\",\"ts\":%.3f,\"dur\":%.3f,\"pid\":%d,\"tid\":%d,"
                "\"args\":{\"cpu\":%d",
                e.ts_us, Us(dur_ns), kKernelPid, tid, cpu);
  out << "{\"name\":" << JsonString(name) << ',' << line << args << "}}";
}

}  // namespace

std::string WritePerfettoTrace(const JitterReport& report, const TimingTrace& trace,
                               const KernelTrace* kernel, const std::string& dir) {
  std::string path = (std::filesystem::path(dir) / "perfetto_trace.json").string();
  std::ofstream out(path);
  if (!out) {
    throw std::runtime_error("cannot write " + path +
                             ": check that the directory exists and is writable");
  }
  Ids ids;
  if (trace.pid > 0) ids.pid = trace.pid;
  ids.tid = trace.loop && trace.loop->tid > 0 ? trace.loop->tid : ids.pid;
  // Only when the report matched the kernel's events to the cycles (same clock, loop known).
  detail::KernelTracks tracks;
  if (kernel != nullptr && report.kernel_recorded && trace.loop) {
    tracks = detail::LoopCpuTracks(*kernel, *trace.loop, trace.cycles.front().sample.release_ns,
                                   trace.cycles.back().sample.end_ns);
  }
  out << "{\"displayTimeUnit\":\"ns\",\"traceEvents\":[\n";
  WriteMetadata(out, ids);
  WriteKernelMetadata(out, tracks);
  for (const PendingEvent& e : EventsInTimeOrder(trace, tracks)) {
    out << ",\n";
    if (e.kind == EventKind::kThreadRun || e.kind == EventKind::kIrqRun) {
      WriteKernelEvent(out, e, tracks);
    } else {
      WriteCycleEvent(out, e, report, trace, ids);
    }
  }
  out << "\n]}\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path + ": the disk may be full");
  return path;
}

}  // namespace hiltwin::analysis
