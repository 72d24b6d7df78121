// `hiltwin monitor`: every twin and controller on a DDS domain, live, and commands to one of
// them (docs/telemetry.md). Tasks are those started with `--telemetry dds[:DOMAIN]`; the view
// reads their rt/<ns>/timing topics, the commands go to rt/<ns>/command.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/telemetry/dds_monitor.h"

namespace hiltwin::app {
namespace {

using Clock = std::chrono::steady_clock;
using telemetry::MonitorEntry;
using Seconds = std::chrono::duration<double>;

constexpr auto kRefreshPeriod = std::chrono::milliseconds(500);
constexpr auto kPollPeriod = std::chrono::milliseconds(50);  // how soon a signal is noticed

struct MonitorOptions {
  long long domain = 0;
  double duration_s = 0.0;  // 0: until SIGINT/SIGTERM
  bool json = false;
  double wait_s = 2.0;
  std::vector<std::string> command;  // NS VERB
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

std::unique_ptr<telemetry::DdsMonitor> OpenMonitor(const MonitorOptions& o) {
  if (o.domain < 0 || o.domain > 232) {
    ThrowUsage("--domain " + std::to_string(o.domain) +
                ": DDS domain out of range; use 0..232 (the range of ROS_DOMAIN_ID), the "
                "number the tasks were given with --telemetry dds:DOMAIN");
  }
  try {
    return std::make_unique<telemetry::DdsMonitor>(static_cast<std::uint32_t>(o.domain));
  } catch (const std::exception& e) {
    ThrowUsage(std::string("--domain ") + std::to_string(o.domain) + ": " + e.what());
  }
}

std::string Fixed(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string CyclesText(const MonitorEntry& e) {
  return std::to_string(e.cycle) +
         (e.cycles_planned > 0 ? "/" + std::to_string(e.cycles_planned) : "");
}

// One row per task; the namespace column is as wide as the longest namespace.
std::string FormatTable(const std::vector<MonitorEntry>& entries) {
  std::size_t ns_width = 9;  // "NAMESPACE"
  for (const MonitorEntry& e : entries) ns_width = std::max(ns_width, e.ns.size());
  const int w = static_cast<int>(ns_width);
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-*s  %-10s  %8s  %15s  %7s  %8s  %9s  %-8s  %-9s  %6s\n", w,
                "NAMESPACE", "ROLE", "RATE_HZ", "CYCLES", "MISSES", "P99_US", "TO_VIOL", "VERDICT",
                "STATE", "AGE_S");
  out += line;
  for (const MonitorEntry& e : entries) {
    const std::string distance =
        e.distance_to_violation ? std::to_string(*e.distance_to_violation) : "-";
    std::snprintf(line, sizeof line, "%-*s  %-10s  %8s  %15s  %7llu  %8s  %9s  %-8s  %-9s  %6s%s\n",
                  w, e.ns.c_str(), e.role.c_str(), Fixed(e.rate_hz, 0).c_str(),
                  CyclesText(e).c_str(), static_cast<unsigned long long>(e.deadline_misses),
                  Fixed(e.latency_p99_us, 1).c_str(), distance.c_str(), e.verdict.c_str(),
                  e.state.c_str(), Fixed(e.age_s, 1).c_str(), e.final ? "*" : "");
    out += line;
  }
  return out;
}

nlohmann::ordered_json ToJson(const MonitorEntry& e) {
  nlohmann::ordered_json j = {
      {"ns", e.ns},
      {"role", e.role},
      {"rate_hz", e.rate_hz},
      {"time_s", e.time_s},
      {"cycle", e.cycle},
      {"cycles_planned", e.cycles_planned},
      {"deadline_misses", e.deadline_misses},
      {"latency_p99_us", e.latency_p99_us},
      {"distance_to_violation", nullptr},
      {"verdict", e.verdict},
      {"state", e.state},
      {"final", e.final},
      {"age_s", e.age_s},
  };
  if (e.distance_to_violation) j["distance_to_violation"] = *e.distance_to_violation;
  return j;
}

// Sleeps until `until`, waking every kPollPeriod; false when SIGINT/SIGTERM came first.
bool SleepUnlessStopped(Clock::time_point until) {
  while (Clock::now() < until) {
    if (kernel_glue::StopRequested()) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(kPollPeriod, until - Clock::now()));
  }
  return !kernel_glue::StopRequested();
}

int RunJson(const MonitorOptions& o) {
  const auto monitor = OpenMonitor(o);
  // Every Poll takes what arrived, so polling through the wait keeps the entries' ages right.
  const Clock::time_point until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(Seconds(o.wait_s));
  std::vector<MonitorEntry> entries = monitor->Poll();
  while (SleepUnlessStopped(std::min(until, Clock::now() + kRefreshPeriod)) &&
         Clock::now() < until) {
    entries = monitor->Poll();
  }
  entries = monitor->Poll();
  nlohmann::ordered_json tasks = nlohmann::ordered_json::array();
  for (const MonitorEntry& e : entries) tasks.push_back(ToJson(e));
  const nlohmann::ordered_json doc = {{"domain", o.domain}, {"tasks", tasks}};
  std::printf("%s\n", doc.dump(2).c_str());
  return static_cast<int>(ExitCode::kPass);
}

std::string NamespaceList(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

int RunCommand(const MonitorOptions& o) {
  const std::string& ns = o.command[0];
  const runtime::RemoteCommand command = ParseVerb(ns, o.command[1]);
  const auto monitor = OpenMonitor(o);
  const Clock::time_point until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(Seconds(o.wait_s));
  for (;;) {
    static_cast<void>(monitor->Poll());
    const std::vector<std::string> names = monitor->Namespaces();
    if (std::find(names.begin(), names.end(), ns) != names.end()) break;
    if (Clock::now() >= until) {
      ThrowUsage("--command " + ns + ": no task publishes rt/" + ns + "/timing on DDS domain " +
                  std::to_string(o.domain) + " (waited " + Fixed(o.wait_s, 1) +
                  " s); tasks there: " + NamespaceList(names) +
                  ". Check the namespace (--namespace of run/ecs), the domain (--domain), and "
                  "that both sides use the same CYCLONEDDS_URI");
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
  // The task's command reader was announced with its timing writer: a second is plenty.
  const double left_s = std::max(1.0, Seconds(until - Clock::now()).count());
  const std::string why = monitor->SendCommand(ns, command, left_s);
  if (!why.empty()) ThrowUsage("--command " + ns + " " + o.command[1] + ": " + why);
  // The acknowledgement is DDS's: the task's reader has the command. Whether the task can
  // act on it (a RESET while running, say) only the task knows; it prints that on its stderr.
  std::printf(
      "hiltwin monitor: %s delivered to rt/%s/command on DDS domain %lld (the task prints "
      "whether it took it)\n",
      runtime::ToString(command), ns.c_str(), o.domain);
  return static_cast<int>(ExitCode::kPass);
}

int RunLive(const MonitorOptions& o) {
  const auto monitor = OpenMonitor(o);
  kernel_glue::InstallStopSignalHandlers();
  const bool tty = isatty(STDOUT_FILENO) == 1;
  const Clock::time_point start = Clock::now();
  Clock::time_point next = start;
  int lines_drawn = 0;
  for (;;) {
    const std::vector<MonitorEntry> entries = monitor->Poll();
    const double elapsed_s = Seconds(Clock::now() - start).count();
    std::string frame = "hiltwin monitor: DDS domain " + std::to_string(o.domain) + ", " +
                        std::to_string(entries.size()) + " task(s), t=" + Fixed(elapsed_s, 1) +
                        " s (Ctrl-C to quit; * final record)\n";
    frame += entries.empty()
                 ? "  no task yet: start one with --telemetry dds:" + std::to_string(o.domain) +
                       " (same CYCLONEDDS_URI)\n"
                 : FormatTable(entries);
    // On a terminal the frame is redrawn in place; in a file or pipe, frames are appended.
    if (tty && lines_drawn > 0) std::printf("\033[%dA\033[J", lines_drawn);
    std::fputs(frame.c_str(), stdout);
    if (!tty) std::fputc('\n', stdout);
    std::fflush(stdout);
    lines_drawn = static_cast<int>(std::count(frame.begin(), frame.end(), '\n'));
    if (o.duration_s > 0.0 && elapsed_s >= o.duration_s) break;
    next += kRefreshPeriod;
    Clock::time_point until = next;
    if (o.duration_s > 0.0) {
      until = std::min(until,
                       start + std::chrono::duration_cast<Clock::duration>(Seconds(o.duration_s)));
    }
    if (!SleepUnlessStopped(until)) break;
  }
  return static_cast<int>(ExitCode::kPass);
}

int RunMonitor(const MonitorOptions& o) {
  if (o.wait_s <= 0.0) ThrowUsage("--wait " + Fixed(o.wait_s, 1) + ": give a positive time");
  if (o.duration_s < 0.0) {
    ThrowUsage("--duration " + Fixed(o.duration_s, 1) + ": give a positive time, or 0");
  }
  if (!o.command.empty()) return RunCommand(o);
  if (o.json) return RunJson(o);
  return RunLive(o);
}

Command AddMonitorCommand(CLI::App& parent) {
  auto o = std::make_shared<MonitorOptions>();
  CLI::App* app = parent.add_subcommand(
      "monitor", "every twin and controller on a DDS domain, live; send them commands");
  app->add_option("--domain", o->domain,
                  "DDS domain to watch: the DOMAIN of the tasks' --telemetry dds:DOMAIN (0..232)")
      ->capture_default_str();
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
  app->add_option("--command", o->command,
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
  return Command{app, [o] { return RunMonitor(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(47, AddMonitorCommand);

}  // namespace hiltwin::app
