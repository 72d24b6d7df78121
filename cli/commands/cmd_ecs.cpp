// `hiltwin ecs`: the RELbot's embedded controller on the same framework as the twin (executive,
// lifecycle, QoS verdict, run report, logger), through the ECS image of the IcoBoard. The
// controller code is identical for the twin and the robot (thesis requirement "Must 1"): only
// --io differs, wire:NAME against `hiltwin run --io wire:NAME`, spidev:/dev/spidev0.0 on the robot.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/ecs_report.h"
#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/runs/session_options.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

/// `ecs`'s own flags beside the shared ones.
struct EcsOptions {
  SessionOptions session;
  bool duration_given = false;
  std::string mode = "closedloop";
  std::string setpoint = "closedloop";
  std::string input = "openloop";
  std::string gains_path;
  std::string config_path;
};

/// The controller behind its board, built from the flags; owns everything the task uses.
struct Ecs {
  RelbotParams params = DefaultRelbotParams();
  PidGains gains = DefaultEcsGains();
  std::optional<SetpointProfile> setpoints;
  std::optional<InputProfile> duty_profile;
  std::unique_ptr<io::IoBackend> backend;
  std::unique_ptr<io::IcoBoard> driver;
  std::optional<EcsTask> task;
  std::string profile_name;
};

void LoadEcsConfiguration(const EcsOptions& o, Ecs& ecs) {
  try {
    if (!o.config_path.empty()) ecs.params = LoadRelbotParams(o.config_path);
    if (!o.gains_path.empty()) ecs.gains = LoadEcsGains(o.gains_path);
    if (o.mode == "closedloop") {
      ecs.setpoints.emplace(LoadSetpointProfile(o.setpoint));
      ecs.profile_name = ecs.setpoints->name();
    } else {
      ecs.duty_profile.emplace(LoadInputProfile(o.input));
      ecs.profile_name = ecs.duty_profile->name();
    }
  } catch (const ConfigError& e) {
    ThrowUsage(e.what());
  } catch (const ProfileError& e) {
    ThrowUsage(e.what());
  }
}

/// Loads gains and profiles (exit 2 with file:line), opens the link and checks the board's
/// identity (exit 5 with the thesis's message), then builds the task.
std::unique_ptr<Ecs> BuildEcs(const EcsOptions& o, kernel_glue::TimeNs period_ns) {
  auto ecs = std::make_unique<Ecs>();
  LoadEcsConfiguration(o, *ecs);
  ecs->backend = OpenBoard(o.session, io::Image::kIcoboard);
  ecs->driver = std::make_unique<io::IcoBoard>(ecs->backend->bus());
  InitBoard(*ecs->driver, period_ns);
  const io::WheelGeometry geometry = WheelGeometryOf(ecs->params);
  try {
    if (ecs->setpoints) {
      ecs->task.emplace(*ecs->driver, *ecs->setpoints, ecs->gains, geometry, period_ns);
    } else {
      ecs->task.emplace(*ecs->driver, *ecs->duty_profile, geometry, period_ns);
    }
  } catch (const ConfigError& e) {
    ThrowUsage(std::string("--gains: ") + e.what());
  }
  return ecs;
}

void PrintStartLines(const EcsOptions& o, std::uint64_t planned, const std::string& profile,
                     const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(stdout,
               "hiltwin ecs: RELbot controller (%s, %s) at %.0f Hz for %.3f s (%llu cycles), "
               "io %s, %s clock\n",
               o.mode.c_str(), profile.c_str(), o.session.rate_hz, o.session.duration_s,
               static_cast<unsigned long long>(planned), o.session.io.c_str(),
               o.session.clock.c_str());
  if (o.session.io == "mock") {
    std::fprintf(stdout,
                 "note: the mock board has no plant behind it, so the encoders stay at 0; drive "
                 "the twin with --io wire:NAME and `hiltwin run --io wire:NAME`, or use `hiltwin "
                 "hil`\n");
  }
  if (rt != nullptr)
    std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(*rt).c_str());
  std::fflush(stdout);
}

int RunEcs(EcsOptions o) {
  const kernel_glue::TimeNs period_ns = [&] {
    ValidateSessionOptions(o.session);  // the rate first: the period depends on it
    return kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  }();
  kernel_glue::InstallStopSignalHandlers();  // before any output exists: as `run` does
  ReportFile report_file(o.session.report_path);
  const std::unique_ptr<Ecs> ecs = BuildEcs(o, period_ns);
  // By default the run lasts as long as its profile: the setpoints end settled.
  if (!o.duration_given) o.session.duration_s = ecs->task->length_s();
  ValidateSessionOptions(o.session);
  const std::uint64_t planned = PlannedCycles(o.session);
  const SessionRole role{"ecs", "twin", "hiltwin run", o.session.rate_hz, "controller"};
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *ecs->backend);
  config.task_name = "RELbot ECS";
  config.details = {{"mode", o.mode}, {"profile", ecs->profile_name}};
  config.on_ready = [o, planned, profile = ecs->profile_name](
                        const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(o, planned, profile, rt);
  };
  const runtime::RunReport report = RunSessionOf(std::move(config), *ecs->task);
  const EcsFigures figures =
      EcsFiguresOf(*ecs->task, *ecs->driver, ecs->backend->emulated_board());
  PrintOutcome(role, report, EcsReportJson(report, figures), FormatEcsFigures(figures),
               report_file);
  return static_cast<int>(runtime::ExitCodeFor(report));
}

Command AddEcsCommand(CLI::App& parent) {
  auto o = std::make_shared<EcsOptions>();
  o->session.rate_hz = 1000.0;
  CLI::App* app = parent.add_subcommand(
      "ecs",
      "Run the RELbot's embedded controller (ECS) with a QoS verdict.\n"
      "Closed loop (default): one position PID per wheel follows --setpoint (built-in\n"
      "closedloop: 2.5 m forward, thesis 7.2) and reports the tracking error. Open loop: plays the\n"
      "duty profile --input and logs duty and measured wheel positions (thesis 5.2).\n"
      "The same controller drives the twin (--io wire:NAME, with `hiltwin run --io wire:NAME`)\n"
      "or the robot (--io spidev:/dev/spidev0.0). Default (m,k) rule: (1,2), never two misses\n"
      "in a row. Exit: 0 PASS, 2 bad input, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 internal.\n"
      "SIGINT/SIGTERM stop it cleanly, SIGUSR1 pauses (zero duty), SIGUSR2 resumes.");
  AddSessionOptions(*app, o->session);
  app->get_option("--duration")
      ->description("run length in seconds (default: the profile's length)")
      ->each([o](const std::string&) { o->duration_given = true; });
  app->add_option("--mode", o->mode, "closedloop (PID on --setpoint) or openloop (--input duty)")
      ->check(CLI::IsMember({"closedloop", "openloop"}))
      ->capture_default_str();
  app->add_option("--setpoint", o->setpoint,
                  "closed loop: built-in closedloop, or a CSV file time,left_m,right_m")
      ->capture_default_str();
  app->add_option("--input", o->input,
                  "open loop: built-in openloop, or a CSV duty file time,left,right")
      ->capture_default_str();
  app->add_option("--gains", o->gains_path,
                  "PID gains and limits (TOML, see app_relbot/ecs_gains.toml; default: built in)");
  app->add_option("--config", o->config_path,
                  "RELbot parameter file for the wheel geometry (TOML, app_relbot/relbot.toml)");
  return {app, [o] { return RunEcs(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(20, AddEcsCommand);

}  // namespace hiltwin::app
