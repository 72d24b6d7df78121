// A twin built from `run`'s flags (twin_build.h).
#include "hiltwin/runs/twin_build.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/fmi/fmu_plant.h"
#include "hiltwin/plant/plant_registry.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/session_assembly.h"

namespace hiltwin::app {
namespace {

constexpr std::string_view kFmuPrefix = "fmu:";

std::string KnownPlants() {
  std::string list;
  for (const plant::PlantEntry* entry : plant::RegisteredPlants()) {
    list += "\n  " + entry->name + ": " + entry->description;
  }
  return list + "\n  fmu:PATH.fmu: an FMI 2.0 co-simulation FMU";
}

std::unique_ptr<plant::Plant> OpenPlant(const TwinRunOptions& o,
                                        const plant::PlantEntry** entry_out) {
  const plant::PlantOptions options{o.config_path, o.integrator};
  if (const std::string fmu = FmuPathOf(o.plant); !fmu.empty()) {
    return fmi::OpenFmuPlant(fmu, options);
  }
  const plant::PlantEntry* entry = plant::FindPlant(o.plant);
  if (entry == nullptr) {
    ThrowUsage("--plant " + o.plant + ": no such plant; the plants are:" + KnownPlants());
  }
  *entry_out = entry;
  return entry->make(options);
}

/// --show-setpoint's profile, or none; refused where nothing would show it.
std::optional<SetpointProfile> ShownSetpointOf(const TwinRunOptions& o) {
  if (o.show_setpoint.empty()) return std::nullopt;
  const telemetry::TelemetryOptions& t = o.session.telemetry;
  if (t.specs.empty() && t.web.empty()) {
    ThrowUsage("--show-setpoint " + o.show_setpoint + " draws the setpoint on the telemetry: "
               "give --web (the page) or --telemetry too");
  }
  if (o.plant != kRelbotPlantName) {
    ThrowUsage("--show-setpoint is the RELbot's wheel setpoints; --plant " + o.plant +
               " has other joints (leave the flag out)");
  }
  try {
    return LoadSetpointProfile(o.show_setpoint);
  } catch (const ProfileError& e) {
    ThrowUsage("--show-setpoint: " + std::string(e.what()));
  }
}

}  // namespace

std::string FmuPathOf(const std::string& plant) {
  return plant.starts_with(kFmuPrefix) ? plant.substr(kFmuPrefix.size()) : std::string();
}

void LoadTwinConfiguration(const TwinRunOptions& o, Twin& twin) {
  try {
    if (o.plant == kRelbotPlantName) {
      if (!o.config_path.empty()) twin.params = LoadRelbotParams(o.config_path);
      twin.integrator = ParseIntegrator(o.integrator.empty() ? "rk4" : o.integrator);
    }
    twin.profile.emplace(LoadInputProfile(o.input));
    twin.shown_setpoint = ShownSetpointOf(o);
  } catch (const ConfigError& e) {
    ThrowUsage(e.what());
  } catch (const ProfileError& e) {
    ThrowUsage(e.what());
  } catch (const std::invalid_argument& e) {
    ThrowUsage(e.what());
  }
}

TwinPlant MakeTwinPlant(const TwinRunOptions& o) {
  RegisterRelbotPlant();
  try {
    const plant::PlantEntry* entry = nullptr;
    TwinPlant out;
    out.plant = OpenPlant(o, &entry);
    if (!o.plant_map_path.empty()) {
      out.map = plant::LoadPlantMap(o.plant_map_path);
    } else if (entry != nullptr && entry->default_map) {
      out.map = entry->default_map(*out.plant);
    } else {
      ThrowUsage("--plant " + o.plant + " needs --plant-map FILE.toml: which PWM channel drives which "
            "of its inputs and which output each encoder follows (docs/plants.md)");
    }
    out.bound = plant::BindPlantMap(out.map, *out.plant);  // refused now, before the board opens
    return out;
  } catch (const plant::PlantError& e) {
    ThrowUsage("--plant " + o.plant + ": " + e.what());
  } catch (const plant::PlantMapError& e) {
    ThrowUsage("--plant-map: " + std::string(e.what()));
  }
}

std::unique_ptr<Twin> BuildTwin(const TwinRunOptions& o, kernel_glue::TimeNs period_ns) {
  auto twin = std::make_unique<Twin>();
  LoadTwinConfiguration(o, *twin);
  TwinPlant made = MakeTwinPlant(o);
  twin->plant = std::move(made.plant);
  twin->map_source = made.map.source;
  const double step_s = static_cast<double>(period_ns) * 1e-9;
  std::vector<double> y0(twin->plant->Info().outputs.size(), 0.0);
  try {
    twin->plant->SetInitialInputs(made.bound.initial_inputs);  // the map's [inputs] from t = 0
    twin->plant->Start(step_s, y0);
  } catch (const plant::PlantStepError& e) {
    // A plant that names the flag itself (a 20-sim step mismatch) is quoted as it is.
    const std::string why = e.what();
    ThrowUsage(why.starts_with("--rate") ? why : "--rate " + Num(o.session.rate_hz) + ": " + why);
  } catch (const plant::PlantError& e) {  // not the step's fault: an FMU that fails to start
    ThrowUsage("--plant " + o.plant + ": " + e.what());
  }
  twin->backend = OpenBoard(o.session, io::Image::kIcoboardInverse);
  twin->pwm_source =
      std::make_unique<ProfilePwmSource>(*twin->profile, o.controller_rate_hz, o.session.rate_hz);
  // Only a board in this process (mock, verilated) plays the profile; on a wire or real SPI the
  // controller drives the PWM.
  const io::BackendSpec::Kind kind = twin->backend->kind();
  const bool profile_drives =
      (kind == io::BackendSpec::Kind::kMock || kind == io::BackendSpec::Kind::kVerilated) &&
      twin->backend->AttachPwmSource(twin->pwm_source.get());
  twin->input_name =
      profile_drives ? twin->profile->name() : "the controller on " + o.session.io_text;
  // Nothing reads the twin's transfer times (the executive times its I/O step): no clock reads.
  twin->driver =
      std::make_unique<io::IcoBoardInverse>(twin->backend->bus(), io::UntimedTransfers());
  InitBoard(*twin->driver, period_ns);
  twin->task.emplace(*twin->driver, *twin->plant, std::move(made.bound), step_s, y0);
  return twin;
}

}  // namespace hiltwin::app
