#pragma once
/// A twin behind its FPGA link, built from `run`'s flags: the plant (`--plant`: the RELbot, a
/// 20-sim plant, an FMU) started at the run's step, its plant map (`--plant-map`, or the
/// plant's own), the input profile, the board and the task, owned together. `hiltwin run`
/// builds one per run; `hiltwin tune` builds one per measured or validated rate, so both run
/// the identical twin.

#include <memory>
#include <optional>
#include <string>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"
#include "hiltwin/plant/plant_twin_task.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/integrator.h"
#include "hiltwin/relbot/profile_pwm_source.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/twin_run.h"

namespace hiltwin::app {

/// Everything the twin's task uses; the task refers into it, so it is never moved.
struct Twin {
  /// The RELbot's parameters and integrator (--config, --integrator): what `tune` simulates
  /// its reference with. Unused by other plants, which refuse those flags.
  RelbotParams params = DefaultRelbotParams();
  Integrator integrator = Integrator::kRk4;
  std::optional<InputProfile> profile;
  std::unique_ptr<plant::Plant> plant;
  std::string map_source;  ///< the plant map's file, or "the built-in map of <plant>"
  std::unique_ptr<io::IoBackend> backend;
  std::unique_ptr<ProfilePwmSource> pwm_source;
  std::unique_ptr<io::IcoBoardInverse> driver;
  std::optional<plant::PlantTwinTask> task;
  std::string input_name;
  std::optional<SetpointProfile> shown_setpoint;  ///< --show-setpoint's profile
};

/// The FMU's path of `--plant fmu:PATH`; empty for a plant named by its name.
[[nodiscard]] std::string FmuPathOf(const std::string& plant);

/// Reads --config, --integrator, --input and --show-setpoint (exit 2 naming the problem) into
/// `twin`. --show-setpoint needs the RELbot (its joints are the wheels the setpoint is for) and
/// some telemetry (--web or --telemetry) to send it with.
void LoadTwinConfiguration(const TwinRunOptions& o, Twin& twin);

/// Builds the plant named by --plant and its map (--plant-map or the plant's own) without
/// starting it; exit 2 with the reason for an unknown plant, a bad FMU or map, a flag the
/// plant cannot honour. The map is checked against the plant's ports.
struct TwinPlant {
  std::unique_ptr<plant::Plant> plant;
  plant::PlantMap map;
  plant::BoundPlantMap bound;  ///< `map` checked against `plant`'s ports, for the task
};
[[nodiscard]] TwinPlant MakeTwinPlant(const TwinRunOptions& o);

/// Builds and starts the plant (a step it cannot run at is refused here, exit 2), opens the
/// link and checks the board's identity (exit 2 / 5), then builds the task. `o` must be
/// checked (CheckTwinRunOptions) and its controller rate set.
[[nodiscard]] std::unique_ptr<Twin> BuildTwin(const TwinRunOptions& o,
                                              kernel_glue::TimeNs period_ns);

}  // namespace hiltwin::app
