#pragma once
/// The typed run report (docs/architecture.md, "Run report"). RunSession fills it once, after the
/// loop; the JSON file, the text summary, the problem lines and the exit code are all derived from
/// it here, so no two outputs can disagree and nothing is read back from JSON.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runtime/exit_code.h"
#include "hiltwin/scheduler/overrun_policy.h"
#include "hiltwin/scheduler/timing_stats.h"

namespace hiltwin::runtime {

/// Which clock paced the loop.
enum class ClockKind : std::uint8_t { kRealtime, kVirtual };
/// "realtime" / "virtual".
[[nodiscard]] const char* ToString(ClockKind clock) noexcept;

/// The miss figures, all from the QoS monitor (the one miss ledger). The plain figures count
/// every release it recorded, grace period included; the `judged` ones only those after it.
struct MissLedger {
  std::uint64_t releases = 0;                ///< recorded releases, grace period included
  std::uint64_t deadline_misses = 0;         ///< grace period included
  double miss_pct = 0.0;                     ///< deadline_misses / releases
  std::uint64_t max_consecutive_misses = 0;  ///< grace period included
  std::uint64_t grace_cycles = 0;            ///< configured: releases not judged
  std::uint64_t grace_misses = 0;            ///< misses inside the grace period
  std::uint64_t cycles_judged = 0;
  std::uint64_t misses_judged = 0;
  double miss_pct_judged = 0.0;
  std::uint64_t max_consecutive_misses_judged = 0;
  std::optional<std::uint64_t> abort_cycle;  ///< release at which policy abort fired
};

/// What the link to the board saw.
struct LinkFigures {
  std::uint64_t io_errors = 0;           ///< corrupted or missed frames (inputs held)
  std::uint64_t peer_absent_cycles = 0;  ///< wire: cycles with no peer process attached
  std::uint64_t pulse_limit_cycles =
      0;                           ///< cycles with an encoder change above one period's pulses
  std::string peer_name = "peer";  ///< who sits on the other side ("controller", "twin")
  std::string peer_stopped;        ///< wire: why the peer ended its run (stop peer_stopped)
};

/// The fault that stopped the run (I/O or model).
struct RunFault {
  lifecycle::StopReason kind = lifecycle::StopReason::kNone;
  std::uint64_t cycle = 0;
  std::string reason;
};

/// The CSV log's accounting (tracing::CsvLogger): each row the log should hold is counted
/// once, as written, dropped or lost.
struct LogFigures {
  std::string path;
  std::uint64_t rows_written = 0;  ///< in the file (the kernel took their bytes)
  std::uint64_t rows_dropped = 0;  ///< never reached the writer: its queue was full
  std::uint64_t rows_lost = 0;     ///< the file did not take them (disk full, size limit, ...)
  std::string error;               ///< empty while the log is complete
  std::string lost_reason;         ///< the errno text alone, e.g. "No space left on device"
};

/// Everything a run's outputs say.
struct RunReport {
  std::string task_name;  ///< e.g. "RELbot twin"
  std::string io;         ///< backend spec, e.g. "mock"
  ClockKind clock = ClockKind::kRealtime;
  /// Application facts reported verbatim as top-level string keys (e.g. input, integrator).
  std::vector<std::pair<std::string, std::string>> details;

  qos::Verdict verdict = qos::Verdict::kPass;  ///< the QoS monitor's; see ConclusionOf
  lifecycle::StopReason stop_reason = lifecycle::StopReason::kNone;
  /// The signal that asked for a stop_requested stop (SIGINT, SIGTERM, SIGHUP); 0 otherwise
  /// (also for a stop command).
  int stop_signal = 0;
  lifecycle::StopReason fault_while_stopping = lifecycle::StopReason::kNone;
  lifecycle::State final_state = lifecycle::State::kInit;

  double rate_hz = 0.0;
  std::int64_t period_ns = 0;
  std::int64_t deadline_ns = 0;
  scheduler::OverrunPolicy overrun_policy = scheduler::OverrunPolicy::kCatchUp;
  std::uint64_t cycles_planned = 0;
  std::uint64_t cycles_run = 0;        ///< cycles executed (paused ones included)
  std::uint64_t cycles_paused = 0;     ///< executed in `paused`: not stepped, not judged
  std::uint64_t releases = 0;          ///< releases the executive consumed (run + skipped)
  std::uint64_t releases_skipped = 0;  ///< by the skip policy

  MissLedger misses;
  qos::ViolationPolicy qos_policy = qos::ViolationPolicy::kFlag;
  std::vector<qos::RuleStatus> constraints;

  scheduler::TimingSummary latency;        ///< wake - release
  scheduler::TimingSummary compute;        ///< the step's computation, I/O excluded
  scheduler::TimingSummary io_time;        ///< the step's board exchange
  scheduler::TimingSummary response;       ///< end - release
  scheduler::TimingSummary period_jitter;  ///< start-to-start minus the period

  LinkFigures link;
  std::optional<RunFault> fault;
  bool outputs_safe = true;  ///< the safe outputs were written when the loop ended
  std::optional<LogFigures> log;
  std::optional<LogFigures> timing_log;  ///< `--timing-log`: every cycle's time stamps
  double wall_time_s = 0.0;
  std::optional<kernel_glue::RtSetupRecord> rt_setup;  ///< absent on the virtual clock
  /// What the command found doubtful about the set-up (e.g. a controller too slow to follow the
  /// encoders), said at the start and kept here: the summary and the JSON `warnings` list them.
  std::vector<std::string> warnings;
};

/// What a run concludes: the one source of the JSON's `verdict`, `complete` and
/// `verdict_text`, the summary's verdict line and the exit code, so none can say more than
/// another.
struct Conclusion {
  /// The QoS verdict of the judged cycles; none when no cycle was judged (stopped, or its peer
  /// lost, before the first judged cycle; a fault at start-up).
  std::optional<qos::Verdict> verdict;
  /// The verdict covers the run: at least one cycle was judged and no fault ended it. False
  /// when a fault ended the run (the verdict then judges only the timing of the cycles run).
  bool complete = false;
  /// The summary's verdict line without its label, e.g. "PASS", or "PASS for the timing of the
  /// 2001 cycles run; the run did NOT finish: model fault at cycle 2000", or "NONE (no cycle was
  /// judged: stopped by SIGTERM before the first judged cycle)".
  std::string text;
};

[[nodiscard]] Conclusion ConclusionOf(const RunReport& report);

/// "PASS", "FLAGGED", "ABORTED", or "NONE" when there is no verdict (the JSON's `verdict`).
[[nodiscard]] const char* VerdictWord(const Conclusion& conclusion) noexcept;

/// The JSON report. Keys of the contract (docs/architecture.md, "Run report") come first and keep
/// their names.
[[nodiscard]] nlohmann::ordered_json ToJson(const RunReport& report);

/// A short human summary for stdout (a few lines, ends with the verdict).
[[nodiscard]] std::string FormatSummary(const RunReport& report);

/// What went wrong or needs attention, one line each, for stderr (empty when nothing did).
[[nodiscard]] std::vector<std::string> Problems(const RunReport& report);

/// The process exit code: an I/O fault or an incomplete log (data or timing) 5, a model fault 1;
/// no verdict (no cycle judged): 128 + the signal when stopped on request (130 SIGINT, 143
/// SIGTERM or a stop command, 129 SIGHUP: what the shell reports for a command that signal
/// ended), otherwise 5 (the peer was lost before the first judged cycle); else the verdict
/// (PASS 0, FLAGGED 3, ABORTED 4).
[[nodiscard]] ExitCode ExitCodeFor(const RunReport& report) noexcept;

}  // namespace hiltwin::runtime
