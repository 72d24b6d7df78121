// `hiltwin run` as a function (twin_run.h): typed options -> twin -> the shared session
// assembly -> the run's outcome. cli/commands/cmd_run.cpp and trace_run.cpp both call it.
#include "hiltwin/runs/twin_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/relbot/encoder_reading.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "hiltwin/relbot/setpoint_display_task.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runtime/link_faulting_task.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

void PrintStartLines(const char* command, const SessionSettings& s, std::uint64_t planned,
                     const std::string& plant, const std::string& input,
                     const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(
      stdout,
      "hiltwin %s: %s twin at %.0f Hz for %.3f s (%llu cycles), io %s, input %s, %s clock\n",
      command, plant.c_str(), s.rate_hz, s.duration_s, static_cast<unsigned long long>(planned),
      s.io_text.c_str(), input.c_str(), runtime::ToString(s.clock));
  if (rt != nullptr)
    std::fprintf(stdout, "real-time set-up: %s\n", kernel_glue::Summary(*rt).c_str());
  std::fflush(stdout);
}

/// How the start line and the report name the task: "RELbot" for the built-in plant (as
/// before plants were pluggable), "plant NAME" otherwise.
std::string TaskNameOf(const plant::PlantInfo& info) {
  return info.name == kRelbotPlantName ? std::string("RELbot") : "plant " + info.name;
}

/// The report's facts about the plant: which, what kind, wired by which map, and its own.
std::vector<std::pair<std::string, std::string>> PlantDetails(const Twin& twin) {
  const plant::PlantInfo& info = twin.plant->Info();
  std::vector<std::pair<std::string, std::string>> details = {
      {"input", twin.input_name},
      {"plant", info.name},
      {"plant kind", info.kind},
      {"plant map", twin.map_source}};
  details.insert(details.end(), info.details.begin(), info.details.end());
  return details;
}

/// --inject-link-fault's faults, checked against the board and the run's length (exit 2).
io::LinkFaultSchedule LinkFaultsOf(const TwinRunOptions& o) {
  io::LinkFaultSchedule schedule;
  if (o.link_faults.empty()) return schedule;
  const io::BackendSpec::Kind kind = o.session.io.kind;
  if (kind != io::BackendSpec::Kind::kMock && kind != io::BackendSpec::Kind::kWire) {
    ThrowUsage("--inject-link-fault needs an emulated board (--io mock or wire:NAME), not --io " +
               o.session.io_text);
  }
  try {
    for (const io::LinkFaultInjection& fault : o.link_faults) schedule.Add(fault);
    schedule.CheckFiresWithin(PlannedCycles(o.session));
  } catch (const std::exception& e) {
    ThrowUsage(std::string("--inject-link-fault ") + e.what());
  }
  return schedule;
}

/// Whether the controller behind the board reads the encoders often enough: over a wire its
/// readers decode the emulated lines (both limits); on a real board only the count's wrap
/// applies; on the mock board and the Verilator model nothing decodes the counts.
std::vector<std::string> ControllerWarnings(const TwinRunOptions& o, const Twin& twin) {
  const io::BackendSpec::Kind kind = o.session.io.kind;
  if (kind != io::BackendSpec::Kind::kWire && kind != io::BackendSpec::Kind::kSpidev) return {};
  EncoderReading reading{o.controller_rate_hz, std::nullopt, std::nullopt, "--input-rate"};
  if (kind == io::BackendSpec::Kind::kWire) reading.twin_rate_hz = o.session.rate_hz;
  // Only the RELbot's top speed is known; another plant's counts are checked for the history.
  if (o.plant == kRelbotPlantName) reading.top_counts_per_s = TopCountsPerSecond(twin.params);
  return EncoderReadingWarnings(reading);
}

/// The report's line naming the injected link faults, e.g. "drop-answer,at=4000,count=3".
std::string DescribeAll(const io::LinkFaultSchedule& schedule) {
  std::string text;
  for (const io::LinkFaultInjection& injection : schedule.injections()) {
    text += (text.empty() ? "" : "; ") + io::Describe(injection);
  }
  return text;
}

}  // namespace

SessionRole TwinRole(const char* command, double controller_rate_hz) {
  return {command, "controller", "hiltwin ecs", controller_rate_hz, "twin"};
}

void ValidateTwinRunNumbers(const TwinRunOptions& o) {
  ValidateSessionSettings(o.session);
  if (!std::isfinite(o.controller_rate_hz) || o.controller_rate_hz <= 0.0 ||
      o.controller_rate_hz > o.session.rate_hz) {
    ThrowUsage("--input-rate " + Num(o.controller_rate_hz) +
               ": the controller rate must be positive and not above --rate (" +
               Num(o.session.rate_hz) + " Hz)");
  }
}

void CheckTwinRunOptions(const TwinRunOptions& o) {
  ValidateTwinRunNumbers(o);
  static_cast<void>(LinkFaultsOf(o));
}

TwinRunOutcome RunTwin(const TwinRunOptions& o, const char* command) {
  ValidateTwinRunNumbers(o);
  const io::LinkFaultSchedule link_faults = LinkFaultsOf(o);
  const std::uint64_t planned = PlannedCycles(o.session);
  // Before the first output exists: a stop signal during start-up (building the plant, INIT)
  // then ends the run at its first cycle with a report, instead of killing the process with
  // an empty report behind (docs/reliability.md, row M13).
  kernel_glue::InstallStopSignalHandlers();
  ReportFile report_file(o.session.report_path);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(o, period_ns);
  const SessionRole role = TwinRole(command, o.controller_rate_hz);
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *twin->backend);
  const std::string task_name = TaskNameOf(twin->plant->Info());
  config.task_name = task_name + " twin";
  config.details = PlantDetails(*twin);
  if (!link_faults.empty()) config.details.emplace_back("link faults", DescribeAll(link_faults));
  config.on_ready = [command, s = o.session, planned, task_name,
                     input = twin->input_name](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(command, s, planned, task_name, input, rt);
  };
  config.warnings = ControllerWarnings(o, *twin);
  PrintWarnings(command, config.warnings);
  // The emulated board exists: LinkFaultsOf accepted only mock and wire.
  std::optional<runtime::LinkFaultingTask> faulting;
  if (!link_faults.empty()) {
    faulting.emplace(*twin->task, *twin->backend->emulated_board(), link_faults);
  }
  runtime::RunTask& faulted = faulting ? static_cast<runtime::RunTask&>(*faulting) : *twin->task;
  std::optional<SetpointDisplayTask> showing;
  if (twin->shown_setpoint) showing.emplace(faulted, *twin->shown_setpoint);
  runtime::RunTask& task = showing ? static_cast<runtime::RunTask&>(*showing) : faulted;
  const runtime::RunReport report = RunSessionOf(std::move(config), task);
  const int exit_code = PrintOutcome(role, report, runtime::ToJson(report), "", report_file);
  if (report.fault && report.fault->kind == lifecycle::StopReason::kModelFault &&
      o.plant == kRelbotPlantName) {
    std::fprintf(
        stderr,
        "hiltwin %s: try a higher --rate, --integrator rk4 or check the parameters in --config\n",
        command);
  }
  twin->plant->Finish();
  return {report, exit_code};
}

}  // namespace hiltwin::app
