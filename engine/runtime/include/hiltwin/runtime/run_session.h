#pragma once
/// One run assembly for every command (docs/architecture.md, "The run assembly"). Given a validated
/// configuration and a task, a RunSession owns, in this order: the executive, the QoS monitor (the
/// one miss ledger), the lifecycle, the CSV logger; then, in Run(), the loop thread (created
/// through kernel_glue::NamedThread, raised to SCHED_FIFO and pinned by the RT set-up on itself),
/// the logger's writer thread (SCHED_OTHER on the CPUs the loop does not use), the loop, the safe
/// outputs, the drain, and the typed RunReport. The calling (control) thread stays SCHED_OTHER and
/// prints the progress line; no other thread exists. Its section draws it.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/io/peer_link.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/runtime/run_task.h"
#include "hiltwin/runtime/session_command.h"
#include "hiltwin/runtime/telemetry.h"
#include "hiltwin/runtime/virtual_costs.h"
#include "hiltwin/scheduler/executive.h"
#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::runtime {

class CycleRunner;
class TelemetryPublisher;

/// Where and how often to log.
struct LogConfig {
  std::string path;
  std::uint32_t decimation = 1;  ///< every Nth cycle
};

/// The process on the other end of the link (wire): the session waits for it in `ready`, with a
/// countdown, and tells it why this side stopped once the outputs are safe.
struct PeerWait {
  io::PeerLink* link = nullptr;  ///< not owned; must outlive the session
  /// Waiting longer than this ends the run as an I/O fault; 0: start at once without waiting
  /// (cycles without a peer are then counted as peer_absent_cycles).
  double timeout_s = 30.0;
  std::string start_hint;  ///< the command that starts the other side, for messages
};

/// A validated run, as plain data (cactus-rt style config struct).
struct SessionConfig {
  std::string task_name = "task";  ///< for the report, e.g. "RELbot twin"
  std::string io;                  ///< backend spec, for the report
  std::string peer_name = "peer";  ///< who is on the other side of the link
  std::vector<std::pair<std::string, std::string>> details;  ///< app facts for the report
  std::vector<std::string> warnings;  ///< said at the start by the command; in the report
  ClockKind clock = ClockKind::kRealtime;
  double rate_hz = 4000.0;
  scheduler::ExecutiveConfig executive;  ///< max_cycles: the planned releases (0: until stopped)
  qos::QosConfig qos;
  kernel_glue::RtSetupRequest rt;  ///< applied to the loop thread (realtime clock only)
  OverrunInjector injector;
  /// Virtual clock only: the wake-up latency and compute time every cycle is charged
  /// (virtual_costs.h). Empty: the virtual loop takes no time.
  VirtualCycleCosts virtual_costs;
  std::optional<LogConfig> log;
  /// Every cycle's time stamps, through a second RT-safe logger (tracing/timing_log_format.h):
  /// the trace for users who may not use LTTng. Empty: none.
  std::string timing_log_path;
  bool progress = false;  ///< a throttled progress line on stderr, from the control thread
  /// SIGUSR1 pauses and SIGUSR2 resumes the run (forwarded by the control thread within
  /// 100 ms). Off by default: the handlers are process-wide, the command decides.
  bool pause_signals = false;
  /// Live telemetry (telemetry.h): no sinks, no telemetry thread and no per-cycle cost.
  TelemetryConfig telemetry;
  /// Set when the link has a process on its other end (wire); empty otherwise.
  std::optional<PeerWait> peer;
  /// The virtual clock the link shares with its peer (a wire in lockstep, not owned): the
  /// loop runs on it instead of a VirtualClock of its own. Needs ClockKind::kVirtual, a peer
  /// to wait for, and no virtual costs (the peer's time would not be charged them).
  kernel_glue::Clock* lockstep_clock = nullptr;
  /// Called on the control thread once the loop thread is set up, before the first cycle:
  /// the RT set-up record (null on the virtual clock). For the command's start-up lines.
  std::function<void(const kernel_glue::RtSetupRecord*)> on_ready;
};

/// Test hooks run on the loop thread around the loop (e.g. to count allocations there).
class LoopThreadHooks {
 public:
  virtual ~LoopThreadHooks() = default;
  virtual void BeforeLoop() noexcept {}
  /// After the loop and the safe outputs.
  virtual void AfterLoop() noexcept {}
};

/// A telemetry sink could not be opened for this task (the message says which and why).
class TelemetryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RunSession {
 public:
  /// Builds everything, opens the log (truncating it) and the telemetry sinks. Throws
  /// std::invalid_argument for a bad configuration, TelemetryError when a sink cannot be
  /// opened and std::runtime_error when the log cannot be created; the messages name domain
  /// values, not flags. `task` must outlive the session.
  RunSession(SessionConfig config, RunTask& task);
  ~RunSession();
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  /// Runs the session to its end (see the header comment) and returns its report. Call once.
  /// Throws std::runtime_error when a thread cannot be started.
  [[nodiscard]] RunReport Run();

  /// Thread-safe and lock-free; acted on by the loop after its current cycle, in the order
  /// posted. False when the loop has not yet taken the commands before it (queue full).
  bool Post(SessionCommand command) noexcept;
  void SetLoopThreadHooks(LoopThreadHooks* hooks) noexcept { hooks_ = hooks; }

 private:
  struct LoopResult;
  void LoopThreadMain(LoopResult& result) noexcept;
  /// The constructor's last step when telemetry is asked for: opens the sinks for this task.
  void OpenTelemetry();
  void PrintProgress() const;
  /// Control thread, in `ready`: polls the peer until it is up (true), the wait times out
  /// (io_fault) or a stop signal arrives (stop_requested).
  [[nodiscard]] bool WaitForPeer();
  void ForwardPauseSignal() noexcept;
  /// Drains and closes the data log and the timing log (after the loop).
  void StopLoggers();
  /// Releases the parked loop thread without running a cycle and joins it.
  static void CancelLoop(LoopResult& result, std::unique_lock<std::mutex>& lock,
                         kernel_glue::NamedThread& loop);
  [[nodiscard]] RunReport BuildReport(const LoopResult& result, double wall_time_s) const;

  SessionConfig config_;
  RunTask& task_;
  std::unique_ptr<kernel_glue::Clock> own_clock_;  ///< null on a lockstep clock
  kernel_glue::Clock* clock_;                       ///< the loop's clock
  lifecycle::Lifecycle lifecycle_;
  qos::QosMonitor monitor_;
  scheduler::Executive executive_;
  std::unique_ptr<tracing::CsvLogger> logger_;
  std::unique_ptr<tracing::CsvLogger> timing_log_;
  std::unique_ptr<CycleRunner> runner_;
  std::vector<int> allowed_cpus_;  ///< the process's CPUs, read before anything is pinned
  LoopThreadHooks* hooks_ = nullptr;
  std::optional<RunFault> wait_fault_;  ///< the peer never came
  const char* wait_peer_stopped_ = "";   ///< the peer ended while this side waited (static text)
  bool ran_ = false;
  /// Last: destroyed first, so its thread has stopped before what it reads goes away.
  std::unique_ptr<TelemetryPublisher> telemetry_;
};

}  // namespace hiltwin::runtime
