#pragma once
/// `hiltwin hil`'s run: the twin (`hiltwin run`) and the controller (`hiltwin ecs`) started as
/// two processes on one wire, waited for, and their reports combined (hil_report.h). The
/// command (cli/commands/cmd_hil.cpp) parses its flags, once, into HilRunOptions.

#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runs/output_files.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::app {

/// hil's configuration, checked. The rules, profiles, files and extra arguments are passed on
/// as given to the two sides, which parse them (a mistake there is that side's exit 2).
struct HilRunOptions {
  double twin_rate_hz = 4000.0;  ///< checked (scheduler::ValidateRateHz)
  double ecs_rate_hz = 1000.0;   ///< checked (scheduler::ValidateRateHz)
  double duration_s = 0.0;       ///< the controller's run length; 0 only before the parse
  std::string mode = "closedloop";  ///< closedloop or openloop
  std::string setpoint = "closedloop";
  std::string input = "openloop";
  std::string controller;           ///< --controller for the ECS ("": its default, pid)
  std::string controller_map_path;  ///< --controller-map for the ECS ("": the RELbot's)
  std::string gains_path;
  std::string config_path;
  std::vector<std::string> twin_qos, ecs_qos;
  std::optional<double> twin_max_miss_pct, ecs_max_miss_pct;
  std::optional<std::string> on_violation;  ///< for both sides; each side's default when unset
  std::vector<std::string> twin_args, ecs_args;
  std::string report_path;
  std::string log_dir;
  std::string wire;  ///< the wire's name (wire:NAME), checked; hil-<pid> without --wire
  double wait_peer_s = 10.0;
  std::string clock = "realtime";  ///< realtime, or virtual: both sides in lockstep (checked)
  bool no_progress = false;
  /// Passed on: each side publishes under NS/twin and NS/controller; the twin serves --web.
  /// Checked.
  telemetry::TelemetryOptions telemetry;
};

/// Every file hil reads and writes, for CheckFilesDistinct: the profiles (unless built in),
/// --controller-map, --gains, --config, --report and, with --log-dir, each side's report, log
/// and output there.
[[nodiscard]] std::vector<NamedFile> HilFiles(const HilRunOptions& o);

/// Starts both sides, waits for them (a stop signal is passed on), prints the combined summary
/// and writes the combined report; returns the worse of the two sides' exit codes. Throws
/// CommandError: exit 2 for a --log-dir or --report that cannot be made, 5 for a temporary
/// folder that cannot be.
int RunHil(const HilRunOptions& o);

}  // namespace hiltwin::app
