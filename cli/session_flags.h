#pragma once
/// The flags every command that runs a session shares (`run` for the twin, `ecs` for the
/// controller; `trace` runs `run`'s): rate, duration, QoS rules, clock, overrun policy, deadline,
/// log, report, fault injection, real-time set-up, progress and the wait for a wire peer. One
/// definition, so the two sides of a HiL pair take the same flags with the same meaning, and the
/// one place their text is read: flags -> SessionFlags (as CLI11 binds them) -> SessionSettings
/// (typed, hiltwin/runs/session_settings.h), once, before anything runs.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runs/output_files.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/session_settings.h"
#include "hiltwin/runs/twin_run.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::app {

/// The shared flags as the command line gave them.
struct SessionFlags {
  double rate_hz = 4000.0;
  double duration_s = 10.0;
  std::string io = "mock";
  std::vector<std::string> mk_rules;
  std::vector<std::string> window_rules;
  std::optional<std::uint32_t> max_consecutive_misses;
  double max_miss_pct = 1.0;
  std::uint64_t grace_cycles = 0;
  std::string on_violation = "flag";
  std::string clock = "realtime";
  std::string overrun_policy = "catch-up";
  double deadline_us = 0.0;
  std::string log_path;
  std::uint32_t log_decimation = 1;
  std::string timing_log_path;
  std::string report_path;
  std::vector<std::string> inject_overrun;
  int priority = 80;
  std::vector<int> cpus;
  bool no_progress = false;
  double wait_peer_s = kDefaultWaitPeerS;
  std::string board_image;
  telemetry::TelemetryOptions telemetry;
};

/// Adds the shared flags (with their help texts) to `app`. `--rate` and `--duration` take
/// their defaults from `f` as it is when called.
void AddSessionFlags(CLI::App& app, SessionFlags& f);

/// Adds --telemetry, --namespace, --web and --telemetry-rate (part of AddSessionFlags; `hil`
/// adds them alone and passes them on to its two processes).
void AddTelemetryFlags(CLI::App& app, telemetry::TelemetryOptions& t);

/// The typed settings of the shared flags: SessionNumbersOf, checked (ValidateSessionSettings),
/// then ParseSessionTexts. Throws CommandError(kUsage) naming the flag, as the run would have.
[[nodiscard]] SessionSettings SessionSettingsFrom(const SessionFlags& f, const SessionRole& role);

/// The numbers, paths, CPUs and telemetry flags as given (not yet checked); the parsed fields
/// keep their defaults. For a command that checks its own numbers before ParseSessionTexts.
[[nodiscard]] SessionSettings SessionNumbersOf(const SessionFlags& f);

/// Parses every text of the shared flags into `s`, whose numbers must be checked: --io,
/// --board-image, --clock, --overrun-policy, --on-violation, the QoS rules (the documented
/// default (m,k) rule for role's rate pair unless --qos is given) and --inject-overrun.
void ParseSessionTexts(const SessionFlags& f, const SessionRole& role, SessionSettings& s);

/// The shared flags' output files (--log, --timing-log, --report), for CheckFilesDistinct
/// beside the command's own inputs and outputs.
[[nodiscard]] std::vector<NamedFile> SessionOutputFiles(const SessionFlags& f);

/// "realtime" or "virtual" (--clock, checked by CLI11 to be one of them).
[[nodiscard]] runtime::ClockKind ClockKindOf(const std::string& text);

/// `run`'s own flags beside the shared ones (`trace` takes them too).
struct TwinRunFlags {
  SessionFlags session;
  std::string input = "openloop";
  /// --input-rate; not given: min(1000 Hz, --rate), the thesis ECS rate
  std::optional<double> input_rate_hz;
  std::string plant = "relbot";
  std::string plant_map_path;
  std::string config_path;
  std::string integrator;
  std::vector<std::string> inject_link_faults;
  std::string show_setpoint;
};

/// Adds every `run` flag (shared and own) to `app`.
void AddTwinRunFlags(CLI::App& app, TwinRunFlags& f);

/// The typed options of `run`'s flags: the controller rate resolved, the session's settings
/// (SessionSettingsFrom), --inject-link-fault parsed, and no output naming an input or another
/// output (CheckFilesDistinct over the run's files and the command's `more_files`, e.g. what
/// `trace` writes). `command` ("run", "trace") names the command in messages.
[[nodiscard]] TwinRunOptions TwinRunOptionsFrom(const TwinRunFlags& f, const char* command,
                                                const std::vector<NamedFile>& more_files = {});

}  // namespace hiltwin::app
