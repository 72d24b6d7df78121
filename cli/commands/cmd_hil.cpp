// `hiltwin hil`: the closed HiL loop on one machine. Starts the twin (`hiltwin run`) and the
// controller (`hiltwin ecs`) as two real processes on a fresh wire, lets them find each other
// (either may be first), waits for both, reads both run reports back and prints one combined
// summary; exits with the worse of the two exit codes (or the failed side's, when the other
// only echoes it). No shared memory is left behind.
// Flags -> HilRunOptions (checked, read once) -> RunHil (hiltwin/runs/hil_run.h).
#include <unistd.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "commands.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/pid_controller.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/controllers.h"
#include "hiltwin/runs/hil_run.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/scheduler/executive.h"
#include "session_flags.h"

namespace hiltwin::app {
namespace {

/// hil's namespace without --namespace: the sides publish under hil/twin and hil/controller.
telemetry::TelemetryOptions HilTelemetryDefaults() {
  telemetry::TelemetryOptions t;
  t.ns = "hil";
  return t;
}

void Validate(HilRunOptions& o) {
  for (const auto& [flag, rate] :
       {std::pair{"--twin-rate", o.twin_rate_hz}, std::pair{"--ecs-rate", o.ecs_rate_hz}}) {
    try {
      scheduler::ValidateRateHz(rate);
    } catch (const std::invalid_argument& e) {
      ThrowUsage(std::string(flag) + ": " + e.what());
    }
  }
  if (!std::isfinite(o.duration_s) || o.duration_s < 0.0 || o.duration_s > 7 * 86400.0) {
    ThrowUsage("--duration " + Num(o.duration_s) +
               ": must be 0 (the profile's length) .. 604800 s");
  }
  if (!std::isfinite(o.wait_peer_s) || o.wait_peer_s <= 0.0 || o.wait_peer_s > 3600.0) {
    ThrowUsage("--wait-peer " + Num(o.wait_peer_s) + ": must be above 0 and at most 3600 s");
  }
  if (o.duration_s == 0.0) {
    try {  // the same loaders the ECS uses, so a bad profile fails here with file:line
      o.duration_s = o.mode == "closedloop" ? LoadSetpointProfile(o.setpoint).length_s()
                                            : LoadInputProfile(o.input).period_s();
    } catch (const ProfileError& e) {
      ThrowUsage(e.what());
    }
  }
}

/// Checks the telemetry flags here, so a mistake is the parent's exit 2, not a child's.
void ValidateTelemetry(const telemetry::TelemetryOptions& t) {
  try {
    static_cast<void>(telemetry::ParseDdsSpecs(t.specs));
    static_cast<void>(telemetry::ParseUdpSpecs(t.specs));
    if (!t.web.empty()) static_cast<void>(telemetry::ParseWebSpec(t.web));
    telemetry::CheckAcceptCommands(t);
    telemetry::CheckNamespace(t.ns + "/controller");
  } catch (const std::invalid_argument& e) {
    ThrowUsage(e.what());
  }
}

/// The flags, read once, in the order they are checked (exit 2 naming the flag): the files (no
/// output names an input or another output), the rates and the duration (0: the profile's
/// length, read here), the controller map's syntax, the telemetry flags and the wire's name.
HilRunOptions HilRunOptionsOf(HilRunOptions o) {
  CheckFilesDistinct(HilFiles(o));
  Validate(o);
  // The controller and its map, made, bound and dropped here: a library that cannot be
  // loaded, a map that does not parse or does not fit the controller is the parent's exit 2
  // before either side starts, not an ECS that dies beside a twin waiting for it.
  if (o.mode == "closedloop") {
    static_cast<void>(MakeBoundController({o.controller.empty() ? kPidControllerName : o.controller,
                                           o.controller_map_path, o.gains_path, o.config_path}));
  }
  ValidateTelemetry(o.telemetry);
  if (o.wire.empty()) o.wire = "hil-" + std::to_string(::getpid());
  try {
    (void)io::WireBus::SegmentName(o.wire);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("--wire: ") + e.what());
  }
  return o;
}

Command AddHilCommand(CLI::App& parent) {
  auto o = std::make_shared<HilRunOptions>();
  o->telemetry = HilTelemetryDefaults();
  CLI::App* app = parent.add_subcommand(
      "hil",
      "Closed-loop HiL on one machine: twin and controller as two processes on one wire.\n"
      "The twin (`hiltwin run`) and the controller (`hiltwin ecs`) run on a fresh wire; one\n"
      "combined summary and report.\n"
      "The twin runs 2 s longer than the ECS, so the ECS's finish ends the pair. Exit: the worse\n"
      "of the two sides' codes (0 < 3 FLAGGED < 4 ABORTED < 128+N stopped by signal N before any\n"
      "cycle was judged < 5 I/O < 2 bad input < 1 internal). SIGINT/SIGTERM/SIGHUP stop both\n"
      "sides cleanly; their reports are combined and the work folder removed.");
  app->add_option("--twin-rate", o->twin_rate_hz, "twin update rate in Hz")->capture_default_str();
  app->add_option("--ecs-rate", o->ecs_rate_hz, "controller rate in Hz")->capture_default_str();
  app->add_option("--duration", o->duration_s,
                  "controller run length in seconds (default: the profile's length)");
  app->add_option("--mode", o->mode,
                  "closedloop (--controller on --setpoint) or openloop (--input duty)")
      ->check(CLI::IsMember({"closedloop", "openloop"}))
      ->capture_default_str();
  app->add_option("--setpoint", o->setpoint, "closed loop: closedloop or CSV time,left_m,right_m")
      ->capture_default_str();
  app->add_option("--input", o->input, "open loop: openloop or CSV time,left,right")
      ->capture_default_str();
  app->add_option("--controller", o->controller,
                  "the ECS's controller: pid (default), lib:PATH.so, 20sim:NAME, fmu:PATH.fmu");
  app->add_option("--controller-map", o->controller_map_path,
                  "the ECS's controller map (TOML; default: relbot/ecs_controller_map.toml)");
  app->add_option("--gains", o->gains_path,
                  "--controller pid's gains (TOML, relbot/ecs_gains.toml)");
  app->add_option("--config", o->config_path, "RELbot parameters (TOML), for both sides");
  app->add_option("--twin-qos", o->twin_qos, "twin (m,k) rule M:K (repeatable)");
  app->add_option("--ecs-qos", o->ecs_qos, "controller (m,k) rule M:K (repeatable)");
  app->add_option("--twin-max-miss-pct", o->twin_max_miss_pct, "twin miss ratio limit, %");
  app->add_option("--ecs-max-miss-pct", o->ecs_max_miss_pct, "controller miss ratio limit, %");
  app->add_option("--on-violation", o->on_violation,
                  "flag or abort, for both sides (default: flag; one side alone: --twin-arg)")
      ->check(CLI::IsMember({"flag", "abort"}));
  app->add_option("--twin-arg", o->twin_args,
                  "pass one more argument to `hiltwin run` (repeatable), e.g. --twin-arg=--cpu "
                  "--twin-arg=1");
  app->add_option("--ecs-arg", o->ecs_args, "pass one more argument to `hiltwin ecs` (repeatable)");
  app->add_option("--report", o->report_path, "write the combined JSON report to this file");
  app->add_option("--log-dir", o->log_dir,
                  "keep twin.csv, ecs.csv, both reports and both outputs in this folder");
  app->add_option("--wire", o->wire, "wire name (default: hil-<pid>, fresh)");
  app->add_option("--wait-peer", o->wait_peer_s, "how long each side waits for the other, s")
      ->capture_default_str();
  app->add_option("--clock", o->clock,
                  "realtime: both sides on CLOCK_MONOTONIC (timing, QoS); virtual: both sides in "
                  "lockstep on one virtual time base, as fast as they compute, with results that "
                  "are exact and repeatable on any machine (docs/lockstep.md)")
      ->check(CLI::IsMember({"realtime", "virtual"}))
      ->capture_default_str();
  app->add_flag("--no-progress", o->no_progress, "no progress line on the terminal");
  AddTelemetryFlags(*app, o->telemetry);
  return {app, [o] { return RunHil(HilRunOptionsOf(*o)); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(30, AddHilCommand);

}  // namespace hiltwin::app
