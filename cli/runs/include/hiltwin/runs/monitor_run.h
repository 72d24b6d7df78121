#pragma once
/// `hiltwin monitor`'s runs (docs/telemetry.md): the live view of every twin and controller on
/// a DDS domain (their rt/<ns>/timing topics), the same as one JSON document, or one command
/// sent to one of them (rt/<ns>/command). The command (cli/commands/cmd_monitor.cpp) parses its
/// flags, once, into MonitorRunOptions.

#include <optional>
#include <string>

#include "hiltwin/runtime/telemetry.h"

namespace hiltwin::app {

/// A command for the task publishing under one namespace.
struct MonitorCommand {
  std::string ns;  ///< the task's namespace: the command goes to rt/<ns>/command
  runtime::RemoteCommand command{};
  std::string verb;  ///< the command as the user typed it, for messages
};

struct MonitorRunOptions {
  long long domain = 0;     ///< DDS domain, 0..232 (checked when the monitor joins it)
  double duration_s = 0.0;  ///< live view: stop after this long; 0: until SIGINT/SIGTERM
  bool json = false;        ///< collect for wait_s, print one JSON document, exit
  double wait_s = 2.0;      ///< json: how long to collect; command: how long to wait for the task
  std::optional<MonitorCommand> command;  ///< set: send it and exit (no view)
};

/// Refuses (exit 2) a wait_s that is not positive and a negative duration_s, naming --wait and
/// --duration. The command calls it before it reads --command's verb, so a command line with
/// several mistakes is told the same one first as it always was; RunMonitor calls it again.
void CheckMonitorTimes(const MonitorRunOptions& o);

/// Sends o.command, or prints the JSON document (o.json), or shows the live view. Returns 0;
/// throws CommandError (exit 2) for bad options, a domain DDS refuses, an unknown namespace or
/// a command nobody acknowledged.
int RunMonitor(const MonitorRunOptions& o);

}  // namespace hiltwin::app
