#pragma once
/// The session assembly every command that runs a session shares (`run` for the twin, `ecs` for
/// the controller, `tune`'s runs): typed SessionSettings -> the board -> runtime::SessionConfig
/// -> the run -> report. One definition, so the two sides of a HiL pair run with the same meaning
/// and the same checks; the flags themselves are read once, in cli/session_flags.h.

#include <cstdint>
#include <memory>
#include <string>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/runs/command.h"
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

/// The --report file. Created before the run (kernel_glue::OpenOutputFile: a link or a missing
/// folder is exit 2), so a path that cannot be written fails first, not after the run; written
/// once, at the end, through the descriptor that created it. A report that was never written
/// (the command failed before or during its run, e.g. the wrong FPGA image at INIT) is removed
/// again: an empty file would read as a run that said nothing.
class ReportFile {
 public:
  ReportFile() = default;  ///< no --report
  explicit ReportFile(std::string path);
  ~ReportFile();
  ReportFile(ReportFile&& other) noexcept;
  ReportFile& operator=(ReportFile&&) = delete;
  ReportFile(const ReportFile&) = delete;
  ReportFile& operator=(const ReportFile&) = delete;

  /// A report was asked for.
  [[nodiscard]] bool wanted() const noexcept { return fd_ >= 0; }
  /// Writes `text` and closes the file; CommandError (exit 5) naming the path when it cannot.
  void Write(const std::string& text);

 private:
  std::string path_;
  int fd_ = -1;
};

/// Writes `json` to the report (exit 5 when it cannot), prints the summary on stdout and the
/// problems on stderr, prefixed with "hiltwin <command>: ".
void PrintOutcome(const SessionRole& role,
                  const runtime::RunReport& report, const nlohmann::ordered_json& json,
                  const std::string& extra_summary, ReportFile& report_file);

/// A number as a person writes it (4000, 0.25), for messages.
[[nodiscard]] std::string Num(double value);

}  // namespace hiltwin::app
