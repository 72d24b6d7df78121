#include "cycle_runner.h"

#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/tracing/trace.h"
#include "hiltwin/tracing/trace_codes.h"
#include "traced_lifecycle.h"

namespace hiltwin::runtime {

using lifecycle::Event;
using lifecycle::StopReason;

CycleRunner::CycleRunner(RunTask& task, kernel_glue::Clock& clock,
                         lifecycle::Lifecycle& lifecycle, qos::QosMonitor& monitor,
                         const OverrunInjector& injector, const CycleRunnerConfig& config)
    : task_(task),
      clock_(clock),
      lifecycle_(lifecycle),
      monitor_(monitor),
      injector_(injector),
      logger_(config.logger),
      timing_log_(config.timing_log),
      planned_releases_(config.planned_releases),
      task_log_columns_(config.task_log_columns),
      period_ns_(config.period_ns),
      deadline_ns_(config.deadline_ns),
      virtual_compute_ns_(config.virtual_compute_ns),
      violations_seen_(monitor.rules().size(), 0) {}

scheduler::CycleAction CycleRunner::Step(const scheduler::CycleContext& context) noexcept {
  // The rules change only with the state, which changes a few times a run.
  const lifecycle::State state = lifecycle_.state();
  if (!rules_state_ || *rules_state_ != state) [[unlikely]] {
    rules_state_ = state;
    rules_ = lifecycle::RulesOf(state);
  }
  stepped_ = false;
  step_status_ = StepStatus::Ok();
  const kernel_glue::TimeNs io_start_ns = clock_.NowNs();
  const io::ExchangeStatus io = task_.Exchange(rules_.live_outputs);
  SetIoNsOfLastStep(clock_.NowNs() - io_start_ns);
  io_fault_ = io.code == io::ExchangeStatus::Code::kFault;
  peer_stop_seen_ = false;
  if (!io.ok() || io.peer_absent || io.pulse_limit || io.peer_stopped != nullptr) [[unlikely]] {
    NoteExchange(io, context.cycle);
    if (io_fault_) return scheduler::CycleAction::kContinue;  // OnCycle records, then stops
  }
  if (!rules_.steps_model) {
    ++counts_.paused_cycles;
    return scheduler::CycleAction::kContinue;
  }
  step_status_ = task_.Step(context);
  if (!injector_.empty()) InjectOverrun(context.cycle);
  if (!virtual_compute_ns_.empty()) {
    clock_.SpendNs(virtual_compute_ns_[context.cycle % virtual_compute_ns_.size()]);
  }
  if (step_status_.code == StepStatus::Code::kModelFault) {
    NoteFault(StopReason::kModelFault, context.cycle, step_status_.reason);
  } else {
    stepped_ = true;
  }
  return scheduler::CycleAction::kContinue;
}

void CycleRunner::NoteExchange(const io::ExchangeStatus& io, std::uint64_t cycle) noexcept {
  if (io_fault_) {
    TraceIoError(cycle, tracing::IoErrorKind::kFault);
    NoteFault(StopReason::kIoFault, cycle, io.reason);
    return;  // the step is not run on stale inputs: nothing else of this exchange counts
  }
  if (!io.ok()) {
    ++counts_.io_errors;  // the task held its inputs
    TraceIoError(cycle, tracing::IoErrorKind::kHeldInputs);
  }
  if (io.peer_absent) {
    ++counts_.peer_absent_cycles;
    TraceIoError(cycle, tracing::IoErrorKind::kPeerAbsent);
  }
  if (io.pulse_limit) {
    ++counts_.pulse_limit_cycles;
    TraceIoError(cycle, tracing::IoErrorKind::kPulseLimit);
  }
  peer_stop_seen_ = io.peer_stopped != nullptr;
  if (peer_stop_seen_ && peer_stopped_ == nullptr) peer_stopped_ = io.peer_stopped;
}

void CycleRunner::InjectOverrun(std::uint64_t cycle) noexcept {
  const kernel_glue::TimeNs extra_ns = injector_.ExtraNs(cycle);
  if (extra_ns > 0) {
    HILTWIN_TRACE(overrun_injected, cycle, extra_ns);
    clock_.SpendNs(extra_ns);
  }
}

scheduler::CycleAction CycleRunner::OnCycle(const scheduler::TimingSample& sample) noexcept {
  HILTWIN_TRACE(cycle, sample.cycle, sample.release_ns, sample.wake_ns, sample.start_ns,
                sample.end_ns, sample.io_ns, sample.releases_skipped,
                static_cast<std::uint8_t>(sample.missed),
                static_cast<std::uint8_t>(rules_.records_qos));
  if (sample.missed) {
    HILTWIN_TRACE(deadline_miss, sample.cycle, sample.end_ns - sample.release_ns - deadline_ns_);
  }
  if (timing_log_ != nullptr) LogTiming(sample);
  if (telemetry_.snapshot != nullptr) LeaveTelemetry(sample);
  qos_abort_ = false;
  if (rules_.records_qos) RecordQos(sample);
  if (stepped_ && logger_ != nullptr) Log(sample);
  if (!PostEvents(sample)) return scheduler::CycleAction::kContinue;
  return lifecycle_.rules().releases_cycles ? scheduler::CycleAction::kContinue
                                            : scheduler::CycleAction::kStop;
}

[[gnu::always_inline]] inline void CycleRunner::RecordQos(
    const scheduler::TimingSample& sample) noexcept {
  qos_abort_ = monitor_.Record(sample.cycle, sample.missed);
  if (sample.missed || sample.releases_skipped > 0) [[unlikely]] RecordMisses(sample);
}

void CycleRunner::RecordMisses(const scheduler::TimingSample& sample) noexcept {
  // Skipped releases are misses too, but once the monitor says abort the run has ended:
  // releases after that one are not judged.
  for (std::uint32_t i = 1; i <= sample.releases_skipped && !qos_abort_; ++i) {
    qos_abort_ = monitor_.Record(sample.cycle + i, true);
  }
  // A rule's violation count can only rise on a miss: the common cycle skips the loop.
  TraceViolations(sample.cycle);
}

void CycleRunner::TraceViolations(std::uint64_t cycle) noexcept {
  const auto rules = monitor_.rules();
  for (std::size_t i = 0; i < rules.size() && i < violations_seen_.size(); ++i) {
    if (rules[i].violations == violations_seen_[i]) continue;
    violations_seen_[i] = rules[i].violations;
    HILTWIN_TRACE(qos_violation, static_cast<std::uint32_t>(i), cycle, rules[i].distance_to_failure,
                  rules[i].violations);
  }
}

void CycleRunner::TraceIoError(std::uint64_t cycle, tracing::IoErrorKind kind) noexcept {
  HILTWIN_TRACE(io_error, cycle, static_cast<std::uint8_t>(kind));
}

void CycleRunner::LogTiming(const scheduler::TimingSample& sample) noexcept {
  // Nanoseconds since release 0, so the doubles stay exact (timing_log_format.h).
  if (!timing_base_set_) {
    timing_base_ns_ =
        sample.release_ns - static_cast<kernel_glue::TimeNs>(sample.cycle) * period_ns_;
    timing_base_set_ = true;
  }
  const auto rel = [this](kernel_glue::TimeNs t) {
    return static_cast<double>(t - timing_base_ns_);
  };
  const std::array<double, tracing::kTimingLogFields.size()> row = {
      static_cast<double>(sample.cycle),
      rel(sample.release_ns),
      rel(sample.wake_ns),
      rel(sample.start_ns),
      rel(sample.end_ns),
      static_cast<double>(sample.io_ns),
      static_cast<double>(sample.releases_skipped),
      sample.missed ? 1.0 : 0.0,
      rules_.records_qos ? 1.0 : 0.0};
  timing_log_->TryLog(rel(sample.release_ns) * 1e-9, row);
}

void CycleRunner::LeaveTelemetry(const scheduler::TimingSample& sample) noexcept {
  LoopSnapshot& snapshot = telemetry_.snapshot->Back();
  snapshot.cycle = sample.cycle;
  snapshot.task_time_s = task_.LogTimeS();
  task_.FillTelemetry(snapshot.task);
  telemetry_.snapshot->Publish();
  // A full ring (the telemetry thread stalled) drops the value and counts it: the recent
  // latency figure then covers fewer cycles, which the record says (latency_samples).
  static_cast<void>(telemetry_.latencies->TryPush(sample.wake_ns - sample.release_ns));
}

void CycleRunner::Log(const scheduler::TimingSample& sample) noexcept {
  const std::size_t n = task_log_columns_;
  task_.FillLogRow(std::span<double>(row_.data(), n));
  row_[n] = static_cast<double>(sample.cycle);  // release index: model time lags it under skip
  row_[n + 1] = static_cast<double>(sample.wake_ns - sample.release_ns) * 1e-3;
  row_[n + 2] = static_cast<double>(sample.end_ns - sample.start_ns - sample.io_ns) * 1e-3;
  row_[n + 3] = static_cast<double>(sample.io_ns) * 1e-3;
  row_[n + 4] = sample.missed ? 1.0 : 0.0;
  logger_->TryLog(task_.LogTimeS(),
                  std::span<const double>(row_.data(), n + kTimingLogColumns.size()));
}

[[gnu::always_inline]] inline bool CycleRunner::PostEvents(
    const scheduler::TimingSample& sample) noexcept {
  const std::uint64_t next_release = sample.cycle + 1 + sample.releases_skipped;
  const bool plan_done = planned_releases_ != 0 && next_release >= planned_releases_;
  // The common cycle: nothing happened and nothing was asked (relaxed loads only).
  const bool quiet = !io_fault_ && step_status_.code == StepStatus::Code::kOk && !qos_abort_ &&
                     !plan_done && !peer_stop_seen_ && !commands_.MaybeNonEmpty() &&
                     !kernel_glue::StopRequested();
  if (quiet) return false;
  HandleEvents(sample.cycle, plan_done);
  return true;
}

void CycleRunner::HandleEvents(std::uint64_t cycle, bool plan_done) noexcept {
  // Faults first: when several causes meet in one cycle the report names the one that makes
  // the outputs unsafe. Every event goes to the lifecycle from here and nowhere else.
  const auto handle = [this, cycle](Event event) { HandleTraced(lifecycle_, event, cycle); };
  if (io_fault_) handle(Event::kIoFault);
  if (step_status_.code == StepStatus::Code::kModelFault) handle(Event::kModelFault);
  if (qos_abort_) handle(Event::kQosAbort);
  if (kernel_glue::StopRequested()) handle(Event::kStopRequest);
  if (plan_done || step_status_.code == StepStatus::Code::kFinished) {
    handle(Event::kFinishReached);
  }
  if (peer_stop_seen_) handle(Event::kPeerStopped);
  HandleCommands(cycle);
}

void CycleRunner::HandleCommands(std::uint64_t cycle) noexcept {
  SessionCommand command{};
  while (commands_.TryPop(command)) {
    switch (command) {
      case SessionCommand::kStop:
        HandleTraced(lifecycle_, Event::kStopRequest, cycle);
        break;
      case SessionCommand::kPause:
        HandleTraced(lifecycle_, Event::kPause, cycle);
        break;
      case SessionCommand::kResume:
        HandleTraced(lifecycle_, Event::kStart, cycle);
        break;
    }
  }
}

bool CycleRunner::Post(SessionCommand command) noexcept { return commands_.TryPush(command); }

bool CycleRunner::WriteSafeOutputs() noexcept {
  // Delivered to the board is what counts: a wire whose peer is gone still takes them.
  return task_.Exchange(false).board_answered;
}

void CycleRunner::NoteFault(StopReason kind, std::uint64_t cycle, const char* reason) noexcept {
  if (!fault_) fault_ = LoopFault{kind, cycle, reason};
}

}  // namespace hiltwin::runtime
