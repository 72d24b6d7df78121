#pragma once
/// Process exit codes of every hiltwin command (docs/architecture.md, "Exit codes"); users' scripts
/// and CI rely on these numbers.

namespace hiltwin::runtime {

enum class ExitCode : int {
  kPass = 0,      ///< success / QoS PASS
  kInternal = 1,  ///< a bug or an unexpected failure inside hiltwin (also: a diverged model)
  kUsage = 2,     ///< bad flag, configuration or input file
  kFlagged = 3,   ///< run completed but QoS FLAGGED (results unreliable)
  kAborted = 4,   ///< run ABORTED by the QoS policy
  kIo = 5,  ///< hardware / I/O error (e.g. the wrong FPGA image, a log that could not be written)
  /// Stopped on request before any cycle was judged (no verdict): 128 + the signal, the code a
  /// shell reports for a command that signal ended (130 SIGINT, 143 SIGTERM, 129 SIGHUP).
  kStoppedBySignal = 128,
};

/// kStoppedBySignal + `signal_number`.
[[nodiscard]] constexpr ExitCode StoppedBy(int signal_number) noexcept {
  return static_cast<ExitCode>(static_cast<int>(ExitCode::kStoppedBySignal) + signal_number);
}

}  // namespace hiltwin::runtime
