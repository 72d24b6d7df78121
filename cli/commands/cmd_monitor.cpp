// `hiltwin monitor`: every twin and controller on a DDS domain, live, and commands to one of
// them (docs/telemetry.md). Tasks are those started with `--telemetry dds[:DOMAIN]`; the view
// reads their rt/<ns>/timing topics, the commands go to rt/<ns>/command.
// Flags -> MonitorRunOptions (typed, read once) -> RunMonitor (hiltwin/runs/monitor_run.h).
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "hiltwin/runs/monitor_run.h"
#include "hiltwin/runtime/telemetry.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::app {
namespace {

struct MonitorFlags {
  MonitorRunOptions run;                ///< every flag but --command, typed by CLI11
  std::vector<std::string> command;     // NS VERB
  const CLI::Option* domain = nullptr;  // --domain; not given: ROS_DOMAIN_ID, as ROS 2 tools
};

runtime::RemoteCommand ParseVerb(const std::string& ns, const std::string& text) {
  std::string verb = text;  // the codes' names are upper case; users type either
  std::transform(verb.begin(), verb.end(), verb.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (std::int32_t code = 1; code <= 6; ++code) {
    const auto command = runtime::RemoteCommandOf(code);
    if (command && verb == runtime::ToString(*command)) return *command;
  }
  ThrowUsage("--command " + ns + " " + text +
              ": unknown command; use one of stop, pause, start, quit, reset, initialise");
}

// --wait and --duration are checked before the verb is read, the order they always had.
MonitorRunOptions MonitorRunOptionsOf(const MonitorFlags& flags) {
  MonitorRunOptions run = flags.run;
  CheckMonitorTimes(run);
  if (flags.domain->count() == 0) {
    try {
      run.domain = telemetry::DefaultDdsDomain("--domain N");
    } catch (const std::invalid_argument& e) {
      ThrowUsage(e.what());
    }
  }
  if (!flags.command.empty()) {
    const std::string& ns = flags.command[0];
    run.command = MonitorCommand{ns, ParseVerb(ns, flags.command[1]), flags.command[1]};
  }
  return run;
}

Command AddMonitorCommand(CLI::App& parent) {
  auto flags = std::make_shared<MonitorFlags>();
  MonitorRunOptions* o = &flags->run;
  CLI::App* app = parent.add_subcommand(
      "monitor", "Watch every twin and controller on a DDS domain, live; send them commands.");
  flags->domain = app->add_option(
      "--domain", o->domain,
      "DDS domain to watch: the DOMAIN of the tasks' --telemetry dds:DOMAIN (0..232; default "
      "ROS_DOMAIN_ID, else 0)");
  app->add_option("--duration", o->duration_s,
                  "live view: stop after S seconds (default: until Ctrl-C or SIGTERM)");
  auto* json = app->add_flag("--json", o->json,
                             "collect for --wait seconds, print {\"domain\": N, \"tasks\": "
                             "[{ns, role, rate_hz, time_s, cycle, cycles_planned, "
                             "deadline_misses, latency_p99_us, distance_to_violation, verdict, "
                             "state, final, age_s}]} and exit");
  app->add_option("--wait", o->wait_s,
                  "--json: how long to collect; --command: how long to wait for the task")
      ->capture_default_str();
  app->add_option("--command", flags->command,
                  "NS VERB: send VERB (stop, pause, start, quit, reset, initialise) to the task "
                  "publishing under namespace NS, e.g. --command bench1/twin stop")
      ->expected(2)
      ->excludes(json);
  app->footer(
      "Finds every task started with --telemetry dds[:DOMAIN] (hiltwin run, ecs, hil) on the\n"
      "domain through DDS discovery, as `ros2 topic list` does, and shows per task: namespace,\n"
      "role, rate, cycles run (of planned), deadline misses, p99 wake-up latency over the last\n"
      "second, consecutive misses left before a QoS rule is violated (TO_VIOL; - when no rule\n"
      "can fail), verdict so far, lifecycle state, and seconds since its last record (AGE_S;\n"
      "* marks a task's final record). Refreshed every 0.5 s: redrawn in place on a terminal,\n"
      "appended otherwise.\n"
      "Commands go to rt/NS/command (std_msgs/Int32, the seed ECS codes: INITIALISE 1, START 2,\n"
      "STOP 3, RESET 4, PAUSE 5, QUIT 6). Exit 0 means the task's reader acknowledged it; the\n"
      "task prints on its stderr whether it took it (a running task refuses RESET).\n"
      "Discovery uses Cyclone DDS's configuration (CYCLONEDDS_URI) on both sides; on one\n"
      "machine without multicast use config/cyclonedds-loopback.xml.\n"
      "Exit: 0 done (a command delivered); 2 bad usage, an unknown namespace or a\n"
      "command nobody acknowledged; 1 internal error.");
  return Command{app, [flags] { return RunMonitor(MonitorRunOptionsOf(*flags)); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(47, AddMonitorCommand);

}  // namespace hiltwin::app
