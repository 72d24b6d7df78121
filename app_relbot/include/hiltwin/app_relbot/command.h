#pragma once
/// The `hiltwin` command line: exit codes (DESIGN.md "Contracts") and the shape every
/// subcommand takes. Each subcommand lives in its own app_relbot/src/cmd_<name>.cpp.

#include <CLI/CLI.hpp>
#include <functional>
#include <stdexcept>
#include <string>

namespace hiltwin::app {

/// Process exit codes; users' scripts and CI rely on these numbers.
enum class ExitCode : int {
  kPass = 0,      ///< success / QoS PASS
  kInternal = 1,  ///< a bug or an unexpected failure inside hiltwin
  kUsage = 2,     ///< bad flag, configuration or input file
  kFlagged = 3,   ///< run completed but QoS FLAGGED (results unreliable)
  kAborted = 4,   ///< run ABORTED by the QoS policy
  kIo = 5,        ///< hardware / I/O error (e.g. the wrong FPGA image)
};

/// Ends a command with `code` and a message that says what, where and what to do.
/// Thrown only outside the real-time loop (configuration, start-up, reporting).
class CommandError : public std::runtime_error {
 public:
  CommandError(ExitCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  [[nodiscard]] ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// A registered subcommand: its CLI11 node and what to run when it was chosen.
/// `run` returns the process exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

}  // namespace hiltwin::app
