#include "hiltwin/runs/session_options.h"

#include "hiltwin/kernel_glue/output_file.h"
#include "hiltwin/kernel_glue/thread.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>

#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/scheduler/executive.h"
#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::app {
namespace {

qos::QosConfig MakeQosConfig(const SessionOptions& o, const SessionRole& role,
                             std::uint64_t planned_cycles) {
  qos::QosConfig config;
  config.planned_cycles = planned_cycles;
  config.grace_cycles = o.grace_cycles;
  try {
    config.policy = qos::ParseViolationPolicy(o.on_violation);
    // Exactly 0 switches the ratio rule off; anything else (negative, NaN) is validated.
    if (o.max_miss_pct != 0.0) config.rules.push_back(qos::MakeMissRatioRule(o.max_miss_pct));
    if (o.mk_rules.empty()) {
      // The documented default (m,k) rule for this rate pair (docs/qos.md).
      for (const qos::RuleSpec& rule : qos::DefaultRulesFor(o.rate_hz, role.other_rate_hz)) {
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
    ThrowUsage(std::string("QoS rules: ") + e.what() + " (see 'hiltwin " + role.command +
          " --help' and docs/qos.md)");
  }
  return config;
}

runtime::OverrunInjector MakeInjector(const SessionOptions& o, std::uint64_t planned) {
  runtime::OverrunInjector injector;
  try {
    for (const std::string& spec : o.inject_overrun)
      injector.Add(runtime::ParseOverrunInjection(spec));
    injector.CheckFiresWithin(planned);
  } catch (const std::exception& e) {  // invalid_argument, length_error: both the user's input
    ThrowUsage(std::string("--inject-overrun ") + e.what());
  }
  return injector;
}

runtime::TelemetryConfig MakeTelemetry(telemetry::TelemetryOptions t, const SessionRole& role,
                                      const std::vector<int>& loop_cpus) {
  if (t.ns.empty()) t.ns = role.default_namespace;
  // Cyclone DDS starts its threads with the participant: on the helper CPUs, off the loop's.
  const kernel_glue::ScopedThreadCpus on_helpers(
      kernel_glue::HelperCpus(kernel_glue::AllowedCpus(), loop_cpus));
  try {
    return telemetry::MakeTelemetryConfig(t);
  } catch (const std::exception& e) {
    ThrowUsage(e.what());
  }
}

/// The start-up line that says where telemetry goes.
std::string TelemetryLine(const runtime::TelemetryConfig& t) {
  std::string line = "telemetry: namespace " + t.ns + ", " + Num(t.rate_hz) + " Hz:";
  for (std::size_t i = 0; i < t.sinks.size(); ++i) {
    line += (i == 0 ? " " : "; ") + t.sinks[i]->Describe();
  }
  return line;
}

}  // namespace

std::string Num(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

void AddSessionOptions(CLI::App& app, SessionOptions& o) {
  app.add_option("--rate", o.rate_hz, "update rate in Hz (1 .. 50000)")->capture_default_str();
  app.add_option("--duration", o.duration_s, "run length in seconds")->capture_default_str();
  app.add_option("--io", o.io, "FPGA link: mock | wire:NAME | spidev:/dev/spidevB.C | verilated")
      ->capture_default_str();
  app.add_option("--qos", o.mk_rules,
                 "(m,k)-firm rule M:K: at least M deadlines met in any K cycles (repeatable; "
                 "replaces the default (m,k) rule)");
  app.add_option("--max-misses", o.window_rules,
                 "rule N:K: at most N misses in any K cycles (repeatable)");
  app.add_option("--max-consecutive-misses", o.max_consecutive_misses,
                 "rule: at most N consecutive misses");
  app.add_option("--max-miss-pct", o.max_miss_pct,
                 "rule: overall miss ratio below P percent (0: off)")
      ->capture_default_str();
  app.add_option("--grace-cycles", o.grace_cycles,
                 "ignore the first N cycles (start-up); fewer than the run's cycles")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--on-violation", o.on_violation,
                 "flag: finish and mark unreliable (exit 3); abort: stop at once (exit 4)")
      ->check(CLI::IsMember({"flag", "abort"}))
      ->capture_default_str();
  app.add_option("--clock", o.clock, "realtime, or virtual: the identical loop as fast as possible")
      ->check(CLI::IsMember({"realtime", "virtual"}))
      ->capture_default_str();
  app.add_option("--overrun-policy", o.overrun_policy,
                 "after an overrun: catch-up (run skipped steps back to back) or skip (count them "
                 "as misses)")
      ->check(CLI::IsMember({"catch-up", "skip"}))
      ->capture_default_str();
  app.add_option("--deadline-us", o.deadline_us, "deadline in microseconds (0: the period)")
      ->capture_default_str();
  app.add_option("--log", o.log_path, "write a CSV log (20-sim DataFromFile / MATLAB readable)");
  app.add_option("--log-decimation", o.log_decimation, "log every Nth cycle")
      ->capture_default_str();
  app.add_option("--timing-log", o.timing_log_path,
                 "write every cycle's time stamps to this file (no LTTng needed); analyse it "
                 "with 'hiltwin trace --analyze FILE'");
  app.add_option("--report", o.report_path, "write the JSON run report to this file");
  app.add_option("--inject-overrun", o.inject_overrun,
                 "add compute time to chosen cycles, e.g. at=20000,count=5,extra-us=600 or "
                 "every=1000,extra-us=300 (repeatable)");
  app.add_option("--priority", o.priority, "SCHED_FIFO priority of the loop (0: none)")
      ->capture_default_str();
  app.add_option("--cpu", o.cpus, "pin the loop to these CPUs");
  app.add_flag("--no-progress", o.no_progress, "no progress line on the terminal");
  app.add_option("--wait-peer", o.wait_peer_s,
                 "wire only: wait in ready up to SECONDS for the other process (countdown on "
                 "stderr; exit 5 if it never comes); 0: start at once")
      ->capture_default_str();
  app.add_option("--board-image", o.board_image,
                 "fault injection (mock and wire): the FPGA image the emulated board carries, "
                 "icoboard or icoboard_inverse; the wrong one stops at INIT with exit 5")
      ->check(CLI::IsMember({"icoboard", "icoboard_inverse"}));
  AddTelemetryOptions(app, o.telemetry);
}

void AddTelemetryOptions(CLI::App& app, telemetry::TelemetryOptions& t) {
  app.add_option("--telemetry", t.specs,
                 "live telemetry out of the loop (repeatable): dds[:DOMAIN] publishes ROS 2 "
                 "topics rt/NS/{pose,joint_states,timing} and takes commands on rt/NS/command; "
                 "udp[:HOST:PORT] streams JSON to PlotJuggler (default 127.0.0.1:9870)");
  app.add_option("--namespace", t.ns,
                 "telemetry namespace NS, one per task on a network (default: twin for run, "
                 "controller for ecs; hil publishes its sides under NS/twin and NS/controller, "
                 "default hil)");
  app.add_option("--web", t.web,
                 "serve a live page (pose, trail, wheels, timing) at ADDR:PORT (bare --web: "
                 "127.0.0.1:8080)")
      ->expected(0, 1)
      ->default_str("127.0.0.1:8080");
  app.add_option("--telemetry-rate", t.rate_hz, "telemetry records per second (0 < HZ <= 1000)")
      ->capture_default_str();
}

void ValidateSessionOptions(const SessionOptions& o) {
  try {
    scheduler::ValidateRateHz(o.rate_hz);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("--rate: ") + e.what());
  }
  if (!std::isfinite(o.duration_s) || o.duration_s <= 0.0 || o.duration_s > 7 * 86400.0) {
    ThrowUsage("--duration " + Num(o.duration_s) +
          ": must be a positive number of seconds, at most 604800 (7 days)");
  }
  if (!std::isfinite(o.deadline_us) || o.deadline_us < 0.0 ||
      o.deadline_us * 1e3 > 1e9 / o.rate_hz) {
    ThrowUsage("--deadline-us: must be between 0 (= the period) and the period (" +
          Num(1e6 / o.rate_hz) + " us)");
  }
  if (o.log_decimation == 0) ThrowUsage("--log-decimation: must be at least 1");
  if (o.priority < 0 || o.priority > 99) ThrowUsage("--priority: 0 (no SCHED_FIFO) .. 99");
  if (!std::isfinite(o.wait_peer_s) || o.wait_peer_s < 0.0 || o.wait_peer_s > 86400.0) {
    ThrowUsage("--wait-peer " + Num(o.wait_peer_s) + ": must be 0 .. 86400 seconds");
  }
}

std::uint64_t PlannedCycles(const SessionOptions& o) {
  const auto planned = static_cast<std::uint64_t>(std::llround(o.duration_s * o.rate_hz));
  if (planned == 0) ThrowUsage("--duration is shorter than one period at --rate");
  if (o.grace_cycles >= planned) {
    // A grace period that covers the whole run would judge nothing and always PASS.
    ThrowUsage("--grace-cycles " + std::to_string(o.grace_cycles) + ": must be below the " +
          std::to_string(planned) + " cycles of the run; lower it or lengthen --duration");
  }
  return planned;
}

io::BackendOptions BackendOptionsFor(const SessionOptions& o, io::Image side) {
  io::BackendOptions options;
  options.side = side;
  if (!o.board_image.empty()) {
    options.mock_board_image =
        o.board_image == "icoboard" ? io::Image::kIcoboard : io::Image::kIcoboardInverse;
  }
  return options;
}

std::unique_ptr<io::IoBackend> OpenBoard(const SessionOptions& o, io::Image side) {
  try {
    return io::OpenBackend(o.io, BackendOptionsFor(o, side));
  } catch (const io::ConfigError& e) {
    ThrowUsage(std::string("--io: ") + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string("--io ") + o.io + ": " + e.what());
  }
}

runtime::SessionConfig MakeSessionConfig(const SessionOptions& o, const SessionRole& role,
                                         io::IoBackend& backend) {
  const std::uint64_t planned = PlannedCycles(o);
  runtime::SessionConfig config;
  config.io = o.io;
  config.peer_name = role.peer_name;
  config.clock =
      o.clock == "virtual" ? runtime::ClockKind::kVirtual : runtime::ClockKind::kRealtime;
  config.rate_hz = o.rate_hz;
  config.executive.period_ns = kernel_glue::PeriodNsFromRateHz(o.rate_hz);
  config.executive.deadline_ns =
      static_cast<kernel_glue::TimeNs>(std::llround(o.deadline_us * 1e3));
  config.executive.max_cycles = planned;
  if (const auto policy = scheduler::ParseOverrunPolicy(o.overrun_policy)) {
    config.executive.overrun_policy = *policy;
  } else {
    ThrowUsage("--overrun-policy '" + o.overrun_policy + "': use 'catch-up' or 'skip'");
  }
  config.qos = MakeQosConfig(o, role, planned);
  config.rt.fifo_priority = o.priority;
  config.rt.cpus = o.cpus;
  config.injector = MakeInjector(o, planned);
  if (!o.log_path.empty()) config.log = runtime::LogConfig{o.log_path, o.log_decimation};
  config.timing_log_path = o.timing_log_path;
  config.progress = !o.no_progress && isatty(STDERR_FILENO) == 1;
  config.pause_signals = true;  // kill -USR1 pauses, -USR2 resumes (documented in --help)
  if (io::PeerLink* link = backend.peer_link(); link != nullptr) {
    config.peer =
        runtime::PeerWait{link, o.wait_peer_s, std::string(role.peer_command) + " --io " + o.io};
  } else if (o.wait_peer_s != SessionOptions{}.wait_peer_s && o.wait_peer_s != 0.0) {
    ThrowUsage(
        "--wait-peer only applies to --io wire:NAME; a mock board has no peer and a real "
        "board's peer cannot be seen from here (drop --wait-peer)");
  }
  config.telemetry = MakeTelemetry(o.telemetry, role, o.cpus);
  return config;
}

void InitBoard(io::IcoBoardLink& driver, kernel_glue::TimeNs period_ns) {
  const io::InitResult init = driver.Init(period_ns);
  if (!init.ok) {
    throw CommandError(ExitCode::kIo,
                       init.message.empty() ? "Failed to initialise FPGA" : init.message);
  }
}

runtime::RunReport RunSessionOf(runtime::SessionConfig config, runtime::RunTask& task) {
  // Where telemetry goes, after the command's own start-up lines: built when they print, after
  // the session has opened the sinks, so each names its topics and address as opened.
  if (!config.telemetry.sinks.empty()) {
    config.on_ready = [on_ready = std::move(config.on_ready),
                       telemetry = config.telemetry](const kernel_glue::RtSetupRecord* rt) {
      if (on_ready) on_ready(rt);
      std::fprintf(stdout, "%s\n", TelemetryLine(telemetry).c_str());
      std::fflush(stdout);
    };
  }
  std::optional<runtime::RunSession> session;
  // Only the two logs can fail to open; the message names the flag of the one that did.
  const std::string timing_log_path = config.timing_log_path;
  const std::string timing_log_quoted = "'" + timing_log_path + "'";
  try {
    session.emplace(std::move(config), task);
  } catch (const kernel_glue::OutputFileError& e) {
    ThrowUsage(e.MessageFor(!timing_log_path.empty() && e.path() == timing_log_path ? "--timing-log"
                                                                                : "--log"));
  } catch (const tracing::LogWriteError& e) {
    // The path was fine, the disk is not (already full, an I/O error): exit 5, not usage.
    const bool timing = timing_log_quoted != "''" &&
                        std::string(e.what()).find(timing_log_quoted) != std::string::npos;
    throw CommandError(ExitCode::kIo, std::string(timing ? "--timing-log: " : "--log: ") + e.what());
  } catch (const std::invalid_argument& e) {
    ThrowUsage(e.what());
  } catch (const runtime::TelemetryError& e) {
    ThrowUsage(std::string("telemetry: ") + e.what());
  } catch (const std::runtime_error& e) {
    const bool timing = timing_log_quoted != "''" &&
                        std::string(e.what()).find(timing_log_quoted) != std::string::npos;
    ThrowUsage(std::string(timing ? "--timing-log: " : "--log: ") + e.what());
  }
  return session->Run();
}

ReportFile::ReportFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) return;
  try {
    fd_ = kernel_glue::OpenOutputFile(path_, "--report");  // a link or a missing folder: exit 2
  } catch (const kernel_glue::OutputFileError& e) {
    ThrowUsage(e.what());
  }
}

ReportFile::ReportFile(ReportFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

ReportFile::~ReportFile() {
  if (fd_ < 0) return;
  // Never written: remove it, but only if the path still names the file this created.
  struct stat ours {};
  struct stat named {};
  if (::fstat(fd_, &ours) == 0 && ::lstat(path_.c_str(), &named) == 0 &&
      ours.st_dev == named.st_dev && ours.st_ino == named.st_ino) {
    ::unlink(path_.c_str());
  }
  ::close(fd_);
}

void ReportFile::Write(const std::string& text) {
  if (fd_ < 0) return;
  std::size_t done = 0;
  int error = 0;
  while (done < text.size() && error == 0) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno != EINTR) {
      error = errno;
    }
  }
  if (::close(std::exchange(fd_, -1)) != 0 && error == 0) error = errno;
  if (error != 0) {
    throw CommandError(ExitCode::kIo, "--report " + path_ + ": cannot write the run report (" +
                                          std::strerror(error) +
                                          "); check the disk has space and the folder is writable");
  }
}

void PrintOutcome(const SessionRole& role,
                  const runtime::RunReport& report, const nlohmann::ordered_json& json,
                  const std::string& extra_summary, ReportFile& report_file) {
  report_file.Write(json.dump(2) + '\n');
  std::fputs(extra_summary.c_str(), stdout);
  std::fputs(runtime::FormatSummary(report).c_str(), stdout);
  std::fflush(stdout);
  for (const std::string& line : runtime::Problems(report)) {
    std::fprintf(stderr, "hiltwin %s: %s\n", role.command, line.c_str());
  }
}

}  // namespace hiltwin::app
