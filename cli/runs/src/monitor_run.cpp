#include "hiltwin/runs/monitor_run.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/telemetry/dds_monitor.h"

namespace hiltwin::app {
namespace {

using Clock = std::chrono::steady_clock;
using telemetry::MonitorEntry;
using Seconds = std::chrono::duration<double>;

constexpr auto kRefreshPeriod = std::chrono::milliseconds(500);
constexpr auto kPollPeriod = std::chrono::milliseconds(50);  // how soon a signal is noticed

std::unique_ptr<telemetry::DdsMonitor> OpenMonitor(const MonitorRunOptions& o) {
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

int RunJson(const MonitorRunOptions& o) {
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

int RunCommand(const MonitorRunOptions& o, const MonitorCommand& request) {
  const std::string& ns = request.ns;
  const runtime::RemoteCommand command = request.command;
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
  if (!why.empty()) ThrowUsage("--command " + ns + " " + request.verb + ": " + why);
  // The acknowledgement is DDS's: the task's reader has the command. Whether the task can
  // act on it (a RESET while running, say) only the task knows; it prints that on its stderr.
  std::printf(
      "hiltwin monitor: %s delivered to rt/%s/command on DDS domain %lld (the task prints "
      "whether it took it)\n",
      runtime::ToString(command), ns.c_str(), o.domain);
  return static_cast<int>(ExitCode::kPass);
}

int RunLive(const MonitorRunOptions& o) {
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

}  // namespace

void CheckMonitorTimes(const MonitorRunOptions& o) {
  if (o.wait_s <= 0.0) ThrowUsage("--wait " + Fixed(o.wait_s, 1) + ": give a positive time");
  if (o.duration_s < 0.0) {
    ThrowUsage("--duration " + Fixed(o.duration_s, 1) + ": give a positive time, or 0");
  }
}

int RunMonitor(const MonitorRunOptions& o) {
  CheckMonitorTimes(o);
  if (o.command) return RunCommand(o, *o.command);
  if (o.json) return RunJson(o);
  return RunLive(o);
}

}  // namespace hiltwin::app
