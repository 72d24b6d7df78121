// `hiltwin run`: the RELbot twin in real time (or on the virtual clock) behind the FPGA link,
// with a QoS verdict, a JSON run report and an optional CSV log (DESIGN.md "Contracts").
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/app_relbot/commands.h"
#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/scheduler/executive.h"

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

[[noreturn]] void Usage(const std::string& message) {
  throw CommandError(ExitCode::kUsage, message);
}

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
  if (!std::isfinite(o.deadline_us) || o.deadline_us < 0.0 ||
      o.deadline_us * 1e3 > 1e9 / o.rate_hz) {
    Usage("--deadline-us: must be between 0 (= the period) and the period (" +
          Num(1e6 / o.rate_hz) + " us)");
  }
  if (o.log_decimation == 0) Usage("--log-decimation: must be at least 1");
  if (o.clock != "realtime" && o.clock != "virtual") {
    Usage("--clock '" + o.clock + "': use 'realtime' or 'virtual'");
  }
  if (o.priority < 0 || o.priority > 99) Usage("--priority: 0 (no SCHED_FIFO) .. 99");
}

/// The RELbot twin behind its FPGA link, built from the flags; owns everything the task uses.
struct Twin {
  RelbotParams params = DefaultRelbotParams();
  Integrator integrator = Integrator::kRk4;
  std::optional<InputProfile> profile;
  std::unique_ptr<io::IoBackend> backend;
  std::unique_ptr<ProfilePwmSource> pwm_source;
  std::unique_ptr<io::IcoBoardInverse> driver;
  std::optional<RelbotModel> model;
  io::WheelGeometry geometry;
  std::optional<TwinTask> task;
  std::string input_name;
};

void LoadTwinConfiguration(const RunOptions& o, Twin& twin) {
  try {
    if (!o.config_path.empty()) twin.params = LoadRelbotParams(o.config_path);
    twin.integrator = ParseIntegrator(o.integrator);
    twin.profile.emplace(LoadInputProfile(o.input));
  } catch (const ConfigError& e) {
    Usage(e.what());
  } catch (const ProfileError& e) {
    Usage(e.what());
  } catch (const std::invalid_argument& e) {
    Usage(e.what());
  }
}

/// Builds the model (a rate it cannot integrate stably is refused here, exit 2), opens the
/// link and checks the board's identity (exit 2 / 5), then builds the task.
std::unique_ptr<Twin> BuildTwin(const RunOptions& o, kernel_glue::TimeNs period_ns) {
  auto twin = std::make_unique<Twin>();
  LoadTwinConfiguration(o, *twin);
  try {
    twin->model.emplace(twin->params, twin->integrator, static_cast<double>(period_ns) * 1e-9);
  } catch (const ConfigError& e) {
    Usage("--rate " + Num(o.rate_hz) + ": " + e.what());
  }
  try {
    twin->backend = io::OpenBackend(o.io, io::BackendOptions{});
  } catch (const io::ConfigError& e) {
    Usage(std::string("--io: ") + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string("--io ") + o.io + ": " + e.what());
  }
  twin->pwm_source = std::make_unique<ProfilePwmSource>(*twin->profile, o.controller_rate_hz);
  // Only the mock board plays the profile; on a wire or real SPI the controller drives the PWM.
  const bool profile_drives = twin->backend->kind() == io::BackendSpec::Kind::kMock;
  if (io::EmulatedFpga* board = twin->backend->emulated_board();
      board != nullptr && profile_drives) {
    board->SetPwmSource(twin->pwm_source.get());
  }
  twin->input_name = profile_drives ? twin->profile->name() : "the controller on " + o.io;
  twin->driver = std::make_unique<io::IcoBoardInverse>(twin->backend->bus());
  const io::InitResult init = twin->driver->Init(period_ns);
  if (!init.ok) {
    throw CommandError(ExitCode::kIo,
                       init.message.empty() ? "Failed to initialise FPGA" : init.message);
  }
  twin->geometry = WheelGeometryOf(twin->params);
  twin->task.emplace(*twin->driver, *twin->model, twin->geometry);
  return twin;
}

runtime::OverrunInjector MakeInjector(const RunOptions& o, std::uint64_t planned) {
  runtime::OverrunInjector injector;
  try {
    for (const std::string& spec : o.inject_overrun)
      injector.Add(runtime::ParseOverrunInjection(spec));
    injector.CheckFiresWithin(planned);
  } catch (const std::exception& e) {  // invalid_argument, length_error: both the user's input
    Usage(std::string("--inject-overrun ") + e.what());
  }
  return injector;
}

void PrintStartLines(const RunOptions& o, std::uint64_t planned, const std::string& input,
                     const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(
      stdout,
      "hiltwin run: RELbot twin at %.0f Hz for %.3f s (%llu cycles), io %s, input %s, %s clock\n",
      o.rate_hz, o.duration_s, static_cast<unsigned long long>(planned), o.io.c_str(),
      input.c_str(), o.clock.c_str());
  if (rt != nullptr)
    std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(*rt).c_str());
  std::fflush(stdout);
}

runtime::SessionConfig MakeSessionConfig(const RunOptions& o, const Twin& twin,
                                         std::uint64_t planned, kernel_glue::TimeNs period_ns) {
  runtime::SessionConfig config;
  config.task_name = "RELbot twin";
  config.io = o.io;
  config.peer_name = "controller";
  config.details = {{"input", twin.input_name},
                    {"integrator", std::string(IntegratorName(twin.integrator))}};
  config.clock =
      o.clock == "virtual" ? runtime::ClockKind::kVirtual : runtime::ClockKind::kRealtime;
  config.rate_hz = o.rate_hz;
  config.executive.period_ns = period_ns;
  config.executive.deadline_ns =
      static_cast<kernel_glue::TimeNs>(std::llround(o.deadline_us * 1e3));
  config.executive.max_cycles = planned;
  if (const auto policy = scheduler::ParseOverrunPolicy(o.overrun_policy)) {
    config.executive.overrun_policy = *policy;
  } else {
    Usage("--overrun-policy '" + o.overrun_policy + "': use 'catch-up' or 'skip'");
  }
  config.qos = MakeQosConfig(o, planned);
  config.rt.fifo_priority = o.priority;
  config.rt.cpus = o.cpus;
  config.injector = MakeInjector(o, planned);
  if (!o.log_path.empty()) config.log = runtime::LogConfig{o.log_path, o.log_decimation};
  config.progress = !o.no_progress && isatty(STDERR_FILENO) == 1;
  config.pause_signals = true;  // kill -USR1 pauses, -USR2 resumes (documented in --help)
  config.on_ready = [o, planned, input = twin.input_name](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(o, planned, input, rt);
  };
  return config;
}

/// Opens the report file before the run: a path that cannot be written fails first, not after.
std::ofstream OpenReport(const std::string& path) {
  std::ofstream file;
  if (path.empty()) return file;
  file.open(path, std::ios::out | std::ios::trunc);
  if (!file) {
    Usage("--report " + path + ": cannot create the file (" + std::strerror(errno) +
          "); check that the folder exists and is writable");
  }
  return file;
}

void PrintOutcome(const RunOptions& o, const runtime::RunReport& report,
                  std::ofstream& report_file) {
  if (report_file.is_open()) {
    report_file << runtime::ToJson(report).dump(2) << '\n';
    report_file.flush();
    if (!report_file) {
      throw CommandError(
          ExitCode::kIo,
          "--report " + o.report_path +
              ": cannot write the run report; check the folder exists and is writable");
    }
  }
  std::fputs(runtime::FormatSummary(report).c_str(), stdout);
  std::fflush(stdout);
  for (const std::string& line : runtime::Problems(report)) {
    std::fprintf(stderr, "hiltwin run: %s\n", line.c_str());
  }
  if (report.fault && report.fault->kind == statemachine::StopReason::kModelFault) {
    std::fprintf(
        stderr,
        "hiltwin run: try a higher --rate, --integrator rk4 or check the parameters in --config\n");
  }
}

int RunTwin(RunOptions o) {
  if (o.controller_rate_hz == 0.0) o.controller_rate_hz = std::min(1000.0, o.rate_hz);
  Validate(o);
  const auto planned = static_cast<std::uint64_t>(std::llround(o.duration_s * o.rate_hz));
  if (planned == 0) Usage("--duration is shorter than one period at --rate");
  if (o.grace_cycles >= planned) {
    // A grace period that covers the whole run would judge nothing and always PASS.
    Usage("--grace-cycles " + std::to_string(o.grace_cycles) + ": must be below the " +
          std::to_string(planned) + " cycles of the run; lower it or lengthen --duration");
  }
  std::ofstream report_file = OpenReport(o.report_path);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(o, period_ns);
  std::optional<runtime::RunSession> session;
  try {
    session.emplace(MakeSessionConfig(o, *twin, planned, period_ns), *twin->task);
  } catch (const std::invalid_argument& e) {
    Usage(e.what());
  } catch (const std::runtime_error& e) {
    Usage(std::string("--log: ") + e.what());
  }
  const runtime::RunReport report = session->Run();
  PrintOutcome(o, report, report_file);
  return static_cast<int>(runtime::ExitCodeFor(report));
}

Command AddRunCommand(CLI::App& parent) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* app = parent.add_subcommand(
      "run",
      "Run the RELbot twin with a QoS verdict.\n"
      "The twin runs at --rate behind the FPGA link (--io) and is driven by --input played into\n"
      "the emulated board's PWM reader at --input-rate (mock) or by a controller (wire/spidev).\n"
      "Exit: 0 PASS, 2 bad input, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 model fault/internal.\n"
      "While it runs: SIGINT/SIGTERM stop it cleanly (report and log written), SIGUSR1 pauses\n"
      "(link kept, safe outputs, model frozen, not judged) and SIGUSR2 resumes.");
  app->add_option("--rate", o->rate_hz, "twin update rate in Hz (1 .. 50000)")
      ->capture_default_str();
  app->add_option("--duration", o->duration_s, "run length in seconds")->capture_default_str();
  app->add_option("--io", o->io, "FPGA link: mock | wire:NAME | spidev:/dev/spidevB.C")
      ->capture_default_str();
  app->add_option("--input", o->input,
                  "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app->add_option("--input-rate", o->controller_rate_hz,
                  "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                  "default 1000, or --rate if lower)");
  app->add_option("--qos", o->mk_rules,
                  "(m,k)-firm rule M:K: at least M deadlines met in any K cycles (repeatable; "
                  "replaces the default (k-1,k) rule)");
  app->add_option("--max-misses", o->window_rules,
                  "rule N:K: at most N misses in any K cycles (repeatable)");
  app->add_option("--max-consecutive-misses", o->max_consecutive_misses,
                  "rule: at most N consecutive misses");
  app->add_option("--max-miss-pct", o->max_miss_pct,
                  "rule: overall miss ratio below P percent (0: off)")
      ->capture_default_str();
  app->add_option("--grace-cycles", o->grace_cycles,
                  "ignore the first N cycles (start-up); fewer than the run's cycles")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--on-violation", o->on_violation,
                  "flag: finish and mark unreliable (exit 3); abort: stop at once (exit 4)")
      ->check(CLI::IsMember({"flag", "abort"}))
      ->capture_default_str();
  app->add_option("--clock", o->clock,
                  "realtime, or virtual: the identical loop as fast as possible")
      ->check(CLI::IsMember({"realtime", "virtual"}))
      ->capture_default_str();
  app->add_option("--overrun-policy", o->overrun_policy,
                  "after an overrun: catch-up (run skipped steps back to back) or skip (count them "
                  "as misses)")
      ->check(CLI::IsMember({"catch-up", "skip"}))
      ->capture_default_str();
  app->add_option("--deadline-us", o->deadline_us, "deadline in microseconds (0: the period)")
      ->capture_default_str();
  app->add_option("--log", o->log_path, "write a CSV log (20-sim DataFromFile / MATLAB readable)");
  app->add_option("--log-decimation", o->log_decimation, "log every Nth cycle")
      ->capture_default_str();
  app->add_option("--report", o->report_path, "write the JSON run report to this file");
  app->add_option("--inject-overrun", o->inject_overrun,
                  "add compute time to chosen cycles, e.g. at=20000,count=5,extra-us=600 or "
                  "every=1000,extra-us=300 (repeatable)");
  app->add_option("--config", o->config_path,
                  "RELbot parameter file (TOML, see app_relbot/relbot.toml)");
  app->add_option("--integrator", o->integrator, "euler | rk2 | rk4")->capture_default_str();
  app->add_option("--priority", o->priority, "SCHED_FIFO priority of the loop (0: none)")
      ->capture_default_str();
  app->add_option("--cpu", o->cpus, "pin the loop to these CPUs");
  app->add_flag("--no-progress", o->no_progress, "no progress line on the terminal");
  return {app, [o] { return RunTwin(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(10, AddRunCommand);

}  // namespace hiltwin::app
