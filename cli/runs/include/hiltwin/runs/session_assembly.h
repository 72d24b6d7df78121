#pragma once
/// The session assembly every command that runs a session shares (`run` for the twin, `ecs` for
/// the controller, `tune`'s runs): typed SessionSettings -> the board -> runtime::SessionConfig
/// -> the run -> report. One definition, so the two sides of a HiL pair run with the same meaning
/// and the same checks; the flags themselves are read once, in cli/session_flags.h.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/output_files.h"
#include "hiltwin/runs/session_settings.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {

/// What the command that runs the session is, for messages and help texts.
struct SessionRole {
  const char* command;            ///< "run" or "ecs"
  const char* peer_name;          ///< who is on the other side: "controller" or "twin"
  const char* peer_command;       ///< how the other side starts: "hiltwin ecs" or "hiltwin run"
  double other_rate_hz;           ///< the other side's rate, for the default (m,k) rule
  const char* default_namespace;  ///< telemetry namespace without --namespace: "twin", ...
};

/// The planned cycles of --duration at --rate (at least 1; checked against --grace-cycles).
[[nodiscard]] std::uint64_t PlannedCycles(const SessionSettings& s);

/// How to open the board for this side: the side's image and, for fault injection, the image
/// its emulated board carries instead (--board-image).
[[nodiscard]] io::BackendOptions BackendOptionsFor(const SessionSettings& s, io::Image side);

/// Opens --io as `side` (exit 2 for an option the backend refuses, 5 when the OS refuses it).
[[nodiscard]] std::unique_ptr<io::IoBackend> OpenBoard(const SessionSettings& s, io::Image side);

/// The session configuration of the shared settings: clock, executive, QoS (its rules checked
/// against the run's length), RT set-up, injection, log, progress, pause signals, telemetry (its
/// sinks opened now: a port in use is exit 2 before the run starts) and, on a wire, the wait for
/// the peer. The command adds its task's name, details and on_ready.
[[nodiscard]] runtime::SessionConfig MakeSessionConfig(const SessionSettings& s,
                                                       const SessionRole& role,
                                                       io::IoBackend& backend);

/// INIT and the identity check of this side's board; exit 5 with the thesis's message
/// ("Failed to initialise FPGA: ...", fig. 4.2) when the board carries the wrong image.
void InitBoard(io::IcoBoardLink& driver, kernel_glue::TimeNs period_ns);

/// Builds the session (a bad configuration, or a log that cannot be created: exit 2) and runs
/// it to its end.
[[nodiscard]] runtime::RunReport RunSessionOf(runtime::SessionConfig config,
                                              runtime::RunTask& task);

/// Prints the summary on stdout and the problems on stderr, prefixed with "hiltwin <command>: ",
/// then writes `json` to the report. Returns the run's exit code (runtime::ExitCodeFor), made
/// at least as bad as 5 when the report could not be written (said on stderr, as a log's).
[[nodiscard]] int PrintOutcome(const SessionRole& role, const runtime::RunReport& report,
                               const nlohmann::ordered_json& json,
                               const std::string& extra_summary, ReportFile& report_file);

/// Each warning on stderr as "hiltwin <command>: warning: ...", at the start of a run (the
/// report keeps them: SessionConfig::warnings).
void PrintWarnings(const char* command, const std::vector<std::string>& warnings);

/// A number as a person writes it (4000, 0.25), for messages.
[[nodiscard]] std::string Num(double value);
/// A number in the shortest text that reads back as the same double (to_chars): for what is
/// read again, a child's command line, a parameter file, a report's exact gains.
[[nodiscard]] std::string ExactNum(double value);

}  // namespace hiltwin::app
