// `hiltwin run`: the RELbot twin in real time (or on the virtual clock) behind the FPGA link,
// with a QoS verdict, a JSON run report and an optional CSV log (DESIGN.md "Contracts").
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/app_relbot/commands.h"
#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/overrun_injection.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/run_report.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/scheduler/executive.h"
#include "hiltwin/statemachine/lifecycle.h"
#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::app {
namespace {

struct RunOptions {
  double rate_hz = 4000.0;
  double duration_s = 10.0;
  std::string io = "mock";
  std::string input = "openloop";
  double controller_rate_hz = 0.0;  ///< 0: min(1000 Hz, --rate), the thesis ECS rate
  std::vector<std::string> mk_rules;
  std::vector<std::string> window_rules;
  std::optional<std::uint32_t> max_consecutive_misses;
  double max_miss_pct = 1.0;
  std::uint64_t grace_cycles = 0;
  std::string on_violation = "flag";
  std::string clock = "realtime";
  std::string overrun_policy = "catch-up";
  double deadline_us = 0.0;
  std::string log_path;
  std::uint32_t log_decimation = 1;
  std::string report_path;
  std::vector<std::string> inject_overrun;
  std::string config_path;
  std::string integrator = "rk4";
  int priority = 80;
  std::vector<int> cpus;
  bool no_progress = false;
};

/// A number as a person writes it (4000, 0.25), for messages.
std::string Num(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

[[noreturn]] void Usage(const std::string& message) { throw CommandError(ExitCode::kUsage, message); }

qos::QosConfig MakeQosConfig(const RunOptions& o, std::uint64_t planned_cycles) {
  qos::QosConfig config;
  config.planned_cycles = planned_cycles;
  config.grace_cycles = o.grace_cycles;
  try {
    config.policy = qos::ParseViolationPolicy(o.on_violation);
    // Exactly 0 switches the ratio rule off; anything else (negative, NaN) is validated.
    if (o.max_miss_pct != 0.0) config.rules.push_back(qos::MakeMissRatioRule(o.max_miss_pct));
    if (o.mk_rules.empty()) {
      // The documented default (m,k) rule for this twin/controller rate pair (docs/qos.md).
      for (const qos::RuleSpec& rule : qos::DefaultRulesFor(o.rate_hz, o.controller_rate_hz)) {
        if (rule.kind == qos::RuleKind::kMkFirm) config.rules.push_back(rule);
      }
    }
    for (const std::string& text : o.mk_rules) config.rules.push_back(qos::ParseMkRule(text));
    for (const std::string& text : o.window_rules) {
      config.rules.push_back(qos::ParseMissesInWindowRule(text));
    }
    if (o.max_consecutive_misses) {
      config.rules.push_back(qos::MakeConsecutiveMissesRule(*o.max_consecutive_misses));
    }
    qos::Validate(config);
  } catch (const std::invalid_argument& e) {
    Usage(std::string("QoS rules: ") + e.what() + " (see 'hiltwin run --help' and docs/qos.md)");
  }
  return config;
}

void Validate(const RunOptions& o) {
  try {
    scheduler::ValidateRateHz(o.rate_hz);
  } catch (const std::invalid_argument& e) {
    Usage(std::string("--rate: ") + e.what());
  }
  if (!std::isfinite(o.duration_s) || o.duration_s <= 0.0 || o.duration_s > 7 * 86400.0) {
    Usage("--duration " + Num(o.duration_s) +
          ": must be a positive number of seconds, at most 604800 (7 days)");
  }
  if (!std::isfinite(o.controller_rate_hz) || o.controller_rate_hz <= 0.0 ||
      o.controller_rate_hz > o.rate_hz) {
    Usage("--input-rate: the controller rate must be positive and not above --rate (" +
          Num(o.rate_hz) + " Hz)");
  }
  if (!std::isfinite(o.deadline_us) || o.deadline_us < 0.0 || o.deadline_us * 1e3 > 1e9 / o.rate_hz) {
    Usage("--deadline-us: must be between 0 (= the period) and the period (" +
          Num(1e6 / o.rate_hz) + " us)");
  }
  if (o.log_decimation == 0) Usage("--log-decimation: must be at least 1");
  if (o.clock != "realtime" && o.clock != "virtual") {
    Usage("--clock '" + o.clock + "': use 'realtime' or 'virtual'");
  }
  if (o.priority < 0 || o.priority > 99) Usage("--priority: 0 (no SCHED_FIFO) .. 99");
}

/// The online CPUs not in `loop_cpus`; empty when the loop is not pinned or uses them all.
std::vector<int> OtherCpus(const std::vector<int>& loop_cpus) {
  std::vector<int> others;
  if (loop_cpus.empty()) return others;
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  for (int cpu = 0; cpu < online; ++cpu) {
    if (std::find(loop_cpus.begin(), loop_cpus.end(), cpu) == loop_cpus.end()) others.push_back(cpu);
  }
  return others;
}

/// Throttled one-line progress on a terminal, from a non-RT thread reading atomics only.
class ProgressLine {
 public:
  ProgressLine(const scheduler::Executive& executive, const qos::QosMonitor& monitor,
               std::uint64_t planned, bool enabled)
      : enabled_(enabled) {
    if (!enabled_) return;
    thread_ = std::thread([this, &executive, &monitor, planned] {
      while (!done_.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        Print(executive, monitor, planned);
      }
      Print(executive, monitor, planned);
      std::fputc('\n', stderr);
    });
  }
  ~ProgressLine() { Finish(); }
  void Finish() {
    if (!enabled_ || done_.exchange(true)) return;
    thread_.join();
  }

 private:
  static void Print(const scheduler::Executive& executive, const qos::QosMonitor& monitor,
                    std::uint64_t planned) {
    const auto& live = executive.live();
    const qos::LiveQos q = monitor.Live();
    const std::string distance = q.distance_to_failure == qos::kNeverFails
                                     ? std::string("-")
                                     : std::to_string(q.distance_to_failure);
    std::fprintf(stderr,
                 "\r  %llu/%llu cycles  misses %llu  worst latency %.1f us  verdict so far %s  "
                 "misses to failure %s   ",
                 static_cast<unsigned long long>(live.cycles_run.load()),
                 static_cast<unsigned long long>(planned),
                 static_cast<unsigned long long>(live.deadline_misses.load()),
                 static_cast<double>(live.max_latency_ns.load()) / 1e3, qos::ToString(q.verdict),
                 distance.c_str());
    std::fflush(stderr);
  }
  bool enabled_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

int RunTwin(RunOptions o) {
  if (o.controller_rate_hz == 0.0) o.controller_rate_hz = std::min(1000.0, o.rate_hz);
  Validate(o);
  const bool virtual_clock = o.clock == "virtual";
  const auto planned = static_cast<std::uint64_t>(std::llround(o.duration_s * o.rate_hz));
  if (planned == 0) Usage("--duration is shorter than one period at --rate");
  if (o.grace_cycles >= planned) {
    // A grace period that covers the whole run would judge nothing and always PASS.
    Usage("--grace-cycles " + std::to_string(o.grace_cycles) + ": must be below the " +
          std::to_string(planned) + " cycles of the run; lower it or lengthen --duration");
  }
  // Open the report now: a path that cannot be written fails before the run, not after it.
  std::ofstream report_file;
  if (!o.report_path.empty()) {
    report_file.open(o.report_path, std::ios::out | std::ios::trunc);
    if (!report_file) {
      Usage("--report " + o.report_path + ": cannot create the file (" + std::strerror(errno) +
            "); check that the folder exists and is writable");
    }
  }
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.rate_hz);

  // --- configuration (may throw: exit 2) ---
  RelbotParams params = DefaultRelbotParams();
  Integrator integrator = Integrator::kRk4;
  std::optional<InputProfile> profile;
  OverrunInjector injector;
  try {
    if (!o.config_path.empty()) params = LoadRelbotParams(o.config_path);
    integrator = ParseIntegrator(o.integrator);
    profile.emplace(LoadInputProfile(o.input));
    for (const std::string& spec : o.inject_overrun) injector.Add(ParseOverrunInjection(spec));
  } catch (const ConfigError& e) {
    Usage(e.what());
  } catch (const ProfileError& e) {
    Usage(e.what());
  } catch (const std::invalid_argument& e) {
    Usage(e.what());
  } catch (const std::length_error& e) {
    Usage(std::string("--inject-overrun: ") + e.what());
  }
  const qos::QosConfig qos_config = MakeQosConfig(o, planned);
  scheduler::ExecutiveConfig exec_config;
  exec_config.period_ns = period_ns;
  exec_config.deadline_ns = static_cast<kernel_glue::TimeNs>(std::llround(o.deadline_us * 1e3));
  exec_config.max_cycles = planned;
  if (const auto policy = scheduler::ParseOverrunPolicy(o.overrun_policy)) {
    exec_config.overrun_policy = *policy;
  } else {
    Usage("--overrun-policy '" + o.overrun_policy + "': use 'catch-up' or 'skip'");
  }

  statemachine::Lifecycle lifecycle;
  kernel_glue::MonotonicClock monotonic;
  kernel_glue::VirtualClock virtual_time;
  kernel_glue::Clock& clock = virtual_clock ? static_cast<kernel_glue::Clock&>(virtual_time)
                                            : static_cast<kernel_glue::Clock&>(monotonic);

  // --- I/O: open the link and check the board's identity (exit 2 / 5) ---
  std::unique_ptr<io::IoBackend> backend;
  try {
    backend = io::OpenBackend(o.io, io::BackendOptions{});
  } catch (const io::ConfigError& e) {
    Usage(std::string("--io: ") + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string("--io ") + o.io + ": " + e.what());
  }
  ProfilePwmSource pwm_source(*profile, o.controller_rate_hz);
  // Only the mock board plays the profile; on a wire or real SPI the controller drives the PWM.
  const bool profile_drives = backend->kind() == io::BackendSpec::Kind::kMock;
  if (io::EmulatedFpga* board = backend->emulated_board(); board != nullptr && profile_drives) {
    board->SetPwmSource(&pwm_source);
  }
  const std::string input_name = profile_drives ? profile->name() : "the controller on " + o.io;
  io::IcoBoardInverse driver(backend->bus(), &clock);
  const io::InitResult init = driver.Init(period_ns);
  if (!init.ok) {
    throw CommandError(ExitCode::kIo, init.message.empty() ? "Failed to initialise FPGA" : init.message);
  }

  std::optional<RelbotModel> model_storage;
  try {
    model_storage.emplace(params, integrator, static_cast<double>(period_ns) * 1e-9);
  } catch (const ConfigError& e) {
    Usage(std::string("--rate ") + Num(o.rate_hz) + ": " + e.what());
  }
  RelbotModel& model = *model_storage;
  const io::WheelGeometry geometry = WheelGeometryOf(params);
  qos::QosMonitor monitor(qos_config);
  scheduler::Executive executive(clock, exec_config);
  TwinTask task(driver, model, geometry, clock, injector, lifecycle);
  QosObserver qos_observer(monitor);
  executive.AddObserver(qos_observer);

  std::unique_ptr<tracing::CsvLogger> logger;
  std::unique_ptr<LogObserver> log_observer;
  if (!o.log_path.empty()) {
    tracing::CsvLoggerConfig log_config;
    log_config.path = o.log_path;
    log_config.columns = LogObserver::Columns();
    log_config.decimation = o.log_decimation;
    // No deadline on the virtual clock: keep every row rather than drop when the writer lags.
    log_config.wait_when_full = virtual_clock;
    // Keep the writer off the loop's CPUs: it would inherit the pinning of this thread.
    log_config.writer_cpus = OtherCpus(o.cpus);
    try {
      logger = std::make_unique<tracing::CsvLogger>(std::move(log_config));
    } catch (const std::invalid_argument& e) {
      Usage(std::string("--log: ") + e.what());
    } catch (const std::exception& e) {
      Usage(std::string("--log: ") + e.what());
    }
    log_observer = std::make_unique<LogObserver>(*logger, task);
    executive.AddObserver(*log_observer);
  }
  lifecycle.Handle(statemachine::Event::kConfigured);

  // --- real-time set-up of this (the loop's) thread; refusals warn and the run goes on. It
  // comes before the writer thread starts: mallopt is process-wide and not thread-safe, and
  // a stop signal must find its handler before there is a log to lose. ---
  kernel_glue::RtSession rt_session;
  if (!virtual_clock) {
    kernel_glue::RtSetupRequest request;
    request.fifo_priority = o.priority;
    request.cpus = o.cpus;
    rt_session = kernel_glue::RtSession::Apply(request);
  }
  kernel_glue::InstallStopSignalHandlers();
  executive.SetStopCheck(&kernel_glue::StopRequested);
  if (logger) logger->Start();

  std::fprintf(stdout, "hiltwin run: RELbot twin at %.0f Hz for %.3f s (%llu cycles), io %s, input %s, %s clock\n",
               o.rate_hz, o.duration_s, static_cast<unsigned long long>(planned), o.io.c_str(),
               input_name.c_str(), o.clock.c_str());
  if (!virtual_clock) std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(rt_session.record()).c_str());
  std::fflush(stdout);

  const bool progress = !o.no_progress && isatty(STDERR_FILENO) == 1;
  ProgressLine progress_line(executive, monitor, planned, progress);
  lifecycle.Handle(statemachine::Event::kStart);
  const kernel_glue::TimeNs wall_start_ns = monotonic.NowNs();
  const scheduler::StopCause cause = executive.Run(task);
  const double wall_time_s = static_cast<double>(monotonic.NowNs() - wall_start_ns) * 1e-9;
  progress_line.Finish();

  // --- stop: events to the lifecycle, safe outputs, drain the log ---
  switch (cause) {
    case scheduler::StopCause::kCycleLimit: lifecycle.Handle(statemachine::Event::kFinishReached); break;
    case scheduler::StopCause::kStopRequested: lifecycle.Handle(statemachine::Event::kStopRequest); break;
    case scheduler::StopCause::kObserverStopped: lifecycle.Handle(statemachine::Event::kQosAbort); break;
    case scheduler::StopCause::kTaskStopped: break;  // the task already told the lifecycle
  }
  const io::ExchangeStatus hold = task.HoldOutputs();
  if (logger) logger->Stop();
  lifecycle.Handle(statemachine::Event::kDrained);

  RunFacts facts;
  facts.stop_reason = statemachine::ToString(lifecycle.stop_reason());
  facts.clock = o.clock;
  facts.io = o.io;
  facts.input = input_name;
  facts.integrator = std::string(IntegratorName(integrator));
  facts.rate_hz = o.rate_hz;
  facts.cycles_planned = planned;
  facts.io_errors = task.io_errors();
  facts.counts_over_limit = driver.counters().counts_over_limit;
  facts.controller_absent_cycles = task.controller_absent_cycles();
  facts.wall_time_s = wall_time_s;
  if (logger) {
    facts.log_path = o.log_path;
    facts.log_rows_written = logger->rows_written();
    facts.log_rows_dropped = logger->rows_dropped();
  }
  nlohmann::ordered_json report = BuildRunReport(facts, executive, monitor, rt_session.record());
  report["outputs_safe"] = hold.code != io::ExchangeStatus::Code::kFault;
  report["final_state"] = statemachine::ToString(lifecycle.state());
  if (lifecycle.stop_reason() == statemachine::StopReason::kIoFault ||
      lifecycle.stop_reason() == statemachine::StopReason::kModelFault) {
    report["fault"] = {{"cycle", task.fault_cycle()}, {"reason", task.fault_reason()}};
  }
  if (logger && !logger->error().empty()) report["log_error"] = logger->error();

  if (report_file.is_open()) {
    report_file << report.dump(2) << '\n';
    report_file.flush();
    if (!report_file) {
      throw CommandError(ExitCode::kIo, "--report " + o.report_path +
                                            ": cannot write the run report; check the folder exists and is writable");
    }
  }
  std::fputs(FormatRunSummary(report).c_str(), stdout);
  std::fflush(stdout);

  if (lifecycle.stop_reason() == statemachine::StopReason::kIoFault) {
    std::fprintf(stderr, "hiltwin run: I/O fault at cycle %llu: %s\n",
                 static_cast<unsigned long long>(task.fault_cycle()), task.fault_reason());
    return static_cast<int>(ExitCode::kIo);
  }
  if (lifecycle.stop_reason() == statemachine::StopReason::kModelFault) {
    std::fprintf(stderr,
                 "hiltwin run: model fault at cycle %llu: %s; try a higher --rate, --integrator rk4 "
                 "or check the parameters in --config\n",
                 static_cast<unsigned long long>(task.fault_cycle()), task.fault_reason());
    return static_cast<int>(ExitCode::kInternal);
  }
  if (task.controller_absent_cycles() > 0) {
    std::fprintf(stderr,
                 "hiltwin run: warning: no controller was attached to %s in %llu of %llu cycles; "
                 "the twin saw zero duty then. Start the controller (ECS) process on the same "
                 "wire before or during the run.\n",
                 o.io.c_str(), static_cast<unsigned long long>(task.controller_absent_cycles()),
                 static_cast<unsigned long long>(executive.stats().cycles_run));
  }
  if (logger && !logger->error().empty()) {
    std::fprintf(stderr, "hiltwin run: the log %s is incomplete: %s\n", o.log_path.c_str(),
                 logger->error().c_str());
    return static_cast<int>(ExitCode::kIo);
  }
  switch (monitor.verdict()) {
    case qos::Verdict::kPass: return static_cast<int>(ExitCode::kPass);
    case qos::Verdict::kFlagged: return static_cast<int>(ExitCode::kFlagged);
    case qos::Verdict::kAborted: return static_cast<int>(ExitCode::kAborted);
  }
  return static_cast<int>(ExitCode::kInternal);
}

Command AddRunCommand(CLI::App& parent) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* app = parent.add_subcommand(
      "run",
      "Run the RELbot twin with a QoS verdict.\n"
      "The twin runs at --rate behind the FPGA link (--io) and is driven by --input played into\n"
      "the emulated board's PWM reader at --input-rate (mock) or by a controller (wire/spidev).\n"
      "Exit: 0 PASS, 2 bad input, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 model fault/internal.");
  app->add_option("--rate", o->rate_hz, "twin update rate in Hz (1 .. 50000)")->capture_default_str();
  app->add_option("--duration", o->duration_s, "run length in seconds")->capture_default_str();
  app->add_option("--io", o->io, "FPGA link: mock | wire:NAME | spidev:/dev/spidevB.C")->capture_default_str();
  app->add_option("--input", o->input, "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app->add_option("--input-rate", o->controller_rate_hz,
                  "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                  "default 1000, or --rate if lower)");
  app->add_option("--qos", o->mk_rules,
                  "(m,k)-firm rule M:K: at least M deadlines met in any K cycles (repeatable; "
                  "replaces the default (k-1,k) rule)");
  app->add_option("--max-misses", o->window_rules, "rule N:K: at most N misses in any K cycles (repeatable)");
  app->add_option("--max-consecutive-misses", o->max_consecutive_misses, "rule: at most N consecutive misses");
  app->add_option("--max-miss-pct", o->max_miss_pct, "rule: overall miss ratio below P percent (0: off)")
      ->capture_default_str();
  app->add_option("--grace-cycles", o->grace_cycles, "ignore the first N cycles (start-up); fewer than the run's cycles")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--on-violation", o->on_violation, "flag: finish and mark unreliable (exit 3); abort: stop at once (exit 4)")
      ->check(CLI::IsMember({"flag", "abort"}))
      ->capture_default_str();
  app->add_option("--clock", o->clock, "realtime, or virtual: the identical loop as fast as possible")
      ->check(CLI::IsMember({"realtime", "virtual"}))
      ->capture_default_str();
  app->add_option("--overrun-policy", o->overrun_policy,
                  "after an overrun: catch-up (run skipped steps back to back) or skip (count them as misses)")
      ->check(CLI::IsMember({"catch-up", "skip"}))
      ->capture_default_str();
  app->add_option("--deadline-us", o->deadline_us, "deadline in microseconds (0: the period)")->capture_default_str();
  app->add_option("--log", o->log_path, "write a CSV log (20-sim DataFromFile / MATLAB readable)");
  app->add_option("--log-decimation", o->log_decimation, "log every Nth cycle")->capture_default_str();
  app->add_option("--report", o->report_path, "write the JSON run report to this file");
  app->add_option("--inject-overrun", o->inject_overrun,
                  "add compute time to chosen cycles, e.g. at=40000,count=5,extra-us=600 or "
                  "every=1000,extra-us=300 (repeatable)");
  app->add_option("--config", o->config_path, "RELbot parameter file (TOML, see app_relbot/relbot.toml)");
  app->add_option("--integrator", o->integrator, "euler | rk2 | rk4")->capture_default_str();
  app->add_option("--priority", o->priority, "SCHED_FIFO priority of the loop (0: none)")->capture_default_str();
  app->add_option("--cpu", o->cpus, "pin the loop to these CPUs");
  app->add_flag("--no-progress", o->no_progress, "no progress line on the terminal");
  return {app, [o] { return RunTwin(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(10, AddRunCommand);

}  // namespace hiltwin::app
