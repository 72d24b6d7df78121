// `hiltwin run` as a function (twin_run.h): flags -> twin -> the shared session assembly ->
// the run's outcome. cli/cmd_run.cpp and cli/cmd_trace.cpp both call it.
#include "hiltwin/app_relbot/twin_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "hiltwin/app_relbot/command.h"
#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/app_relbot/twin_task.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

[[noreturn]] void Usage(const std::string& message) {
  throw CommandError(ExitCode::kUsage, message);
}

void Validate(const TwinRunOptions& o) {
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

void LoadTwinConfiguration(const TwinRunOptions& o, Twin& twin) {
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
std::unique_ptr<Twin> BuildTwin(const TwinRunOptions& o, kernel_glue::TimeNs period_ns) {
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
  twin->input_name = profile_drives ? twin->profile->name() : "the controller on " + o.session.io;
  twin->driver = std::make_unique<io::IcoBoardInverse>(twin->backend->bus());
  InitBoard(*twin->driver, period_ns);
  twin->geometry = WheelGeometryOf(twin->params);
  twin->task.emplace(*twin->driver, *twin->model, twin->geometry);
  return twin;
}

void PrintStartLines(const char* command, const SessionOptions& o, std::uint64_t planned,
                     const std::string& input, const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(
      stdout,
      "hiltwin %s: RELbot twin at %.0f Hz for %.3f s (%llu cycles), io %s, input %s, %s clock\n",
      command, o.rate_hz, o.duration_s, static_cast<unsigned long long>(planned), o.io.c_str(),
      input.c_str(), o.clock.c_str());
  if (rt != nullptr)
    std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(*rt).c_str());
  std::fflush(stdout);
}

/// --input-rate, or its documented default.
double ControllerRateOf(const TwinRunOptions& o) {
  return o.controller_rate_hz == 0.0 ? std::min(1000.0, o.session.rate_hz) : o.controller_rate_hz;
}

}  // namespace

void CheckTwinRunOptions(const TwinRunOptions& o) {
  TwinRunOptions checked = o;
  checked.controller_rate_hz = ControllerRateOf(o);
  Validate(checked);
}

TwinRunOutcome RunTwin(TwinRunOptions o, const char* command) {
  o.controller_rate_hz = ControllerRateOf(o);
  Validate(o);
  const std::uint64_t planned = PlannedCycles(o.session);
  std::ofstream report_file = OpenReport(o.session.report_path);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(o, period_ns);
  const SessionRole role{command, "controller", "hiltwin ecs", o.controller_rate_hz};
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *twin->backend);
  config.task_name = "RELbot twin";
  config.details = {{"input", twin->input_name},
                    {"integrator", std::string(IntegratorName(twin->integrator))}};
  config.on_ready = [command, s = o.session, planned,
                     input = twin->input_name](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(command, s, planned, input, rt);
  };
  const runtime::RunReport report = RunSessionOf(std::move(config), *twin->task);
  PrintOutcome(o.session, role, report, runtime::ToJson(report), "", report_file);
  if (report.fault && report.fault->kind == statemachine::StopReason::kModelFault) {
    std::fprintf(
        stderr,
        "hiltwin %s: try a higher --rate, --integrator rk4 or check the parameters in --config\n",
        command);
  }
  const int exit_code = static_cast<int>(runtime::ExitCodeFor(report));
  return {report, exit_code};
}

void AddTwinRunOptions(CLI::App& app, TwinRunOptions& o) {
  AddSessionOptions(app, o.session);
  app.add_option("--input", o.input,
                 "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app.add_option("--input-rate", o.controller_rate_hz,
                 "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                 "default 1000, or --rate if lower)");
  app.add_option("--config", o.config_path,
                 "RELbot parameter file (TOML, see app_relbot/relbot.toml)");
  app.add_option("--integrator", o.integrator, "euler | rk2 | rk4")->capture_default_str();
}

}  // namespace hiltwin::app
