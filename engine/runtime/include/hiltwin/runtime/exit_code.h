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
};

}  // namespace hiltwin::runtime
