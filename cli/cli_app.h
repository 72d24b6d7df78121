#pragma once
// The `hiltwin` command line as an object: every registered subcommand added to one CLI11 app,
// so main.cpp and the command-line fuzz target (fuzz/cli_fuzz.cpp) parse argv the same way.

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"

namespace hiltwin::app {

/// The parsed-into state of one command line. Not movable: the commands' options point into it.
struct CliApp {
  CliApp();
  CliApp(const CliApp&) = delete;
  CliApp& operator=(const CliApp&) = delete;
  CLI::App app;
  std::string log_level = "info";  ///< --log-level; applied to spdlog once parsing completes
  std::vector<Command> commands;   ///< in `hiltwin --help` order
};

/// Builds the app with every registered subcommand (spdlog's default logger is main's job).
[[nodiscard]] std::unique_ptr<CliApp> BuildCliApp();

}  // namespace hiltwin::app
