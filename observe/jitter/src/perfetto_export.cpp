// Chrome trace-event JSON (the "JSON trace format" ui.perfetto.dev and chrome://tracing open):
// one complete slice per cycle from start to end, the wake-up latency as a counter at each
// release, misses as instant events (with the cause the report gave them). Written by hand, event by event, so a run of millions of
// cycles does not build a document tree first.

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

namespace hiltwin::analysis {
namespace {

using detail::Us;

enum class EventKind : std::uint8_t { kLatency, kCycle, kMiss, kSkipped };

// One event to write: what, for which cycle, when (µs).
struct PendingEvent {
  double ts_us = 0.0;
  EventKind kind = EventKind::kCycle;
  std::uint32_t skipped = 0;  // kSkipped: which of the cycle's skipped releases (1..)
  std::size_t cycle = 0;
};


// A JSON string literal; bytes that are not UTF-8 (a thread's name) become U+FFFD.
std::string JsonString(const std::string& text) {
  return nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::vector<PendingEvent> EventsInTimeOrder(const TimingTrace& trace) {
  std::vector<PendingEvent> events;
  events.reserve(trace.cycles.size() * 2);
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
  std::stable_sort(events.begin(), events.end(),
                   [](const PendingEvent& a, const PendingEvent& b) { return a.ts_us < b.ts_us; });
  return events;
}

struct Ids {
  int pid = 1;
  int tid = 1;
};

void WriteMetadata(std::ofstream& out, const Ids& ids) {
  const std::string process = JsonString("hiltwin (pid " + std::to_string(ids.pid) + ")");
  const std::string thread = JsonString("loop (tid " + std::to_string(ids.tid) + ")");
  char line[256];
  std::snprintf(line, sizeof line,
                "{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":%d,\"tid\":%d,\"args\":{\"name\":",
                ids.pid, ids.tid);
  out << line << process << "}},\n";
  std::snprintf(line, sizeof line,
                "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":%d,\"tid\":%d,\"args\":{\"name\":",
                ids.pid, ids.tid);
  out << line << thread << "}}";
}

// "\"preempted\",\"evidence\":\"...\"" for a notable cycle, from the report.
std::string CauseArgs(const JitterReport& report, std::uint64_t k) {
  const auto it = std::lower_bound(report.notable.begin(), report.notable.end(), k,
                                   [](const NotableCycle& n, std::uint64_t key) { return n.k < key; });
  if (it == report.notable.end() || it->k != k) return "\"none\",\"evidence\":\"\"";
  return nlohmann::json(ToString(it->cause.cause)).dump() + ",\"evidence\":" +
         JsonString(it->cause.evidence);
}

void WriteEvent(std::ofstream& out, const PendingEvent& e, const JitterReport& report,
                const TimingTrace& trace, const Ids& ids) {
  const scheduler::TimingSample& s = trace.cycles[e.cycle].sample;
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
  }
  out << line;
}

}  // namespace

std::string WritePerfettoTrace(const JitterReport& report, const TimingTrace& trace,
                               const std::string& dir) {
  std::string path = (std::filesystem::path(dir) / "perfetto_trace.json").string();
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path + ": check that the directory exists and is writable");
  Ids ids;
  if (trace.pid > 0) ids.pid = trace.pid;
  ids.tid = trace.loop && trace.loop->tid > 0 ? trace.loop->tid : ids.pid;
  out << "{\"displayTimeUnit\":\"ns\",\"traceEvents\":[\n";
  WriteMetadata(out, ids);
  for (const PendingEvent& e : EventsInTimeOrder(trace)) {
    out << ",\n";
    WriteEvent(out, e, report, trace, ids);
  }
  out << "\n]}\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path + ": the disk may be full");
  return path;
}

}  // namespace hiltwin::analysis
