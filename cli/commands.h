#pragma once
/// Registry of `hiltwin` subcommands. Each cli/commands/cmd_<name>.cpp registers itself with
/// HILTWIN_REGISTER_COMMAND, so adding a command touches no shared file. The cli/ sources are
/// compiled straight into the executable, so the linker never drops a registration.

#include <vector>

#include "hiltwin/runs/command.h"

namespace hiltwin::app {

/// Adds one subcommand (with its own --help) to `parent` and returns how to run it.
using CommandFactory = Command (*)(CLI::App& parent);

struct CommandEntry {
  int order;  ///< position in `hiltwin --help` (docs/architecture.md's table of commands)
  CommandFactory factory;
};

/// All registered commands, in registration order (sort by `order` before use).
std::vector<CommandEntry>& CommandRegistry();

/// Registers a command at static-initialisation time; returns true so it can seed a constant.
bool RegisterCommand(int order, CommandFactory factory);

}  // namespace hiltwin::app

#define HILTWIN_REGISTER_COMMAND(order, factory)             \
  [[maybe_unused]] static const bool kRegistered_##factory = \
      ::hiltwin::app::RegisterCommand(order, &factory)
