#pragma once
/// Plants by name. Built-in and 20-sim plants register a factory under their name (a 20-sim
/// plant does so from the code that `hiltwin_add_20sim_plant` generates, cmake/TwentySimPlant
/// .cmake); `--plant NAME` finds them here. FMUs are not registered: `--plant fmu:PATH` names
/// a file (fmi module).

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"

namespace hiltwin::plant {

/// What the command line may pass to a plant's factory. A plant refuses (PlantError) an
/// option it has no use for, so a flag is never silently ignored.
struct PlantOptions {
  std::string config_path;  ///< --config: a parameter file ("" = the plant's own values)
  std::string integrator;   ///< --integrator ("" = the plant's default)
};

using PlantFactory = std::function<std::unique_ptr<Plant>(const PlantOptions&)>;

struct PlantEntry {
  std::string name;
  std::string description;  ///< one line for --help and "unknown plant" errors
  PlantFactory make;
  /// The plant's board wiring when --plant-map is not given (the RELbot's appendix G map);
  /// empty: the plant needs a --plant-map.
  std::function<PlantMap(const Plant&)> default_map;
};

/// Adds a plant; returns true so it can initialise a namespace-scope constant. A second entry
/// under the same name is a build mistake and aborts at start-up with both descriptions.
bool RegisterPlant(PlantEntry entry);

/// The entry called `name`, or nullptr.
[[nodiscard]] const PlantEntry* FindPlant(const std::string& name);

/// Every registered plant, sorted by name.
[[nodiscard]] std::vector<const PlantEntry*> RegisteredPlants();

}  // namespace hiltwin::plant
