#pragma once
/// `hiltwin run` as a function: the RELbot twin's flags, built into a task and run through the
/// shared session assembly, with the run's summary, report and exit code. `hiltwin trace` runs
/// exactly this inside its recording, so a traced run and a plain one cannot differ.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "hiltwin/runs/session_options.h"
#include "hiltwin/runtime/run_report.h"

namespace hiltwin::app {

/// `run`'s own flags beside the shared ones.
struct TwinRunOptions {
  SessionOptions session;
  std::string input = "openloop";
  double controller_rate_hz = 0.0;  ///< 0: min(1000 Hz, --rate), the thesis ECS rate
  std::string plant = "relbot";   ///< --plant: a registered name or fmu:PATH.fmu
  std::string plant_map_path;     ///< --plant-map ("" = the plant's own map)
  std::string config_path;
  std::string integrator;  ///< "" = the plant's default (the RELbot's is rk4)
  std::vector<std::string> inject_link_faults;  ///< --inject-link-fault SPECs (mock and wire)
};

/// Adds every `run` flag (shared and own) to `app`.
void AddTwinRunOptions(CLI::App& app, TwinRunOptions& o);

/// The flag checks RunTwin starts with, for a caller that must know before it starts anything.
void CheckTwinRunOptions(const TwinRunOptions& o);

/// What a twin run ended with.
struct TwinRunOutcome {
  runtime::RunReport report;
  int exit_code = 0;
};

/// Checks the flags, builds the twin, runs it and prints its outcome exactly as `hiltwin run`
/// does (stdout summary, stderr problems, --report file). Throws CommandError for bad flags
/// (exit 2) and an unusable board (exit 5) before the run. `command` names it in messages.
TwinRunOutcome RunTwin(TwinRunOptions o, const char* command = "run");

}  // namespace hiltwin::app
