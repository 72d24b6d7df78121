#pragma once
// The per-cycle path of a RunSession, on the loop thread: asks the lifecycle what the state
// allows (RulesOf), times the board exchange apart from the step, applies fault injection,
// records the cycle in the QoS monitor (the one miss ledger), fires the cycle tracepoint,
// offers the log row, and turns every status and stop cause into a lifecycle event. Nothing
// here allocates, blocks, prints or throws.

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/lockfree/command_queue.h"
#include "hiltwin/lockfree/latest_value.h"
#include "hiltwin/lockfree/spsc_ring.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/runtime/run_task.h"
#include "hiltwin/runtime/session_command.h"
#include "hiltwin/scheduler/cycle.h"
#include "hiltwin/tracing/csv_logger.h"
#include "hiltwin/tracing/timing_log_format.h"
#include "hiltwin/tracing/trace_codes.h"

namespace hiltwin::runtime {

/// Commands queued at once before the loop takes them (it takes all of them every cycle).
inline constexpr std::size_t kCommandQueueCapacity = 16;

/// Where the loop leaves telemetry for the telemetry thread (telemetry.h); none owned.
struct TelemetryTaps {
  lockfree::LatestValue<LoopSnapshot>* snapshot = nullptr;  ///< written every cycle
  /// Every cycle's wake-up latency, ns.
  lockfree::SpscQueue<std::int64_t>* latencies = nullptr;
};

/// The first fault of a run, as the loop saw it (reason is static text).
struct LoopFault {
  lifecycle::StopReason kind = lifecycle::StopReason::kNone;
  std::uint64_t cycle = 0;
  const char* reason = "";
};

/// Counts only the loop knows; read after the loop has stopped.
struct LoopCounts {
  std::uint64_t io_errors = 0;
  std::uint64_t peer_absent_cycles = 0;
  std::uint64_t pulse_limit_cycles = 0;
  std::uint64_t paused_cycles = 0;
};

/// Timing columns the session appends to every task's log row.
inline constexpr std::array<const char*, 5> kTimingLogColumns = {"cycle", "latency_us",
                                                                 "compute_us", "io_us", "missed"};

/// The runner's fixed figures and sinks (none owned).
struct CycleRunnerConfig {
  tracing::CsvLogger* logger = nullptr;      ///< the data log; null: none
  tracing::CsvLogger* timing_log = nullptr;  ///< the timing log; null: none
  std::uint64_t planned_releases = 0;        ///< 0: until stopped
  std::size_t task_log_columns = 0;
  kernel_glue::TimeNs period_ns = 0;
  kernel_glue::TimeNs deadline_ns = 0;
  /// Virtual clock: compute time charged to cycle k, table[k % size] (virtual_costs.h).
  std::span<const kernel_glue::TimeNs> virtual_compute_ns;
};

class CycleRunner final : public scheduler::CyclicTask, public scheduler::CycleObserver {
 public:
  /// None of the references is owned. Allocates its per-rule bookkeeping here, never later.
  CycleRunner(RunTask& task, kernel_glue::Clock& clock, lifecycle::Lifecycle& lifecycle,
              qos::QosMonitor& monitor, const OverrunInjector& injector,
              const CycleRunnerConfig& config);

  scheduler::CycleAction Step(const scheduler::CycleContext& context) noexcept override;
  scheduler::CycleAction OnCycle(const scheduler::TimingSample& sample) noexcept override;

  /// Thread-safe and lock-free: the loop acts on it after the current cycle, in the order
  /// posted. False when the queue is full (the command was not taken).
  [[nodiscard]] bool Post(SessionCommand command) noexcept;
  /// Before the loop starts: where to leave telemetry every cycle (off by default).
  void AttachTelemetry(const TelemetryTaps& taps) noexcept { telemetry_ = taps; }

  /// One exchange with safe outputs, after the loop: true when the board took and answered it.
  [[nodiscard]] bool WriteSafeOutputs() noexcept;

  [[nodiscard]] const LoopCounts& counts() const noexcept { return counts_; }
  [[nodiscard]] const std::optional<LoopFault>& fault() const noexcept { return fault_; }
  /// Why the peer ended its run, when it did (wire); null otherwise. Static text.
  [[nodiscard]] const char* peer_stopped() const noexcept { return peer_stopped_; }

 private:
  void RecordQos(const scheduler::TimingSample& sample) noexcept;
  void Log(const scheduler::TimingSample& sample) noexcept;
  void LogTiming(const scheduler::TimingSample& sample) noexcept;
  void LeaveTelemetry(const scheduler::TimingSample& sample) noexcept;
  /// Offers the queued commands to the lifecycle, in the order they were posted.
  void HandleCommands(std::uint64_t cycle) noexcept;
  /// Fires hiltwin:qos_violation for every rule whose violation count rose at `cycle`.
  void TraceViolations(std::uint64_t cycle) noexcept;
  void TraceIoError(std::uint64_t cycle, tracing::IoErrorKind kind) noexcept;
  /// Offers this cycle's events to the lifecycle; false when there were none (the state is
  /// unchanged, the common case).
  bool PostEvents(const scheduler::TimingSample& sample) noexcept;
  /// The events of a cycle that had some, in the order the report's cause needs.
  [[gnu::noinline]] void HandleEvents(std::uint64_t cycle, bool plan_done) noexcept;
  /// The QoS part of a cycle that missed or skipped releases (out of the common path).
  [[gnu::noinline]] void RecordMisses(const scheduler::TimingSample& sample) noexcept;
  void NoteFault(lifecycle::StopReason kind, std::uint64_t cycle, const char* reason) noexcept;
  /// Counts and traces an exchange that was not plainly ok (out of the common cycle's path).
  [[gnu::cold, gnu::noinline]] void NoteExchange(const io::ExchangeStatus& io,
                                                 std::uint64_t cycle) noexcept;
  /// Spends the injected extra compute time of `cycle`, if any (only with --inject-overrun).
  [[gnu::noinline]] void InjectOverrun(std::uint64_t cycle) noexcept;

  RunTask& task_;
  kernel_glue::Clock& clock_;
  lifecycle::Lifecycle& lifecycle_;
  qos::QosMonitor& monitor_;
  const OverrunInjector& injector_;
  tracing::CsvLogger* logger_;
  tracing::CsvLogger* timing_log_;
  std::uint64_t planned_releases_;
  std::size_t task_log_columns_;
  kernel_glue::TimeNs period_ns_;
  kernel_glue::TimeNs deadline_ns_;
  std::span<const kernel_glue::TimeNs> virtual_compute_ns_;
  std::array<double, tracing::kMaxLogColumns> row_{};
  std::vector<std::uint64_t> violations_seen_;  ///< per rule, as last traced
  kernel_glue::TimeNs timing_base_ns_ = 0;      ///< release 0's time, for the timing log
  bool timing_base_set_ = false;

  // This cycle, from Step to OnCycle. Only the loop thread changes the state while the loop
  // runs, so the rules read in Step hold until OnCycle posts events.
  lifecycle::StateRules rules_;
  std::optional<lifecycle::State> rules_state_;  ///< the state rules_ are of (none yet)
  bool stepped_ = false;
  bool io_fault_ = false;
  StepStatus step_status_;
  bool qos_abort_ = false;
  bool peer_stop_seen_ = false;  ///< this cycle's exchange reported the peer's stop

  LoopCounts counts_;
  std::optional<LoopFault> fault_;
  const char* peer_stopped_ = nullptr;
  lockfree::CommandQueue<SessionCommand, kCommandQueueCapacity> commands_;
  TelemetryTaps telemetry_;
};

}  // namespace hiltwin::runtime
