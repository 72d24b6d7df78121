#pragma once
/// The controllers `--controller SPEC` can name (controller/controller_registry.h): every kind
/// registers here, once, before the command line looks one up, as the plants register before
/// `--plant` is read (RegisterRelbotPlant). And the one place a controller is made from the
/// flags and bound to its map: `ecs` runs what it makes; `hil` makes it once before either side
/// starts, so a controller that cannot be loaded or does not fit its map is the parent's exit 2
/// instead of an ECS that dies beside a twin left waiting for it.

#include <memory>
#include <string>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_map.h"

namespace hiltwin::app {

/// Registers every controller and controller kind hiltwin is built with; idempotent.
void RegisterControllers();

/// What --controller, --controller-map, --gains and --config give the ECS's closed loop.
struct ControllerFlags {
  std::string spec;         ///< --controller
  std::string map_path;     ///< --controller-map ("": the RELbot's map)
  std::string gains_path;   ///< --gains (the built-in PID's only)
  std::string config_path;  ///< --config: the RELbot's wheel geometry for its map
};

/// A controller, not started, with the map it runs with, bound to its ports.
struct BoundController {
  std::unique_ptr<controller::Controller> controller;
  controller::BoundControllerMap map;
  std::string map_source;  ///< the map's file, or the built-in map's name
};

/// --gains belongs to the built-in PID: beside another controller, which would silently
/// ignore it, exit 2 naming both flags. Checked before --gains is read.
void CheckGainsFlag(const ControllerFlags& flags);

/// Makes the controller `flags.spec` names and binds `flags.map_path`'s map (or the RELbot's,
/// with --config's wheel geometry) to it. Exit 2 (UsageError) with the message of whatever is
/// wrong: --gains beside another controller, the spec, the map, the fit of the two.
[[nodiscard]] BoundController MakeBoundController(const ControllerFlags& flags);

}  // namespace hiltwin::app
