#pragma once
/// One run's loop timing as `hiltwin trace` analyses it, whatever it was read from: an LTTng
/// CTF trace of the `hiltwin` provider or a timing log (both readers in trace_readers.h).
/// Readers fill it; the jitter analysis (jitter_analysis.h) reads nothing else.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/qos/rules.h"
#include "hiltwin/scheduler/cycle.h"

namespace hiltwin::analysis {

/// What the input was.
enum class TraceSource : std::uint8_t { kLttng, kTimingLog };
/// "lttng" / "timing_log".
[[nodiscard]] const char* ToString(TraceSource source) noexcept;

/// The loop thread, from hiltwin:loop_start (LTTng only).
struct LoopThread {
  int tid = 0;
  int cpu = -1;       ///< CPU it ran its first cycle on (pinned: the pin)
  int policy = 0;     ///< SCHED_OTHER 0, SCHED_FIFO 1, SCHED_RR 2
  int priority = 0;   ///< SCHED_FIFO priority (0 for SCHED_OTHER)
};

/// One cycle as the hiltwin:cycle event (or timing-log row) carries it. `sample.io_ns` and
/// `sample.releases_skipped` as in the executive's TimingSample.
struct TracedCycle {
  scheduler::TimingSample sample;
  bool judged = true;  ///< counted in the QoS ledger (not paused, not before start)
};

/// The rarer events, in the order they were recorded.
enum class TracedEventKind : std::uint8_t {
  kDeadlineMiss,     ///< a = lateness_ns
  kOverrunInjected,  ///< a = extra_ns
  kQosViolation,     ///< a = rule index, b = violations so far
  kStateTransition,  ///< a = from, b = to, c = event (lifecycle codes)
  kIoError,          ///< a = tracing::IoErrorKind
};
struct TracedEvent {
  TracedEventKind kind = TracedEventKind::kDeadlineMiss;
  std::uint64_t k = 0;     ///< release index it belongs to
  std::int64_t time_ns = 0;  ///< LTTng: the event's time stamp; timing log: absent (0)
  std::int64_t a = 0;
  std::int64_t b = 0;
  std::int64_t c = 0;
};

/// Everything a reader found. Times are CLOCK_MONOTONIC ns for LTTng (absolute, so they line
/// up with kernel events) and ns since release 0 for a timing log.
struct TimingTrace {
  TraceSource source = TraceSource::kLttng;
  std::string path;                      ///< what was read, for messages
  std::int64_t period_ns = 0;
  std::int64_t deadline_ns = 0;
  std::uint64_t planned_cycles = 0;      ///< 0: until stopped
  // LTTng: period, deadline, plan and rules come from loop_start and qos_rule; a trace whose
  // recording began after the loop started has neither (0 and empty, `loop` absent).
  std::vector<qos::RuleSpec> rules;      ///< the run's QoS rules, in configuration order
  std::optional<LoopThread> loop;        ///< LTTng: from loop_start
  std::vector<TracedCycle> cycles;       ///< in order of k
  /// LTTng: as recorded. Timing log: one kDeadlineMiss per missed row (a = end - release -
  /// deadline, exactly what the loop traces), nothing else.
  std::vector<TracedEvent> events;
  bool complete = false;                 ///< LTTng: loop_end seen; timing log: no torn row
  /// Events the tracer dropped (CTF packet contexts' events_discarded, summed over streams,
  /// whichever process's they were: per-user buffers share streams between processes);
  /// timing log: rows its logger dropped (queue full), seen as releases between two rows that
  /// neither row accounts for (k jumps by more than 1 + releases_skipped).
  std::uint64_t discarded_events = 0;
  /// Whole packets the tracer lost (CTF packet sequence numbers that jump): their events are
  /// not in discarded_events, because nobody counted them. 0 for a timing log.
  std::uint64_t discarded_packets = 0;
  /// LTTng: the process whose events these are (several runs in one trace: the first one,
  /// and `other_processes` says how many more were seen and left out).
  int pid = 0;
  std::uint32_t other_processes = 0;
  /// LTTng: further loops of that same process (a second loop_start, e.g. `hiltwin tune`'s
  /// candidate runs), left out: the trace is the process's first run.
  std::uint32_t other_runs = 0;
};

/// Thrown by every reader for input it cannot use: the message names the file and the place
/// (line, event index or stream) and what was wrong. `hiltwin trace --analyze` exits 2 with it.
class TraceReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hiltwin::analysis
