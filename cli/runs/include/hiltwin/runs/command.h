#pragma once
/// The `hiltwin` command line: exit codes (docs/architecture.md, "Exit codes") and the shape
/// every subcommand takes. Each subcommand lives in its own cli/commands/cmd_<name>.cpp.

#include <CLI/CLI.hpp>
#include <functional>
#include <stdexcept>
#include <string>

#include "hiltwin/runtime/exit_code.h"

namespace hiltwin::app {

/// Process exit codes (docs/architecture.md, "Exit codes"), shared with the run assembly.
using ExitCode = runtime::ExitCode;

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

/// Ends a command with ExitCode::kUsage (exit 2): a bad flag, argument or input file, named by
/// `message`. One definition for every command and run assembly.
[[noreturn]] inline void ThrowUsage(const std::string& message) {
  throw CommandError(ExitCode::kUsage, message);
}

/// A registered subcommand: its CLI11 node and what to run when it was chosen.
/// `run` returns the process exit code.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

}  // namespace hiltwin::app
