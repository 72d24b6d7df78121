// The shared session flags and `run`'s (session_flags.h): declared here, read here once.
#include "session_flags.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>

#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runtime/overrun_injection.h"
#include "hiltwin/scheduler/overrun_policy.h"

namespace hiltwin::app {
namespace {

/// --deadline-us in ns; -1 for a value no run at `rate_hz` can have (ValidateSessionSettings
/// then names the flag). Compared before rounding, so exactly the values within the period pass.
kernel_glue::TimeNs DeadlineNsOf(double deadline_us, double rate_hz) {
  const bool within = std::isfinite(deadline_us) && deadline_us >= 0.0 &&
                      deadline_us * 1e3 <= 1e9 / rate_hz;
  return within ? static_cast<kernel_glue::TimeNs>(std::llround(deadline_us * 1e3)) : -1;
}

io::BackendSpec BackendSpecOf(const std::string& text) {
  try {
    return io::ParseBackendSpec(text);
  } catch (const io::ConfigError& e) {
    ThrowUsage(std::string("--io: ") + e.what());
  }
}

/// --board-image (CLI11 admits only the two names); unset: the image the side's driver needs.
std::optional<io::Image> BoardImageOf(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const std::optional<io::Image> image = io::ParseImage(text);
  if (!image) ThrowUsage("--board-image " + text + ": use icoboard or icoboard_inverse");
  return image;
}

scheduler::OverrunPolicy OverrunPolicyOf(const std::string& text) {
  const std::optional<scheduler::OverrunPolicy> policy = scheduler::ParseOverrunPolicy(text);
  if (!policy) ThrowUsage("--overrun-policy '" + text + "': use 'catch-up' or 'skip'");
  return *policy;
}

/// Every rule in the report's order. Exactly 0 switches the ratio rule off; anything else
/// (negative, NaN) is refused by MakeMissRatioRule.
std::vector<qos::RuleSpec> QosRulesOf(const SessionFlags& f, double other_rate_hz) {
  std::vector<qos::RuleSpec> rules;
  if (f.max_miss_pct != 0.0) rules.push_back(qos::MakeMissRatioRule(f.max_miss_pct));
  if (f.mk_rules.empty()) {
    // The documented default (m,k) rule for this rate pair (docs/qos.md).
    for (const qos::RuleSpec& rule : qos::DefaultRulesFor(f.rate_hz, other_rate_hz)) {
      if (rule.kind == qos::RuleKind::kMkFirm) rules.push_back(rule);
    }
  }
  for (const std::string& text : f.mk_rules) rules.push_back(qos::ParseMkRule(text));
  for (const std::string& text : f.window_rules) {
    rules.push_back(qos::ParseMissesInWindowRule(text));
  }
  if (f.max_consecutive_misses) {
    rules.push_back(qos::MakeConsecutiveMissesRule(*f.max_consecutive_misses));
  }
  return rules;
}

/// --on-violation and the rules; any that is bad is "QoS rules: ..." with where to read more.
void ParseQos(const SessionFlags& f, const SessionRole& role, SessionSettings& s) {
  try {
    s.on_violation = qos::ParseViolationPolicy(f.on_violation);
    s.qos_rules = QosRulesOf(f, role.other_rate_hz);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("QoS rules: ") + e.what() + " (see 'hiltwin " + role.command +
               " --help' and docs/qos.md)");
  }
}

/// --inject-overrun's SPECs. More than a run can hold is refused here too (the injector's
/// length_error), so every problem with the flag's text is found at the command line.
std::vector<runtime::OverrunInjection> OverrunInjectionsOf(const std::vector<std::string>& specs) {
  std::vector<runtime::OverrunInjection> injections;
  runtime::OverrunInjector capacity;
  try {
    for (const std::string& spec : specs) {
      injections.push_back(runtime::ParseOverrunInjection(spec));
      capacity.Add(injections.back());
    }
  } catch (const std::exception& e) {  // invalid_argument, length_error: both the user's input
    ThrowUsage(std::string("--inject-overrun ") + e.what());
  }
  return injections;
}

/// --inject-link-fault's SPECs (whether the board and the run's length suit them is RunTwin's
/// check: CheckTwinRunOptions).
std::vector<io::LinkFaultInjection> LinkFaultsOf(const std::vector<std::string>& specs) {
  std::vector<io::LinkFaultInjection> faults;
  io::LinkFaultSchedule capacity;
  try {
    for (const std::string& spec : specs) {
      faults.push_back(io::ParseLinkFaultInjection(spec));
      capacity.Add(faults.back());
    }
  } catch (const std::exception& e) {
    ThrowUsage(std::string("--inject-link-fault ") + e.what());
  }
  return faults;
}

/// Every file `run` reads and writes: --input (unless built in), --plant-map, --config, the
/// FMU of --plant fmu:PATH, and the shared outputs.
std::vector<NamedFile> TwinRunFiles(const TwinRunFlags& f) {
  std::vector<NamedFile> files = SessionOutputFiles(f.session);
  files.push_back(ProfileFile("--input", f.input, BuiltinProfileNames()));
  files.push_back({"--plant-map", f.plant_map_path, false});
  files.push_back({"--config", f.config_path, false});
  files.push_back({"--plant", FmuPathOf(f.plant), false});
  files.push_back(ProfileFile("--show-setpoint", f.show_setpoint, BuiltinSetpointNames()));
  return files;
}

/// --input-rate, or its documented default.
double ControllerRateOf(const TwinRunFlags& f) {
  // Only a missing flag means the default: a given 0 is refused (ValidateTwinRunNumbers).
  return f.input_rate_hz.value_or(std::min(1000.0, f.session.rate_hz));
}

}  // namespace

void AddSessionFlags(CLI::App& app, SessionFlags& o) {
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
  app.add_option("--clock", o.clock,
                 "realtime, or virtual: the identical loop as fast as possible; on --io wire:NAME "
                 "both sides must say virtual and then run in lockstep on one virtual time base "
                 "(exact and repeatable; docs/lockstep.md)")
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
  AddTelemetryFlags(app, o.telemetry);
}

void AddTelemetryFlags(CLI::App& app, telemetry::TelemetryOptions& t) {
  app.add_option("--telemetry", t.specs,
                 "live telemetry out of the loop (repeatable): dds[:DOMAIN] publishes ROS 2 "
                 "topics rt/NS/{odom,pose,joint_states,timing}, rt/tf (and rt/clock on the "
                 "virtual clock) on DOMAIN (default ROS_DOMAIN_ID, else 0) and takes commands on "
                 "rt/NS/command; udp[:HOST:PORT] streams JSON to PlotJuggler (default "
                 "127.0.0.1:9870)");
  app.add_option("--namespace", t.ns,
                 "telemetry namespace NS, one per task on a network (default: twin for run, "
                 "controller for ecs; hil publishes its sides under NS/twin and NS/controller, "
                 "default hil)");
  app.add_option("--web", t.web,
                 "serve a live page (pose and trail in 2D or 3D, the setpoint, wheels, timing) at "
                 "ADDR:PORT (bare --web: 127.0.0.1:8080)")
      ->expected(0, 1)
      ->default_str("127.0.0.1:8080");
  app.add_option("--telemetry-rate", t.rate_hz, "telemetry records per second (0 < HZ <= 1000)")
      ->capture_default_str();
  app.add_flag("--accept-commands", t.accept_commands,
               "with --telemetry dds: take commands (stop, pause, start, ...) on rt/NS/command "
               "from any participant on the DDS domain; without it they are refused, and the "
               "task and the sender say so");
}

std::vector<NamedFile> SessionOutputFiles(const SessionFlags& f) {
  return {{"--log", f.log_path, true},
          {"--timing-log", f.timing_log_path, true},
          {"--report", f.report_path, true}};
}

runtime::ClockKind ClockKindOf(const std::string& text) {
  if (text == "virtual") return runtime::ClockKind::kVirtual;
  if (text != "realtime") ThrowUsage("--clock " + text + ": use realtime or virtual");
  return runtime::ClockKind::kRealtime;
}

SessionSettings SessionNumbersOf(const SessionFlags& f) {
  SessionSettings s;
  s.rate_hz = f.rate_hz;
  s.duration_s = f.duration_s;
  s.grace_cycles = f.grace_cycles;
  s.deadline_ns = DeadlineNsOf(f.deadline_us, f.rate_hz);
  s.log_path = f.log_path;
  s.log_decimation = f.log_decimation;
  s.timing_log_path = f.timing_log_path;
  s.report_path = f.report_path;
  s.priority = f.priority;
  s.cpus = f.cpus;
  s.progress = !f.no_progress;
  s.wait_peer_s = f.wait_peer_s;
  s.telemetry = f.telemetry;
  return s;
}

void ParseSessionTexts(const SessionFlags& f, const SessionRole& role, SessionSettings& s) {
  s.io = BackendSpecOf(f.io);
  s.io_text = f.io;
  s.board_image = BoardImageOf(f.board_image);
  s.clock = ClockKindOf(f.clock);
  s.overrun_policy = OverrunPolicyOf(f.overrun_policy);
  ParseQos(f, role, s);
  s.overrun_injections = OverrunInjectionsOf(f.inject_overrun);
}

SessionSettings SessionSettingsFrom(const SessionFlags& f, const SessionRole& role) {
  SessionSettings s = SessionNumbersOf(f);
  ValidateSessionSettings(s);  // the rate first: the deadline and the default rules derive from it
  ParseSessionTexts(f, role, s);
  return s;
}

void AddTwinRunFlags(CLI::App& app, TwinRunFlags& o) {
  AddSessionFlags(app, o.session);
  app.add_option("--input", o.input,
                 "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app.add_option("--input-rate", o.input_rate_hz,
                 "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                 "default 1000, or --rate if lower)");
  app.add_option("--plant", o.plant,
                 "the plant: a built-in or 20-sim plant's name, or fmu:PATH.fmu for an FMI 2.0 "
                 "co-simulation FMU (docs/plants.md)")
      ->capture_default_str();
  app.add_option("--plant-map", o.plant_map_path,
                 "plant map (TOML): which PWM channel drives which plant input and which output "
                 "each encoder follows, with scales (default: the plant's own; docs/plants.md)");
  app.add_option("--config", o.config_path,
                 "RELbot parameter file (TOML, see relbot/relbot.toml)");
  app.add_option("--integrator", o.integrator,
                 "RELbot integrator: euler | rk2 | rk4 (default rk4)");
  app.add_option("--inject-link-fault", o.inject_link_faults,
                 "fault injection (mock and wire): break the link at exchange K, e.g. "
                 "drop-answer,at=4000,count=3; KIND corrupt-request, corrupt-answer, drop-answer, "
                 "delay-answer or stuck-encoder (to the end without count) (repeatable)");
  app.add_option("--show-setpoint", o.show_setpoint,
                 "telemetry only: a controller's setpoint profile (closedloop or CSV "
                 "time,left_m,right_m, as `ecs --setpoint`) sent with each record at the twin's "
                 "time, so the web page draws it beside the robot (hil passes its own)");
}

TwinRunOptions TwinRunOptionsFrom(const TwinRunFlags& f, const char* command,
                                  const std::vector<NamedFile>& more_files) {
  TwinRunOptions o;
  o.session = SessionNumbersOf(f.session);
  o.controller_rate_hz = ControllerRateOf(f);
  o.input = f.input;
  o.plant = f.plant;
  o.plant_map_path = f.plant_map_path;
  o.config_path = f.config_path;
  o.integrator = f.integrator;
  o.show_setpoint = f.show_setpoint;
  // The controller rate is checked with the session's numbers, before the default (m,k) rule
  // is derived from it.
  ValidateTwinRunNumbers(o);
  ParseSessionTexts(f.session, TwinRole(command, o.controller_rate_hz), o.session);
  o.link_faults = LinkFaultsOf(f.inject_link_faults);
  std::vector<NamedFile> files = TwinRunFiles(f);
  files.insert(files.end(), more_files.begin(), more_files.end());
  CheckFilesDistinct(files);
  return o;
}

}  // namespace hiltwin::app
