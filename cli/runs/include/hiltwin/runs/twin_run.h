#pragma once
/// `hiltwin run` as a function: the twin's typed options, built into a task and run through the
/// shared session assembly, with the run's summary, report and exit code. `hiltwin trace` runs
/// exactly this inside its recording, so a traced run and a plain one cannot differ.

#include <string>
#include <vector>

#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/session_settings.h"
#include "hiltwin/runtime/run_report.h"

namespace hiltwin::app {

/// `run`'s typed configuration (its flags parsed by cli/session_flags.h, or set by `tune`).
struct TwinRunOptions {
  SessionSettings session;
  std::string input = "openloop";  ///< --input: a built-in profile's name or a CSV file
  double controller_rate_hz = 1000.0;  ///< the rate --input is played at (the ECS's)
  std::string plant = "relbot";        ///< --plant: a registered name or fmu:PATH.fmu
  std::string plant_map_path;          ///< --plant-map ("" = the plant's own map)
  std::string config_path;
  /// --integrator ("" = the plant's default, the RELbot's rk4), as given: the plant reads it
  /// (plant::PlantOptions), and a plant without integrators refuses it in its own words.
  std::string integrator;
  std::vector<io::LinkFaultInjection> link_faults;  ///< --inject-link-fault (mock and wire)
  /// --show-setpoint: a setpoint profile (as `ecs --setpoint`) sent with the telemetry, for
  /// the page to draw beside the robot; "" for none. `hil` passes its controller's.
  std::string show_setpoint;
};

/// How the twin's runs name themselves in messages: `command` ("run", "trace", "tune") against
/// a controller at `controller_rate_hz`.
[[nodiscard]] SessionRole TwinRole(const char* command, double controller_rate_hz);

/// The numbers' checks RunTwin starts with: the session's, then the controller rate's.
void ValidateTwinRunNumbers(const TwinRunOptions& o);

/// Every check RunTwin starts with (the numbers; the link faults against the board and the
/// run's length), for a caller that must know before it starts anything.
void CheckTwinRunOptions(const TwinRunOptions& o);

/// What a twin run ended with.
struct TwinRunOutcome {
  runtime::RunReport report;
  int exit_code = 0;
};

/// Checks the options, builds the twin, runs it and prints its outcome exactly as `hiltwin run`
/// does (stdout summary, stderr problems, --report file). Throws CommandError for bad options
/// (exit 2) and an unusable board (exit 5) before the run. `command` names it in messages.
TwinRunOutcome RunTwin(const TwinRunOptions& o, const char* command = "run");

}  // namespace hiltwin::app
