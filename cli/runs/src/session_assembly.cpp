// The session assembly (session_assembly.h): typed settings -> board -> SessionConfig -> run.
#include "hiltwin/runs/session_assembly.h"

#include "hiltwin/kernel_glue/output_file.h"
#include "hiltwin/kernel_glue/thread.h"

#include <charconv>
#include <array>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/scheduler/executive.h"
#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::app {
namespace {

/// The monitor's configuration: the parsed rules, checked against this run's length.
qos::QosConfig MakeQosConfig(const SessionSettings& s, const SessionRole& role,
                             std::uint64_t planned_cycles) {
  qos::QosConfig config;
  config.planned_cycles = planned_cycles;
  config.grace_cycles = s.grace_cycles;
  config.policy = s.on_violation;
  config.rules = s.qos_rules;
  try {
    qos::Validate(config);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("QoS rules: ") + e.what() + " (see 'hiltwin " + role.command +
               " --help' and docs/qos.md)");
  }
  return config;
}

/// The parsed injections, checked against this run's length: one that never fires is refused.
runtime::OverrunInjector MakeInjector(const SessionSettings& s, std::uint64_t planned) {
  runtime::OverrunInjector injector;
  try {
    for (const runtime::OverrunInjection& injection : s.overrun_injections) injector.Add(injection);
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

std::string ExactNum(double value) {
  std::array<char, 32> text{};  // holds every double's shortest form
  const auto end = std::to_chars(text.data(), text.data() + text.size(), value).ptr;
  return {text.data(), end};
}

std::uint64_t PlannedCycles(const SessionSettings& s) {
  const auto planned = static_cast<std::uint64_t>(std::llround(s.duration_s * s.rate_hz));
  if (planned == 0) ThrowUsage("--duration is shorter than one period at --rate");
  if (s.grace_cycles >= planned) {
    // A grace period that covers the whole run would judge nothing and always PASS.
    ThrowUsage("--grace-cycles " + std::to_string(s.grace_cycles) + ": must be below the " +
               std::to_string(planned) + " cycles of the run; lower it or lengthen --duration");
  }
  return planned;
}

io::BackendOptions BackendOptionsFor(const SessionSettings& s, io::Image side) {
  io::BackendOptions options;
  options.side = side;
  options.mock_board_image = s.board_image;
  // On a wire the virtual clock is the one both sides share (lockstep, docs/lockstep.md).
  options.lockstep =
      s.clock == runtime::ClockKind::kVirtual && s.io.kind == io::BackendSpec::Kind::kWire;
  return options;
}

std::unique_ptr<io::IoBackend> OpenBoard(const SessionSettings& s, io::Image side) {
  try {
    return io::OpenBackend(s.io, BackendOptionsFor(s, side));
  } catch (const io::ConfigError& e) {
    ThrowUsage(std::string("--io: ") + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string("--io ") + s.io_text + ": " + e.what());
  }
}

runtime::SessionConfig MakeSessionConfig(const SessionSettings& s, const SessionRole& role,
                                         io::IoBackend& backend) {
  const std::uint64_t planned = PlannedCycles(s);
  runtime::SessionConfig config;
  config.io = s.io_text;
  config.peer_name = role.peer_name;
  config.clock = s.clock;
  config.rate_hz = s.rate_hz;
  config.executive.period_ns = kernel_glue::PeriodNsFromRateHz(s.rate_hz);
  config.executive.deadline_ns = s.deadline_ns;
  config.executive.max_cycles = planned;
  config.executive.overrun_policy = s.overrun_policy;
  config.qos = MakeQosConfig(s, role, planned);
  config.rt.fifo_priority = s.priority;
  config.rt.cpus = s.cpus;
  config.injector = MakeInjector(s, planned);
  if (!s.log_path.empty()) config.log = runtime::LogConfig{s.log_path, s.log_decimation};
  config.timing_log_path = s.timing_log_path;
  config.progress = s.progress && isatty(STDERR_FILENO) == 1;
  config.pause_signals = true;  // kill -USR1 pauses, -USR2 resumes (documented in --help)
  if (io::PeerLink* link = backend.peer_link(); link != nullptr) {
    const bool lockstep = s.clock == runtime::ClockKind::kVirtual;  // the peer must say so too
    const std::string start_hint = std::string(role.peer_command) + " --io " + s.io_text +
                                   (lockstep ? " --clock virtual" : "");
    config.peer = runtime::PeerWait{link, s.wait_peer_s, start_hint};
    config.lockstep_clock = backend.lockstep_clock();
    if (config.lockstep_clock != nullptr && s.wait_peer_s == 0.0) {
      ThrowUsage("--wait-peer 0 with --clock virtual on " + s.io_text +
                 ": a lockstep run starts both sides on one time base, so it waits for its peer; "
                 "drop --wait-peer 0 or run --clock realtime");
    }
  } else if (s.wait_peer_s != kDefaultWaitPeerS && s.wait_peer_s != 0.0) {
    ThrowUsage(
        "--wait-peer only applies to --io wire:NAME; a mock board has no peer and a real "
        "board's peer cannot be seen from here (drop --wait-peer)");
  }
  config.telemetry = MakeTelemetry(s.telemetry, role, s.cpus);
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

int PrintOutcome(const SessionRole& role, const runtime::RunReport& report,
                 const nlohmann::ordered_json& json, const std::string& extra_summary,
                 ReportFile& report_file) {
  // The summary first: a report the disk refuses must not cost the run's outcome on screen.
  std::fputs(extra_summary.c_str(), stdout);
  std::fputs(runtime::FormatSummary(report).c_str(), stdout);
  std::fflush(stdout);
  for (const std::string& line : runtime::Problems(report)) {
    std::fprintf(stderr, "hiltwin %s: %s\n", role.command, line.c_str());
  }
  return report_file.WriteAtEnd(json.dump(2) + '\n', role.command,
                                static_cast<int>(runtime::ExitCodeFor(report)));
}

void PrintWarnings(const char* command, const std::vector<std::string>& warnings) {
  for (const std::string& line : warnings) {
    std::fprintf(stderr, "hiltwin %s: warning: %s\n", command, line.c_str());
  }
}

}  // namespace hiltwin::app
