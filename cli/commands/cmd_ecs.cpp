// `hiltwin ecs`: the RELbot's embedded controller on the same framework as the twin (executive,
// lifecycle, QoS verdict, run report, logger), through the ECS image of the IcoBoard. The
// controller code is identical for the twin and the robot (thesis requirement "Must 1"): only
// --io differs, wire:NAME against `hiltwin run --io wire:NAME`, spidev:/dev/spidev0.0 on the robot.
// Flags -> EcsRunOptions (typed, read once) -> RunEcs (hiltwin/runs/ecs_run.h).
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/ecs_run.h"
#include "hiltwin/runs/output_files.h"
#include "session_flags.h"

namespace hiltwin::app {
namespace {

/// `ecs`'s own flags beside the shared ones, as the command line gave them.
struct EcsFlags {
  SessionFlags session;
  bool duration_given = false;
  std::string mode = "closedloop";
  std::string setpoint = "closedloop";
  std::string input = "openloop";
  std::string controller = "pid";
  bool controller_given = false;
  std::string controller_map_path;
  std::string gains_path;
  std::string config_path;
};

/// Every file `ecs` reads and writes: the profiles (unless built in), --gains, --config and the
/// shared outputs.
std::vector<NamedFile> EcsFiles(const EcsFlags& f) {
  std::vector<NamedFile> files = SessionOutputFiles(f.session);
  files.push_back(ProfileFile("--setpoint", f.setpoint, BuiltinSetpointNames()));
  files.push_back(ProfileFile("--input", f.input, BuiltinProfileNames()));
  files.push_back({"--controller-map", f.controller_map_path, false});
  files.push_back({"--gains", f.gains_path, false});
  files.push_back({"--config", f.config_path, false});
  return files;
}

/// The flags, read once (exit 2 naming the flag); no output names an input or another output.
EcsRunOptions EcsRunOptionsOf(const EcsFlags& f) {
  EcsRunOptions o;
  o.session = SessionSettingsFrom(f.session, EcsRole(f.session.rate_hz));
  o.duration_given = f.duration_given;
  o.mode = f.mode == "openloop" ? EcsMode::kOpenLoop : EcsMode::kClosedLoop;  // CLI11-checked
  o.setpoint = f.setpoint;
  o.input = f.input;
  // Open loop plays a duty profile: no controller runs, so naming one is a mistake.
  if (f.mode == "openloop" && (f.controller_given || !f.controller_map_path.empty())) {
    ThrowUsage(std::string(f.controller_given ? "--controller" : "--controller-map") +
               " is for --mode closedloop; open loop plays --input's duties without a "
               "controller: drop it, or use --mode closedloop");
  }
  o.controller = f.controller;
  o.controller_map_path = f.controller_map_path;
  o.gains_path = f.gains_path;
  o.config_path = f.config_path;
  CheckFilesDistinct(EcsFiles(f));
  return o;
}

Command AddEcsCommand(CLI::App& parent) {
  auto o = std::make_shared<EcsFlags>();
  o->session.rate_hz = 1000.0;
  CLI::App* app = parent.add_subcommand(
      "ecs",
      "Run the RELbot's embedded controller (ECS) with a QoS verdict.\n"
      "Closed loop (default): the controller (--controller; default pid, one position PID per\n"
      "wheel) follows --setpoint (built-in closedloop: 2.5 m forward, thesis 7.2) and reports\n"
      "the tracking error; one that returns an error, NaN or a duty beyond its limit is\n"
      "stopped with zero duty and the run ends ABORTED. Open loop: plays the\n"
      "duty profile --input and logs duty and measured wheel positions (thesis 5.2).\n"
      "The same controller drives the twin (--io wire:NAME, with `hiltwin run --io wire:NAME`)\n"
      "or the robot (--io spidev:/dev/spidev0.0). Default (m,k) rule: (1,2), never two misses\n"
      "in a row. Exit: 0 PASS, 2 bad input, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 internal.\n"
      "No cycle judged, no verdict (NONE): 128+N when stopped by signal N first (130 SIGINT,\n"
      "143 SIGTERM, 129 SIGHUP), 5 when the twin went first.\n"
      "SIGINT/SIGTERM/SIGHUP stop it cleanly, SIGUSR1 pauses (zero duty), SIGUSR2 resumes.");
  AddSessionFlags(*app, o->session);
  app->get_option("--duration")
      ->description("run length in seconds (default: the profile's length)")
      ->each([o](const std::string&) { o->duration_given = true; });
  app->add_option("--mode", o->mode,
                  "closedloop (--controller on --setpoint) or openloop (--input duty)")
      ->check(CLI::IsMember({"closedloop", "openloop"}))
      ->capture_default_str();
  app->add_option("--setpoint", o->setpoint,
                  "closed loop: built-in closedloop, or a CSV file time,left_m,right_m")
      ->capture_default_str();
  app->add_option("--input", o->input,
                  "open loop: built-in openloop, or a CSV duty file time,left,right")
      ->capture_default_str();
  app->add_option("--controller", o->controller,
                  "closed loop: the controller, pid (built in), lib:PATH.so (C ABI), 20sim:NAME or "
                  "fmu:PATH.fmu (docs/controllers.md)")
      ->capture_default_str()
      ->each([o](const std::string&) { o->controller_given = true; });
  app->add_option("--controller-map", o->controller_map_path,
                  "controller map (TOML): which encoder, setpoint column and PWM channel meet "
                  "which controller port (default: the RELbot's, relbot/ecs_controller_map.toml)");
  app->add_option("--gains", o->gains_path,
                  "--controller pid's gains and limits (TOML, see relbot/ecs_gains.toml; default: "
                  "built in)");
  app->add_option("--config", o->config_path,
                  "RELbot parameter file for the wheel geometry (TOML, relbot/relbot.toml)");
  return {app, [o] { return RunEcs(EcsRunOptionsOf(*o)); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(20, AddEcsCommand);

}  // namespace hiltwin::app
