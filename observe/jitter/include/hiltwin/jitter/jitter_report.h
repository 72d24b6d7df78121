#pragma once
/// The jitter report of one traced run (`hiltwin trace`): distributions of wake-up latency,
/// period jitter, compute and response time; the misses and how they cluster; the worst cycles;
/// and, when the kernel was recorded, the cause of every late cycle. One typed record; the text,
/// JSON, pictures and the Perfetto export all derive from it (jitter_outputs.h).

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/qos/rules.h"
#include "hiltwin/scheduler/timing_stats.h"
#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis {

/// One histogram bin of a distribution, [low_ns, high_ns).
struct HistogramBin {
  std::int64_t low_ns = 0;
  std::int64_t high_ns = 0;
  std::uint64_t count = 0;
};

/// One timing quantity over the cycles the executive accounts it for — every cycle run, paused
/// and grace cycles included, as the run report's figures (engine/scheduler/src/executive.cpp):
/// latency only of cycles whose loop was asleep at the release (not of catch-up cycles);
/// period jitter only between neighbouring cycles (not the first, not after skipped releases).
/// The same log-linear histogram and percentile rule (scheduler::TimingStats), so the two agree
/// to the bin.
struct Distribution {
  std::string name;  ///< "latency", "period_jitter", "compute", "response"
  scheduler::TimingSummary summary;
  /// Non-empty bins only, ascending; of |value| (period jitter is signed, its percentiles are
  /// of the magnitude).
  std::vector<HistogramBin> bins;
};

/// Where the misses fell.
struct MissClusters {
  std::uint64_t misses = 0;           ///< judged misses, skipped releases included
  std::uint64_t bursts = 0;           ///< runs of consecutive missed releases
  std::uint64_t longest_burst = 0;    ///< releases in the longest run
  std::uint64_t longest_burst_start_k = 0;
  /// Per window rule (mk_firm, misses_in_window), in rule order: how many of its windows held
  /// at least one miss, and the most misses any one held.
  struct RuleWindows {
    qos::RuleSpec rule;
    std::uint64_t windows_touched = 0;
    std::uint64_t max_misses_in_window = 0;
  };
  std::vector<RuleWindows> windows;
};

/// Why a cycle was late.
enum class CauseClass : std::uint8_t {
  kPreempted,       ///< a thread above the loop's priority ran on its CPU while it was runnable
  /// A thread the loop's priority outranks held its CPU while the loop was runnable: the
  /// kernel did not preempt it (a non-preemptible section; PREEMPT_NONE does not preempt in
  /// the kernel at all)
  kNonPreemptible,
  kInterrupt,       ///< a hard interrupt (or the local timer, or softirq) held the CPU
  kPageFault,       ///< the loop thread faulted
  kOwnCompute,      ///< the step itself ran long (compute above its p99.9)
  kInvisible,       ///< nothing in the guest explains it: hypervisor steal or SMI
  /// Released while its predecessor still ran (catch-up): late because of the stall it is
  /// behind, whose cause it carries (Cause::behind_cycle, Cause::inherited)
  kBacklog,
  kNotRecorded,     ///< the kernel was not recorded (no --kernel)
};
/// "preempted", "non_preemptible", "interrupt", "page_fault", "own_compute", "invisible",
/// "backlog", "not_recorded".
[[nodiscard]] const char* ToString(CauseClass cause) noexcept;

/// The evidence for one cause.
struct Cause {
  CauseClass cause = CauseClass::kNotRecorded;
  /// How long the culprit held the CPU inside the window (kBacklog: how long the cycle
  /// waited behind its predecessor)
  std::int64_t duration_ns = 0;
  int cpu = -1;                  ///< the loop's CPU where it happened (-1: not recorded)
  // kBacklog: the stall this cycle is behind, and that stall's class; the fields below are
  // the stall's (its thread, interrupt, ...).
  std::optional<std::uint64_t> behind_cycle;
  std::optional<CauseClass> inherited;
  // kPreempted, kNonPreemptible: the thread that ran instead.
  std::string thread;            ///< comm
  int pid = 0;
  std::string policy;            ///< "SCHED_FIFO", ... ("" when unknown)
  int priority = 0;              ///< rt priority (0 for SCHED_OTHER)
  // kInterrupt: which one ("local_timer", an irq handler's name, a softirq vector).
  std::string interrupt;
  int irq = -1;
  // kPageFault: how many faults, first address.
  std::uint64_t faults = 0;
  std::uint64_t address = 0;
  /// One line a person reads, e.g. "preempted by rt-hog (pid 4242, SCHED_FIFO 95) for 2.10 ms".
  std::string evidence;

  /// The class a summary counts this cause under: a backlog's stall's, else its own.
  [[nodiscard]] CauseClass RankedAs() const noexcept { return inherited.value_or(cause); }
};

/// A stall: a run of consecutive late cycles (missed, or response above the response p99.9;
/// consecutive: no cycle lost from the trace between them). A cycle that is not late is a
/// stall of its own.
struct Burst {
  std::uint64_t first_k = 0;
  std::uint64_t last_k = 0;
  std::uint64_t cycles = 1;            ///< cycles run in it
  std::uint64_t releases_skipped = 0;  ///< releases skipped inside it (not counted in cycles)
  std::int64_t duration_ns = 0;        ///< first cycle's release to last cycle's end
};

/// A cycle worth naming: a miss or a wake-up above p99.9.
struct NotableCycle {
  std::uint64_t k = 0;
  std::int64_t release_ns = 0;
  std::int64_t latency_ns = 0;   ///< wake - release
  std::int64_t compute_ns = 0;   ///< end - start - io
  std::int64_t response_ns = 0;  ///< end - release
  bool missed = false;
  Cause cause;  ///< the dominant cause (the longest culprit in the window)
  Burst burst;  ///< the stall this cycle belongs to
};

/// Ranked causes: how many notable cycles each explains, most first. A backlog cycle counts
/// with the stall it is behind (its class and culprit), so a stall and its catch-up cycles
/// are one line.
struct CauseCount {
  CauseClass cause = CauseClass::kNotRecorded;
  std::uint64_t cycles = 0;   ///< notable cycles this cause is dominant in, backlog included
  std::uint64_t misses = 0;   ///< of them, misses
  std::uint64_t backlog = 0;  ///< of them, catch-up cycles behind a stall of this class
  /// The top culprits within the class ("rt-hog (pid 4242)", "local_timer"), most first.
  std::vector<std::pair<std::string, std::uint64_t>> culprits;
};

/// Whether the run's rate can be held here at all: the median wake-up latency plus the median
/// compute against the deadline. When not, that is the cause of the misses, before any
/// per-cycle one, and the report says so first.
struct Feasibility {
  bool feasible = true;
  std::int64_t latency_p50_ns = 0;
  std::int64_t compute_p50_ns = 0;
  std::int64_t deadline_ns = 0;
  std::int64_t max_rate_hz = 0;  ///< the highest rate the medians allow (0: not judged)
  std::string verdict;           ///< the report's first line ("" when feasible)
  std::string advice;            ///< the command that finds the rate this machine holds
};

/// The kernel's preemption model as the recording named it (kernel_events.h).
struct PreemptionModel {
  std::string model = "unknown";  ///< "PREEMPT_NONE", "PREEMPT", "PREEMPT_RT", ..., "unknown"
  std::string source;             ///< how it was told, or why it is unknown
};

struct JitterReport {
  Feasibility feasibility;
  TraceSource source = TraceSource::kLttng;
  std::string path;
  std::int64_t period_ns = 0;
  std::int64_t deadline_ns = 0;
  /// Release of the trace's first cycle: the outputs count time stamps from it.
  std::int64_t first_release_ns = 0;
  std::uint64_t cycles = 0;          ///< cycles in the trace
  std::uint64_t cycles_judged = 0;   ///< of them, counted in the QoS ledger
  std::uint64_t releases_skipped = 0;
  std::uint64_t misses = 0;          ///< judged misses, skipped releases included (= report)
  double miss_pct = 0.0;             ///< misses / (judged cycles + skipped)
  Distribution latency, period_jitter, compute, response;
  MissClusters clusters;
  /// The 10 worst stalls (Burst), judged cycles or not: of each, the cycle with the longest
  /// response (ties: earlier k first), with its cause like a notable cycle's; longest first.
  std::vector<NotableCycle> worst;
  bool kernel_recorded = false;
  PreemptionModel kernel_preemption;  ///< with the kernel recorded
  /// Every judged miss (those `misses` counts) and every wake-up strictly above the latency
  /// p99.9 (of cycles whose latency was recorded), in order of k.
  std::vector<NotableCycle> notable;
  std::vector<CauseCount> causes;    ///< ranked; empty without the kernel
  std::uint64_t discarded_events = 0;       ///< LTTng's, from the trace
  std::uint64_t kernel_lost_events = 0;     ///< tracefs ring overruns
  bool trace_complete = false;
  std::optional<LoopThread> loop;
  std::vector<std::string> warnings;  ///< e.g. discarded events, incomplete trace
};

/// Analyses a trace; `kernel` may be null (causes: not recorded). Throws TraceReadError when
/// the trace holds no cycle.
[[nodiscard]] JitterReport AnalyzeJitter(const TimingTrace& trace, const KernelTrace* kernel);

}  // namespace hiltwin::analysis
