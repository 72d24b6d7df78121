// The RELbot twin built from `run`'s flags (twin_build.h).
#include "hiltwin/app_relbot/twin_build.h"

#include <stdexcept>

#include "hiltwin/app_relbot/command.h"
#include "hiltwin/app_relbot/session_options.h"

namespace hiltwin::app {
namespace {

[[noreturn]] void Usage(const std::string& message) {
  throw CommandError(ExitCode::kUsage, message);
}

}  // namespace

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

std::unique_ptr<Twin> BuildTwin(const TwinRunOptions& o, kernel_glue::TimeNs period_ns) {
  auto twin = std::make_unique<Twin>();
  LoadTwinConfiguration(o, *twin);
  try {
    twin->model.emplace(twin->params, twin->integrator, static_cast<double>(period_ns) * 1e-9);
  } catch (const ConfigError& e) {
    Usage("--rate " + Num(o.session.rate_hz) + ": " + e.what());
  }
  twin->backend = OpenBoard(o.session, io::Image::kIcoboardInverse);
  twin->pwm_source =
      std::make_unique<ProfilePwmSource>(*twin->profile, o.controller_rate_hz, o.session.rate_hz);
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

}  // namespace hiltwin::app
