#include "hiltwin/runtime/run_session.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "costed_virtual_clock.h"
#include "cycle_runner.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/tracing/timing_log_format.h"
#include "hiltwin/tracing/trace.h"
#include "hiltwin/tracing/trace_codes.h"
#include "telemetry_publisher.h"
#include "traced_lifecycle.h"

namespace hiltwin::runtime {
namespace {

/// The loop's own clock; null when it runs on the link's lockstep clock.
std::unique_ptr<kernel_glue::Clock> MakeClock(const SessionConfig& config) {
  if (config.lockstep_clock != nullptr) return nullptr;
  if (config.clock == ClockKind::kRealtime) return std::make_unique<kernel_glue::MonotonicClock>();
  if (config.virtual_costs.wake_latency_ns.empty()) {
    return std::make_unique<kernel_glue::VirtualClock>();
  }
  return std::make_unique<CostedVirtualClock>(config.virtual_costs.wake_latency_ns);
}

void CheckVirtualCosts(const SessionConfig& config) {
  if (config.virtual_costs.empty()) return;
  if (config.clock != ClockKind::kVirtual) {
    // On the real clock the machine charges its own costs; replaying a table on top of them
    // would count every cost twice.
    throw std::invalid_argument("virtual cycle costs apply to the virtual clock only");
  }
  const auto negative = [](const std::vector<kernel_glue::TimeNs>& table) {
    for (const kernel_glue::TimeNs ns : table) {
      if (ns < 0) return true;
    }
    return false;
  };
  if (negative(config.virtual_costs.wake_latency_ns) || negative(config.virtual_costs.compute_ns)) {
    throw std::invalid_argument("a virtual cycle cost is negative; costs are durations >= 0 ns");
  }
}

std::unique_ptr<tracing::CsvLogger> MakeLogger(const SessionConfig& config, const RunTask& task,
                                               const std::vector<int>& allowed_cpus) {
  if (!config.log) return nullptr;
  tracing::CsvLoggerConfig log;
  log.path = config.log->path;
  log.columns = task.LogColumns();
  log.columns.insert(log.columns.end(), kTimingLogColumns.begin(), kTimingLogColumns.end());
  log.decimation = config.log->decimation;
  // No deadline on the virtual clock: keep every row rather than drop when the writer lags.
  log.wait_when_full = config.clock == ClockKind::kVirtual;
  log.writer_cpus = kernel_glue::HelperCpus(allowed_cpus, config.rt.cpus);
  return std::make_unique<tracing::CsvLogger>(std::move(log));
}

/// The timing log: every cycle, its format in its preamble (tracing/timing_log_format.h).
std::unique_ptr<tracing::CsvLogger> MakeTimingLog(const SessionConfig& config,
                                                  kernel_glue::TimeNs period_ns,
                                                  kernel_glue::TimeNs deadline_ns,
                                                  const std::vector<int>& allowed_cpus) {
  if (config.timing_log_path.empty()) return nullptr;
  tracing::CsvLoggerConfig log;
  log.path = config.timing_log_path;
  log.columns.assign(tracing::kTimingLogFields.begin(), tracing::kTimingLogFields.end());
  log.preamble = {std::string(tracing::kTimingLogMagic), "period_ns=" + std::to_string(period_ns),
                  "deadline_ns=" + std::to_string(deadline_ns),
                  "planned_cycles=" + std::to_string(config.executive.max_cycles)};
  for (const qos::RuleSpec& rule : config.qos.rules) {
    log.preamble.push_back(
        std::string("rule=") + qos::ToString(rule.kind) + " m=" + std::to_string(rule.m) +
        " k=" + std::to_string(rule.k) + " n=" + std::to_string(rule.n) + " max_miss_ppm=" +
        std::to_string(std::llround(rule.max_miss_pct * tracing::kPpmPerPercent)));
  }
  log.wait_when_full = config.clock == ClockKind::kVirtual;
  log.writer_cpus = kernel_glue::HelperCpus(allowed_cpus, config.rt.cpus);
  return std::make_unique<tracing::CsvLogger>(std::move(log));
}

/// hiltwin:loop_start and one hiltwin:qos_rule per rule, from the loop thread.
void TraceLoopStart(const SessionConfig& config, const scheduler::Executive& executive,
                    const std::optional<kernel_glue::RtSession>& rt) noexcept {
  const int priority = rt ? rt->record().fifo_priority : 0;
  const int policy = rt && rt->record().sched_fifo ? SCHED_FIFO : SCHED_OTHER;
  HILTWIN_TRACE(loop_start, static_cast<std::int32_t>(::gettid()),
                static_cast<std::int32_t>(::sched_getcpu()), policy, priority,
                executive.config().period_ns, executive.deadline_ns(), config.executive.max_cycles,
                static_cast<std::uint32_t>(config.qos.rules.size()));
  for (std::size_t i = 0; i < config.qos.rules.size(); ++i) {
    const qos::RuleSpec& rule = config.qos.rules[i];
    HILTWIN_TRACE(
        qos_rule, static_cast<std::uint32_t>(i), static_cast<std::uint8_t>(rule.kind), rule.m,
        rule.k, rule.n,
        static_cast<std::uint32_t>(std::lround(rule.max_miss_pct * tracing::kPpmPerPercent)));
  }
}

io::StopCause StopCauseOf(lifecycle::StopReason reason) noexcept {
  using lifecycle::StopReason;
  switch (reason) {
    case StopReason::kFinished:
      return io::StopCause::kFinished;
    case StopReason::kStopRequested:
      return io::StopCause::kStopRequested;
    case StopReason::kQosAbort:
      return io::StopCause::kQosAbort;
    case StopReason::kIoFault:
    case StopReason::kModelFault:
      return io::StopCause::kFault;
    case StopReason::kPeerStopped:
      return io::StopCause::kPeerStopped;
    case StopReason::kNone:
      break;
  }
  return io::StopCause::kFault;  // the loop ended without a cause: say something is wrong
}

/// "12.5" for messages.
std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", s);
  return text;
}

void CheckConfig(const SessionConfig& config) {
  const std::uint64_t planned = config.executive.max_cycles;
  if (planned != 0 && config.qos.grace_cycles >= planned) {
    // A grace period that covers the whole run would judge nothing and always PASS.
    throw std::invalid_argument("a grace period of " + std::to_string(config.qos.grace_cycles) +
                                " releases covers the whole run of " + std::to_string(planned) +
                                "; judge at least one release");
  }
  if (config.qos.planned_cycles != planned) {
    throw std::invalid_argument("the QoS plan (" + std::to_string(config.qos.planned_cycles) +
                                " releases) differs from the run's (" + std::to_string(planned) +
                                ")");
  }
  config.injector.CheckFiresWithin(planned);
  CheckVirtualCosts(config);
  if (config.lockstep_clock != nullptr) {
    if (config.clock != ClockKind::kVirtual || !config.lockstep_clock->IsVirtual()) {
      throw std::invalid_argument(
          "a lockstep clock is a virtual clock: it needs ClockKind::kVirtual");
    }
    if (!config.peer || config.peer->timeout_s == 0.0) {
      // The time base starts when both sides are there: a side that ran ahead alone would
      // begin the shared time where the other cannot follow.
      throw std::invalid_argument("a lockstep run waits for its peer before its first cycle: "
                                  "give the wait a timeout above 0 s");
    }
    if (!config.virtual_costs.empty()) {
      throw std::invalid_argument("virtual cycle costs do not apply to a lockstep clock");
    }
  }
  if (config.peer && (config.peer->link == nullptr || !(config.peer->timeout_s >= 0.0))) {
    throw std::invalid_argument("waiting for the peer needs a link and a timeout of 0 s or more");
  }
  if (config.rt.fifo_priority < 0 || config.rt.fifo_priority > 99) {
    throw std::invalid_argument("SCHED_FIFO priority " + std::to_string(config.rt.fifo_priority) +
                                " is outside 0 (none) .. 99");
  }
}

}  // namespace

/// What the loop thread hands back to the control thread.
struct RunSession::LoopResult {
  std::mutex mutex;
  std::condition_variable changed;
  bool ready = false;  // RT set-up done, waiting for go
  bool go = false;
  bool cancelled = false;  // start-up failed on the control thread: run no cycle
  bool done = false;
  std::optional<kernel_glue::RtSession> rt;
  std::string setup_error;
  bool outputs_safe = false;
};

RunSession::RunSession(SessionConfig config, RunTask& task)
    : config_((CheckConfig(config), std::move(config))),  // checked before anything is built
      task_(task),
      own_clock_(MakeClock(config_)),
      clock_(own_clock_ ? own_clock_.get() : config_.lockstep_clock),
      monitor_(config_.qos),
      executive_(*clock_, config_.executive),
      allowed_cpus_(kernel_glue::AllowedCpus()) {
  if (task_.LogColumns().size() + kTimingLogColumns.size() > tracing::kMaxLogColumns) {
    throw std::invalid_argument("the task logs " + std::to_string(task_.LogColumns().size()) +
                                " columns; at most " +
                                std::to_string(tracing::kMaxLogColumns - kTimingLogColumns.size()) +
                                " fit beside the timing columns");
  }
  logger_ = MakeLogger(config_, task_, allowed_cpus_);
  timing_log_ = MakeTimingLog(config_, executive_.config().period_ns, executive_.deadline_ns(),
                              allowed_cpus_);
  CycleRunnerConfig runner;
  runner.logger = logger_.get();
  runner.timing_log = timing_log_.get();
  runner.planned_releases = config_.executive.max_cycles;
  runner.task_log_columns = task_.LogColumns().size();
  runner.period_ns = executive_.config().period_ns;
  runner.deadline_ns = executive_.deadline_ns();
  runner.virtual_compute_ns = config_.virtual_costs.compute_ns;
  runner_ =
      std::make_unique<CycleRunner>(task_, *clock_, lifecycle_, monitor_, config_.injector, runner);
  executive_.AddObserver(*runner_);
  if (!config_.telemetry.sinks.empty()) OpenTelemetry();
  HandleTraced(lifecycle_, lifecycle::Event::kConfigured, 0);
}

RunSession::~RunSession() = default;

void RunSession::OpenTelemetry() {
  TelemetryIdentity identity{config_.telemetry.ns, config_.rate_hz, config_.executive.max_cycles};
  // Threads the sinks start as they open (HTTP workers) belong on the helper CPUs.
  const kernel_glue::ScopedThreadCpus on_helpers(
      kernel_glue::HelperCpus(allowed_cpus_, config_.rt.cpus));
  TelemetryShape shape = task_.TelemetryShapeOf();
  shape.virtual_clock = config_.clock == ClockKind::kVirtual;
  shape.lockstep = config_.lockstep_clock != nullptr;
  try {
    telemetry_ = std::make_unique<TelemetryPublisher>(
        config_.telemetry, shape, std::move(identity),
        TelemetrySources{monitor_, executive_, lifecycle_},
        [this](SessionCommand command) { return runner_->Post(command); });
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw TelemetryError(e.what());
  }
  runner_->AttachTelemetry(telemetry_->taps());
}

bool RunSession::Post(SessionCommand command) noexcept { return runner_->Post(command); }

void RunSession::LoopThreadMain(LoopResult& result) noexcept {
  {
    std::unique_lock lock(result.mutex);
    if (config_.clock == ClockKind::kRealtime) {
      // On this thread: SCHED_FIFO, affinity and the stack pre-fault act on the caller.
      // Before the writer thread exists, because mallopt is process-wide and not thread-safe.
      try {
        result.rt.emplace(kernel_glue::RtSession::Apply(config_.rt));
      } catch (const std::exception& e) {
        result.setup_error = e.what();
      }
    }
    result.ready = true;
    result.changed.notify_all();
    result.changed.wait(lock, [&] { return result.go; });
    if (result.cancelled) return;
  }
  if (hooks_ != nullptr) hooks_->BeforeLoop();
  TraceLoopStart(config_, executive_, result.rt);
  // Why the loop ended is the lifecycle's to say (the runner posted the event that ended it);
  // the executive's own stop cause adds nothing.
  static_cast<void>(executive_.Run(*runner_));
  HILTWIN_TRACE(loop_end, executive_.stats().cycles_run, executive_.stats().releases);
  // Leaving run or paused: the outputs go safe at once, from the loop thread.
  result.outputs_safe = runner_->WriteSafeOutputs();
  // Then the peer learns why: it stops cleanly instead of waiting for a heartbeat timeout.
  if (config_.peer) config_.peer->link->AnnounceStop(StopCauseOf(lifecycle_.stop_reason()));
  if (hooks_ != nullptr) hooks_->AfterLoop();
  std::lock_guard lock(result.mutex);
  result.done = true;
  result.changed.notify_all();
}

RunReport RunSession::Run() {
  if (ran_) throw std::logic_error("RunSession::Run called twice");
  ran_ = true;
  kernel_glue::InstallStopSignalHandlers();
  if (config_.pause_signals) kernel_glue::InstallPauseSignalHandlers();
  LoopResult result;
  kernel_glue::NamedThread loop({"hiltwin-loop", allowed_cpus_},
                                [this, &result] { LoopThreadMain(result); });
  std::unique_lock lock(result.mutex);
  result.changed.wait(lock, [&] { return result.ready; });
  try {
    if (!result.setup_error.empty())
      throw std::runtime_error("real-time set-up: " + result.setup_error);
    if (logger_) logger_->Start();  // after the RT set-up: see LoopThreadMain
    if (timing_log_) timing_log_->Start();
    if (config_.on_ready) config_.on_ready(result.rt ? &result.rt->record() : nullptr);
    // Before the wait for a peer: a twin that waits already shows on the monitor (ready).
    if (telemetry_) telemetry_->Start(kernel_glue::HelperCpus(allowed_cpus_, config_.rt.cpus));
  } catch (...) {
    // Release the waiting loop thread without running a cycle, then report the failure.
    CancelLoop(result, lock, loop);
    throw;
  }
  if (config_.peer && !WaitForPeer()) {
    CancelLoop(result, lock, loop);
    result.outputs_safe = true;  // never left the safe outputs
    config_.peer->link->AnnounceStop(StopCauseOf(lifecycle_.stop_reason()));
    StopLoggers();
    HandleTraced(lifecycle_, lifecycle::Event::kDrained, 0);
    if (telemetry_) telemetry_->Stop();  // the final record: safe_stop or stopped
    return BuildReport(result, 0.0);
  }
  // The control thread is a helper too while the loop runs: off the loop's CPUs. Best effort:
  // a refusal leaves it where it was, which costs the loop nothing it did not have before.
  const std::vector<int> helper_cpus = kernel_glue::HelperCpus(allowed_cpus_, config_.rt.cpus);
  static_cast<void>(kernel_glue::SetCallingThreadCpus(helper_cpus));
  const kernel_glue::MonotonicClock wall;
  const kernel_glue::TimeNs wall_start_ns = wall.NowNs();
  HandleTraced(lifecycle_, lifecycle::Event::kStart, 0);
  result.go = true;
  result.changed.notify_all();
  // The control thread's duty while the loop runs: keep this process's presence on the link
  // fresh (a lockstep loop may wait long for its log writer), forward signal commands every
  // 100 ms and print the progress line every 300 ms.
  const auto loop_done = [&] { return result.done; };
  for (int tick = 1; !result.changed.wait_for(lock, std::chrono::milliseconds(100), loop_done);
       ++tick) {
    if (config_.peer) config_.peer->link->KeepAlive();
    if (config_.pause_signals) ForwardPauseSignal();
    if (config_.progress && tick % 3 == 0) PrintProgress();
  }
  lock.unlock();
  loop.Join();
  static_cast<void>(kernel_glue::SetCallingThreadCpus(allowed_cpus_));
  const double wall_time_s = static_cast<double>(wall.NowNs() - wall_start_ns) * 1e-9;
  if (config_.progress) {
    PrintProgress();
    std::fputc('\n', stderr);
  }
  StopLoggers();
  HandleTraced(lifecycle_, lifecycle::Event::kDrained, executive_.stats().releases);
  if (telemetry_) telemetry_->Stop();  // the final record, with the run's last state
  return BuildReport(result, wall_time_s);
}

void RunSession::StopLoggers() {
  if (logger_) logger_->Stop();
  if (timing_log_) timing_log_->Stop();
}

void RunSession::CancelLoop(LoopResult& result, std::unique_lock<std::mutex>& lock,
                            kernel_glue::NamedThread& loop) {
  result.cancelled = true;
  result.go = true;
  result.changed.notify_all();
  lock.unlock();
  loop.Join();
}

bool RunSession::WaitForPeer() {
  const PeerWait& wait = *config_.peer;
  if (wait.timeout_s == 0.0) return true;
  const kernel_glue::MonotonicClock clock;
  const kernel_glue::TimeNs start_ns = clock.NowNs();
  const auto timeout_ns = static_cast<kernel_glue::TimeNs>(wait.timeout_s * 1e9);
  const std::string what = "the " + config_.peer_name + " on " + config_.io;
  long long shown_s = -1;
  for (;;) {
    const io::BusStatus status = wait.link->Poll();
    if (status.result == io::BusResult::kOk) {
      if (shown_s >= 0 && config_.progress) std::fputc('\n', stderr);
      std::fprintf(stderr, "hiltwin: %s is up; starting\n", what.c_str());
      return true;
    }
    if (kernel_glue::StopRequested()) {
      HandleTraced(lifecycle_, lifecycle::Event::kStopRequest, 0);
      return false;
    }
    if (status.result == io::BusResult::kPeerStopped) {
      // The peer came up, ran and ended before this side saw it up (a twin that aborts in its
      // first cycles on a loaded machine): end now, as a cycle would have, not at the timeout.
      if (shown_s >= 0 && config_.progress) std::fputc('\n', stderr);
      wait_peer_stopped_ = status.reason;
      HandleTraced(lifecycle_, lifecycle::Event::kPeerStopped, 0);
      return false;
    }
    if (status.result == io::BusResult::kPeerMismatch) {
      // A peer on the other clock came: refused at once, it will not change its mind.
      if (shown_s >= 0 && config_.progress) std::fputc('\n', stderr);
      wait_fault_ = RunFault{lifecycle::StopReason::kIoFault, 0, status.reason};
      HandleTraced(lifecycle_, lifecycle::Event::kIoFault, 0);
      return false;
    }
    const kernel_glue::TimeNs waited_ns = clock.NowNs() - start_ns;
    if (waited_ns >= timeout_ns) {
      if (shown_s >= 0 && config_.progress) std::fputc('\n', stderr);
      wait_fault_ = RunFault{lifecycle::StopReason::kIoFault, 0,
                             "no " + config_.peer_name + " came up on " + config_.io + " within " +
                                 Seconds(wait.timeout_s) + " s (" + status.reason +
                                 "); start it with: " + wait.start_hint};
      HandleTraced(lifecycle_, lifecycle::Event::kIoFault, 0);
      return false;
    }
    // A countdown: rewritten in place on a terminal, a line every 5 s otherwise.
    const long long left_s = (timeout_ns - waited_ns + 999'999'999) / 1'000'000'000;
    if (left_s != shown_s && (config_.progress || shown_s < 0 || left_s % 5 == 0)) {
      std::fprintf(stderr, "%shiltwin: waiting for %s: %lld s left; start it with: %s%s",
                   config_.progress ? "\r" : "", what.c_str(), left_s, wait.start_hint.c_str(),
                   config_.progress ? "   " : "\n");
      std::fflush(stderr);
      shown_s = left_s;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void RunSession::ForwardPauseSignal() noexcept {
  switch (kernel_glue::TakePauseRequest()) {
    case kernel_glue::PauseRequest::kPause:
      static_cast<void>(Post(SessionCommand::kPause));
      break;
    case kernel_glue::PauseRequest::kResume:
      static_cast<void>(Post(SessionCommand::kResume));
      break;
    case kernel_glue::PauseRequest::kNone:
      break;
  }
}

void RunSession::PrintProgress() const {
  const qos::LiveQos q = monitor_.Live();
  const std::string distance = q.distance_to_failure == qos::kNeverFails
                                   ? std::string("-")
                                   : std::to_string(q.distance_to_failure);
  std::fprintf(stderr,
               "\r  %llu/%llu cycles  %s  misses %llu  worst latency %.1f us  verdict so far %s  "
               "misses to failure %s   ",
               static_cast<unsigned long long>(executive_.live().cycles_run.load()),
               static_cast<unsigned long long>(config_.executive.max_cycles),
               lifecycle::ToString(lifecycle_.state()),
               static_cast<unsigned long long>(q.deadline_misses),
               static_cast<double>(executive_.live().max_latency_ns.load()) / 1e3,
               qos::ToString(q.verdict), distance.c_str());
  std::fflush(stderr);
}

}  // namespace hiltwin::runtime

namespace hiltwin::runtime {
namespace {

MissLedger LedgerOf(const qos::QosMonitor& m) {
  MissLedger ledger;
  ledger.releases = m.releases_recorded();
  ledger.deadline_misses = m.all_misses();
  ledger.miss_pct = m.all_miss_pct();
  ledger.max_consecutive_misses = m.max_consecutive_all_misses();
  ledger.grace_cycles = m.config().grace_cycles;
  ledger.grace_misses = m.grace_misses();
  ledger.cycles_judged = m.cycles_recorded();
  ledger.misses_judged = m.misses();
  ledger.miss_pct_judged = m.miss_pct();
  ledger.max_consecutive_misses_judged = m.max_consecutive_misses();
  ledger.abort_cycle = m.abort_cycle();
  return ledger;
}

LogFigures LogFiguresOf(const tracing::CsvLogger& log) {
  return LogFigures{log.path(),  log.rows_written(), log.rows_dropped(),
                    log.rows_lost(), log.error(),    log.error_reason()};
}

}  // namespace

RunReport RunSession::BuildReport(const LoopResult& result, double wall_time_s) const {
  RunReport r;
  r.task_name = config_.task_name;
  r.io = config_.io;
  r.clock = config_.clock;
  r.details = config_.details;
  r.verdict = monitor_.verdict();
  r.stop_reason = lifecycle_.stop_reason();
  if (r.stop_reason == lifecycle::StopReason::kStopRequested) {
    r.stop_signal = std::max(kernel_glue::StopSignal(), 0);  // -1: RequestStop from code
  }
  r.fault_while_stopping = lifecycle_.fault_while_stopping();
  r.final_state = lifecycle_.state();
  const scheduler::ExecutiveStats& stats = executive_.stats();
  r.rate_hz = config_.rate_hz;
  r.period_ns = executive_.config().period_ns;
  r.deadline_ns = executive_.deadline_ns();
  r.overrun_policy = executive_.config().overrun_policy;
  r.cycles_planned = config_.executive.max_cycles;
  r.cycles_run = stats.cycles_run;
  r.cycles_paused = runner_->counts().paused_cycles;
  r.releases = stats.releases;
  r.releases_skipped = stats.releases_skipped;
  r.misses = LedgerOf(monitor_);
  r.qos_policy = monitor_.config().policy;
  r.constraints.assign(monitor_.rules().begin(), monitor_.rules().end());
  r.latency = stats.wake_latency.Summary();
  r.compute = stats.compute.Summary();
  r.io_time = stats.io.Summary();
  r.response = stats.response.Summary();
  r.period_jitter = stats.period_jitter.Summary();
  const LoopCounts& counts = runner_->counts();
  r.link = {counts.io_errors, counts.peer_absent_cycles, counts.pulse_limit_cycles,
            config_.peer_name,
            runner_->peer_stopped() != nullptr ? runner_->peer_stopped() : wait_peer_stopped_};
  if (const auto& fault = runner_->fault()) {
    r.fault = RunFault{fault->kind, fault->cycle, fault->reason};
  } else if (wait_fault_) {
    r.fault = wait_fault_;
  }
  r.outputs_safe = result.outputs_safe;
  if (logger_) r.log = LogFiguresOf(*logger_);
  if (timing_log_) r.timing_log = LogFiguresOf(*timing_log_);
  r.wall_time_s = wall_time_s;
  if (result.rt) r.rt_setup = result.rt->record();
  r.warnings = config_.warnings;
  return r;
}

}  // namespace hiltwin::runtime
