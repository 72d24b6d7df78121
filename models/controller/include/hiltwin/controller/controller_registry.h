#pragma once
/// Controllers by --controller SPEC (controller.h lists the kinds). Named controllers (the
/// built-in `pid`, every 20-sim controller added with hiltwin_add_20sim_controller) register a
/// factory under their name; file kinds (`lib:`, `fmu:`) register a loader under their prefix.
/// MakeController picks one and says what exists when nothing matches. Every kind runs with
/// the same board wiring when --controller-map is not given: the RELbot's (appendix G channels,
/// its wheel geometry, ports setpoint_left_m, setpoint_right_m, wheel_left_m, wheel_right_m ->
/// duty_left, duty_right), so a student's controller with those ports needs no map.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller {

/// What the command line may pass to a controller's factory. A controller refuses
/// (ControllerError) an option it has no use for, so a flag is never silently ignored.
struct ControllerOptions {
  std::string gains_path;  ///< --gains: the built-in PID's gains file ("" = built in)
  /// The RELbot parameter file (--config) whose wheel geometry the built-in maps use ("" =
  /// the built-in parameters).
  std::string config_path;
};

/// Builds a controller (not started). Throws ControllerError.
using ControllerFactory = std::function<std::unique_ptr<Controller>(const ControllerOptions&)>;
/// Builds a controller from a file (`lib:PATH`, `fmu:PATH`: the text after the prefix).
using ControllerLoader = std::function<std::unique_ptr<Controller>(const std::string& path,
                                                                   const ControllerOptions&)>;
struct ControllerEntry {
  std::string name;         ///< "pid", a 20-sim controller's name
  std::string description;  ///< one line for --help and "unknown controller" errors
  ControllerFactory make;
};

struct ControllerKind {
  std::string prefix;       ///< "lib", "fmu" (SPEC is "<prefix>:<path>")
  std::string description;  ///< one line for --help
  ControllerLoader load;
  std::string argument = "PATH";  ///< what follows "<prefix>:" in SPEC, for messages ("NAME")
};

/// Adds a named controller / a file kind; returns true so it can initialise a namespace-scope
/// constant. A second entry under the same name or prefix is a build mistake and aborts at
/// start-up with both descriptions.
bool RegisterController(ControllerEntry entry);
bool RegisterControllerKind(ControllerKind kind);

[[nodiscard]] const ControllerEntry* FindController(const std::string& name);
[[nodiscard]] std::vector<const ControllerEntry*> RegisteredControllers();  ///< sorted by name
[[nodiscard]] std::vector<const ControllerKind*> RegisteredControllerKinds();  ///< by prefix

/// The controller `spec` names: "<prefix>:<path>" for a registered kind, else a registered
/// name. Throws ControllerError naming the spec and listing what exists (names and prefixes).
[[nodiscard]] std::unique_ptr<Controller> MakeController(const std::string& spec,
                                            const ControllerOptions& options);

}  // namespace hiltwin::controller
