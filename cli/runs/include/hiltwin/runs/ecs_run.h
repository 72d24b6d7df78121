#pragma once
/// `hiltwin ecs`'s run: the RELbot's controller built from its configuration (gains, profiles,
/// RELbot parameters), its board opened and checked, the session run and its outcome printed.
/// The command (cli/commands/cmd_ecs.cpp) parses its flags, once, into EcsRunOptions.

#include <string>

#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/session_settings.h"

namespace hiltwin::app {

/// `ecs`'s typed configuration.
struct EcsRunOptions {
  SessionSettings session;
  bool duration_given = false;  ///< false: the run lasts as long as its profile
  /// What the controller does: follow setpoints with its PIDs, or play a duty profile.
  EcsMode mode = EcsMode::kClosedLoop;
  std::string setpoint;  ///< closed loop: a built-in profile's name or a CSV file
  std::string input;     ///< open loop: a built-in profile's name or a CSV file
  /// Closed loop: the controller (--controller SPEC, controller_registry.h) and its map
  /// (--controller-map; "": the RELbot's, RelbotControllerMap).
  std::string controller = "pid";
  std::string controller_map_path;
  std::string gains_path;  ///< the built-in PID's only
  std::string config_path;
};

/// How the controller's runs name themselves; its default (m,k) rule is judged at its own rate.
SessionRole EcsRole(double rate_hz);

/// Loads the gains and profiles (exit 2 with file:line), opens the link and checks the board's
/// identity (exit 5), runs the controller and prints its outcome; returns the run's exit code
/// (0 PASS, 3 FLAGGED, 4 ABORTED, 5 I/O fault).
int RunEcs(const EcsRunOptions& options);

}  // namespace hiltwin::app
