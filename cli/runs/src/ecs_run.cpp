// `hiltwin ecs`'s run (hiltwin/runs/ecs_run.h): the RELbot's embedded controller on the same
// framework as the twin (executive, lifecycle, QoS verdict, run report, logger), through the
// ECS image of the IcoBoard. The controller code is identical for the twin and the robot
// (thesis requirement "Must 1"): only --io differs, wire:NAME against `hiltwin run --io
// wire:NAME`, spidev:/dev/spidev0.0 on the robot.
#include "hiltwin/runs/ecs_run.h"

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/ecs_report.h"
#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/relbot/encoder_reading.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/pid_controller.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/controllers.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

/// --mode's word for it, as the start line and the report say it.
const char* ToString(EcsMode mode) {
  return mode == EcsMode::kClosedLoop ? "closedloop" : "openloop";
}

/// The controller behind its board, built from the flags; owns everything the task uses.
struct Ecs {
  RelbotParams params = DefaultRelbotParams();
  PidGains gains = DefaultEcsGains();
  std::optional<SetpointProfile> setpoints;
  std::optional<InputProfile> duty_profile;
  std::unique_ptr<controller::Controller> controller;  ///< closed loop
  std::optional<controller::BoundControllerMap> map;   ///< closed loop, bound to `controller`
  std::string map_source;                              ///< the map's file, or the built-in's name
  std::unique_ptr<io::IoBackend> backend;
  std::unique_ptr<io::IcoBoard> driver;
  std::optional<EcsTask> task;
  std::string profile_name;
};

void LoadEcsConfiguration(const EcsRunOptions& o, Ecs& ecs) {
  CheckGainsFlag({o.controller, o.controller_map_path, o.gains_path, o.config_path});
  try {
    if (!o.config_path.empty()) ecs.params = LoadRelbotParams(o.config_path);
    if (!o.gains_path.empty()) ecs.gains = LoadEcsGains(o.gains_path);
    if (o.mode == EcsMode::kClosedLoop) {
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

/// The closed loop's controller and its map, bound (exit 2 with the spec's or the map's
/// message), before any board is opened.
void MakeEcsController(const EcsRunOptions& o, Ecs& ecs) {
  BoundController made =
      MakeBoundController({o.controller, o.controller_map_path, o.gains_path, o.config_path});
  ecs.controller = std::move(made.controller);
  ecs.map = std::move(made.map);
  ecs.map_source = std::move(made.map_source);
}

/// Loads gains, profiles and the controller (exit 2 with file:line), opens the link and checks
/// the board's identity (exit 5 with the thesis's message), then builds the task, which starts
/// the controller (exit 2 when it cannot run at the ECS's period).
std::unique_ptr<Ecs> BuildEcs(const EcsRunOptions& o, kernel_glue::TimeNs period_ns) {
  auto ecs = std::make_unique<Ecs>();
  LoadEcsConfiguration(o, *ecs);
  if (ecs->setpoints) MakeEcsController(o, *ecs);
  ecs->backend = OpenBoard(o.session, io::Image::kIcoboard);
  ecs->driver = std::make_unique<io::IcoBoard>(ecs->backend->bus());
  InitBoard(*ecs->driver, period_ns);
  const io::WheelGeometry geometry = WheelGeometryOf(ecs->params);
  try {
    if (ecs->setpoints) {
      ecs->task.emplace(*ecs->driver, *ecs->setpoints, *ecs->controller, std::move(*ecs->map),
                        geometry, period_ns);
    } else {
      ecs->task.emplace(*ecs->driver, *ecs->duty_profile, geometry, period_ns);
    }
  } catch (const controller::ControllerError& e) {
    ThrowUsage("--controller " + o.controller + ": " + e.what());
  }
  return ecs;
}

/// "setpoint_left_m [m], wheel_left_m [m]": a controller's ports as the start line and the
/// report give them.
std::string DescribePorts(const std::vector<controller::Port>& ports) {
  std::string out;
  for (const controller::Port& port : ports) {
    out += (out.empty() ? "" : ", ") + port.name + " [" + port.unit + "]";
  }
  return out.empty() ? "none" : out;
}

/// "controller pid (built-in): pid; inputs ...; outputs ...; map ...", and the file with its
/// SHA-256 when the code came from one.
std::string ControllerLine(const Ecs& ecs) {
  const controller::ControllerInfo& info = ecs.controller->Info();
  std::string line = "controller " + info.spec + " (" + info.kind + "): " + info.name +
                     "; inputs " + DescribePorts(info.inputs) + "; outputs " +
                     DescribePorts(info.outputs) + "; map " + ecs.map_source + "\n";
  if (!info.file.empty()) {
    line += "controller file " + info.file + ", sha256 " + info.content_sha256 + "\n";
  }
  return line;
}

/// "kp 100 duty/m, ki 1000 duty/(m s), kd 3 duty s/m, filter 0.005 s, limit 1": each number in
/// its shortest form that reads back to the same double, so the report holds the exact gains.
std::string DescribeGains(const PidGains& g) {
  return "kp " + ExactNum(g.kp_duty_per_m) + " duty/m, ki " + ExactNum(g.ki_duty_per_m_s) +
         " duty/(m s), kd " + ExactNum(g.kd_duty_s_per_m) + " duty s/m, filter " +
         ExactNum(g.derivative_filter_s) + " s, limit " + ExactNum(g.duty_limit);
}

void PrintStartLines(const EcsRunOptions& o, std::uint64_t planned, const std::string& profile,
                     const std::string& controller_line, const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(stdout,
               "hiltwin ecs: RELbot controller (%s, %s) at %.0f Hz for %.3f s (%llu cycles), "
               "io %s, %s clock\n",
               ToString(o.mode), profile.c_str(), o.session.rate_hz, o.session.duration_s,
               static_cast<unsigned long long>(planned), o.session.io_text.c_str(),
               runtime::ToString(o.session.clock));
  std::fputs(controller_line.c_str(), stdout);
  if (o.session.io.kind == io::BackendSpec::Kind::kMock) {
    std::fprintf(stdout,
                 "note: the mock board has no plant behind it, so the encoders stay at 0; drive "
                 "the twin with --io wire:NAME and `hiltwin run --io wire:NAME`, or use `hiltwin "
                 "hil`\n");
  }
  if (rt != nullptr)
    std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(*rt).c_str());
  std::fflush(stdout);
}

}  // namespace

/// How the controller's runs name themselves; its default (m,k) rule is judged at its own rate.
SessionRole EcsRole(double rate_hz) {
  return {"ecs", "twin", "hiltwin run", rate_hz, "controller"};
}

int RunEcs(const EcsRunOptions& options) {
  EcsRunOptions o = options;  // the duration is the profile's when not given
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  kernel_glue::InstallStopSignalHandlers();  // before any output exists: as `run` does
  ReportFile report_file(o.session.report_path);
  const std::unique_ptr<Ecs> ecs = BuildEcs(o, period_ns);
  // By default the run lasts as long as its profile: the setpoints end settled.
  if (!o.duration_given) o.session.duration_s = ecs->task->length_s();
  ValidateSessionSettings(o.session);
  const std::uint64_t planned = PlannedCycles(o.session);
  const SessionRole role = EcsRole(o.session.rate_hz);
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *ecs->backend);
  config.task_name = "RELbot ECS";
  config.details = {{"mode", ToString(o.mode)}, {"profile", ecs->profile_name}};
  // The gains the run used, to every digit: with the rates, profile and clock in the report,
  // a lockstep result can be reproduced from the report alone (docs/lockstep.md).
  if (o.mode == EcsMode::kClosedLoop && o.controller == kPidControllerName) {
    config.details.emplace_back("gains", DescribeGains(ecs->gains));
  }
  std::string controller_line;
  if (o.mode == EcsMode::kClosedLoop) {
    // The controller itself is the report's `controller` section (EcsReportJson).
    config.details.emplace_back("controller_map", ecs->map_source);
    controller_line = ControllerLine(*ecs);
  }
  config.on_ready = [o, planned, profile = ecs->profile_name,
                     controller_line](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(o, planned, profile, controller_line, rt);
  };
  // Whether this rate follows the counts (the twin's rate is not known here: `hil` checks it).
  config.warnings =
      EncoderReadingWarnings({o.session.rate_hz, std::nullopt, TopCountsPerSecond(ecs->params)});
  PrintWarnings("ecs", config.warnings);
  const runtime::RunReport report = RunSessionOf(std::move(config), *ecs->task);
  const EcsFigures figures = EcsFiguresOf(*ecs->task, *ecs->driver, ecs->backend->emulated_board());
  return PrintOutcome(role, report, EcsReportJson(report, figures), FormatEcsFigures(figures),
                      report_file);
}

}  // namespace hiltwin::app
