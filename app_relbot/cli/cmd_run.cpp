// `hiltwin run`: the RELbot twin in real time (or on the virtual clock) behind the FPGA link,
// with a QoS verdict, a JSON run report and an optional CSV log (DESIGN.md "Contracts").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "hiltwin/app_relbot/commands.h"
#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/session_options.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

/// `run`'s own flags beside the shared ones.
struct RunOptions {
  SessionOptions session;
  std::string input = "openloop";
  double controller_rate_hz = 0.0;  ///< 0: min(1000 Hz, --rate), the thesis ECS rate
  std::string config_path;
  std::string integrator = "rk4";
};

[[noreturn]] void Usage(const std::string& message) {
  throw CommandError(ExitCode::kUsage, message);
}

void Validate(const RunOptions& o) {
  ValidateSessionOptions(o.session);
  if (!std::isfinite(o.controller_rate_hz) || o.controller_rate_hz <= 0.0 ||
      o.controller_rate_hz > o.session.rate_hz) {
    Usage("--input-rate: the controller rate must be positive and not above --rate (" +
          Num(o.session.rate_hz) + " Hz)");
  }
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
    Usage("--rate " + Num(o.session.rate_hz) + ": " + e.what());
  }
  twin->backend = OpenBoard(o.session, io::Image::kIcoboardInverse);
  twin->pwm_source = std::make_unique<ProfilePwmSource>(*twin->profile, o.controller_rate_hz);
  // Only the mock board plays the profile; on a wire or real SPI the controller drives the PWM.
  const bool profile_drives = twin->backend->kind() == io::BackendSpec::Kind::kMock;
  if (io::EmulatedFpga* board = twin->backend->emulated_board();
      board != nullptr && profile_drives) {
    board->SetPwmSource(twin->pwm_source.get());
  }
  twin->input_name =
      profile_drives ? twin->profile->name() : "the controller on " + o.session.io;
  twin->driver = std::make_unique<io::IcoBoardInverse>(twin->backend->bus());
  InitBoard(*twin->driver, period_ns);
  twin->geometry = WheelGeometryOf(twin->params);
  twin->task.emplace(*twin->driver, *twin->model, twin->geometry);
  return twin;
}

void PrintStartLines(const SessionOptions& o, std::uint64_t planned, const std::string& input,
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

int RunTwin(RunOptions o) {
  if (o.controller_rate_hz == 0.0) o.controller_rate_hz = std::min(1000.0, o.session.rate_hz);
  Validate(o);
  const std::uint64_t planned = PlannedCycles(o.session);
  std::ofstream report_file = OpenReport(o.session.report_path);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(o, period_ns);
  const SessionRole role{"run", "controller", "hiltwin ecs", o.controller_rate_hz};
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *twin->backend);
  config.task_name = "RELbot twin";
  config.details = {{"input", twin->input_name},
                    {"integrator", std::string(IntegratorName(twin->integrator))}};
  config.on_ready = [s = o.session, planned,
                     input = twin->input_name](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(s, planned, input, rt);
  };
  const runtime::RunReport report = RunSessionOf(std::move(config), *twin->task);
  PrintOutcome(o.session, role, report, runtime::ToJson(report), "", report_file);
  if (report.fault && report.fault->kind == statemachine::StopReason::kModelFault) {
    std::fprintf(
        stderr,
        "hiltwin run: try a higher --rate, --integrator rk4 or check the parameters in --config\n");
  }
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
  AddSessionOptions(*app, o->session);
  app->add_option("--input", o->input,
                  "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app->add_option("--input-rate", o->controller_rate_hz,
                  "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                  "default 1000, or --rate if lower)");
  app->add_option("--config", o->config_path,
                  "RELbot parameter file (TOML, see app_relbot/relbot.toml)");
  app->add_option("--integrator", o->integrator, "euler | rk2 | rk4")->capture_default_str();
  return {app, [o] { return RunTwin(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(10, AddRunCommand);

}  // namespace hiltwin::app
