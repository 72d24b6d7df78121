#pragma once
/// The flags every command that runs a session shares (`run` for the twin, `ecs` for the
/// controller): rate, duration, QoS rules, clock, overrun policy, deadline, log, report, fault
/// injection, real-time set-up, progress and the wait for a wire peer. One definition, so the
/// two sides of a HiL pair take the same flags with the same meaning and the same checks, and
/// each command stays thin: flags -> SessionOptions -> runtime::SessionConfig -> report.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/runs/command.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runtime/run_report.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::app {

struct SessionOptions {
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
  std::string timing_log_path;  ///< every cycle's time stamps, for `hiltwin trace --analyze`
  std::string report_path;
  std::vector<std::string> inject_overrun;
  int priority = 80;
  std::vector<int> cpus;
  bool no_progress = false;
  double wait_peer_s = 30.0;
  std::string board_image;  ///< fault injection: the image the emulated board carries
  /// --telemetry, --namespace (empty: the role's default), --web, --telemetry-rate.
  telemetry::TelemetryOptions telemetry;
};

/// What the command that uses the options is, for messages and help texts.
struct SessionRole {
  const char* command;            ///< "run" or "ecs"
  const char* peer_name;          ///< who is on the other side: "controller" or "twin"
  const char* peer_command;       ///< how the other side starts: "hiltwin ecs" or "hiltwin run"
  double other_rate_hz;           ///< the other side's rate, for the default (m,k) rule
  const char* default_namespace;  ///< telemetry namespace without --namespace: "twin", ...
};

/// Adds the shared flags (with their help texts) to `app`. `--rate` and `--duration` take
/// their defaults from `o` as it is when called.
void AddSessionOptions(CLI::App& app, SessionOptions& o);

/// Adds --telemetry, --namespace, --web and --telemetry-rate (part of AddSessionOptions; `hil`
/// adds them alone and passes them on to its two processes).
void AddTelemetryOptions(CLI::App& app, telemetry::TelemetryOptions& t);

/// Checks the shared flags; throws CommandError(kUsage) naming the flag and the fix.
void ValidateSessionOptions(const SessionOptions& o);

/// The planned cycles of --duration at --rate (at least 1; checked against --grace-cycles).
[[nodiscard]] std::uint64_t PlannedCycles(const SessionOptions& o);

/// How to open the board for this side: the side's image and, for fault injection, the image
/// its emulated board carries instead (--board-image).
[[nodiscard]] io::BackendOptions BackendOptionsFor(const SessionOptions& o, io::Image side);

/// Opens --io as `side` (exit 2 for a bad spec, 5 when the OS refuses it).
[[nodiscard]] std::unique_ptr<io::IoBackend> OpenBoard(const SessionOptions& o, io::Image side);

/// The session configuration of the shared flags: clock, executive, QoS (the documented
/// default (m,k) rule for this rate pair unless --qos is given), RT set-up, injection, log,
/// progress, pause signals, telemetry (its sinks opened now: a port in use is exit 2 before the
/// board is touched) and, on a wire, the wait for the peer. The command adds its task's name,
/// details and on_ready.
[[nodiscard]] runtime::SessionConfig MakeSessionConfig(const SessionOptions& o,
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
