// `hiltwin run` as a function (twin_run.h): flags -> twin -> the shared session assembly ->
// the run's outcome. cli/cmd_run.cpp and cli/cmd_trace.cpp both call it.
#include "hiltwin/runs/twin_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "hiltwin/runs/command.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/runtime/link_faulting_task.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::app {
namespace {

void Validate(const TwinRunOptions& o) {
  ValidateSessionOptions(o.session);
  if (!std::isfinite(o.controller_rate_hz) || o.controller_rate_hz <= 0.0 ||
      o.controller_rate_hz > o.session.rate_hz) {
    ThrowUsage("--input-rate: the controller rate must be positive and not above --rate (" +
          Num(o.session.rate_hz) + " Hz)");
  }
}

void PrintStartLines(const char* command, const SessionOptions& o, std::uint64_t planned,
                     const std::string& plant, const std::string& input,
                     const kernel_glue::RtSetupRecord* rt) {
  std::fprintf(
      stdout,
      "hiltwin %s: %s twin at %.0f Hz for %.3f s (%llu cycles), io %s, input %s, %s clock\n",
      command, plant.c_str(), o.rate_hz, o.duration_s, static_cast<unsigned long long>(planned),
      o.io.c_str(), input.c_str(), o.clock.c_str());
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

/// --inject-link-fault's SPECs, checked against the backend and the run's length (exit 2).
io::LinkFaultSchedule LinkFaultsOf(const TwinRunOptions& o) {
  io::LinkFaultSchedule schedule;
  if (o.inject_link_faults.empty()) return schedule;
  if (o.session.io != "mock" && o.session.io.rfind("wire:", 0) != 0) {
    ThrowUsage("--inject-link-fault needs an emulated board (--io mock or wire:NAME), not --io " +
          o.session.io);
  }
  try {
    for (const std::string& spec : o.inject_link_faults)
      schedule.Add(io::ParseLinkFaultInjection(spec));
    schedule.CheckFiresWithin(PlannedCycles(o.session));
  } catch (const std::exception& e) {
    ThrowUsage(std::string("--inject-link-fault ") + e.what());
  }
  return schedule;
}

/// The report's line naming the injected link faults, e.g. "drop-answer,at=4000,count=3".
std::string DescribeAll(const io::LinkFaultSchedule& schedule) {
  std::string text;
  for (const io::LinkFaultInjection& injection : schedule.injections()) {
    text += (text.empty() ? "" : "; ") + io::Describe(injection);
  }
  return text;
}

/// --input-rate, or its documented default.
double ControllerRateOf(const TwinRunOptions& o) {
  return o.controller_rate_hz == 0.0 ? std::min(1000.0, o.session.rate_hz) : o.controller_rate_hz;
}

}  // namespace

void CheckTwinRunOptions(const TwinRunOptions& o) {
  TwinRunOptions checked = o;
  checked.controller_rate_hz = ControllerRateOf(o);
  Validate(checked);
  static_cast<void>(LinkFaultsOf(checked));
}

TwinRunOutcome RunTwin(TwinRunOptions o, const char* command) {
  o.controller_rate_hz = ControllerRateOf(o);
  Validate(o);
  const io::LinkFaultSchedule link_faults = LinkFaultsOf(o);
  const std::uint64_t planned = PlannedCycles(o.session);
  // Before the first output exists: a stop signal during start-up (building the plant, INIT)
  // then ends the run at its first cycle with a report, instead of killing the process with
  // an empty report behind (docs/reliability.md, row M13).
  kernel_glue::InstallStopSignalHandlers();
  ReportFile report_file(o.session.report_path);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(o.session.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(o, period_ns);
  const SessionRole role{command, "controller", "hiltwin ecs", o.controller_rate_hz, "twin"};
  runtime::SessionConfig config = MakeSessionConfig(o.session, role, *twin->backend);
  const std::string task_name = TaskNameOf(twin->plant->Info());
  config.task_name = task_name + " twin";
  config.details = PlantDetails(*twin);
  if (!link_faults.empty()) config.details.emplace_back("link faults", DescribeAll(link_faults));
  config.on_ready = [command, s = o.session, planned, task_name,
                     input = twin->input_name](const kernel_glue::RtSetupRecord* rt) {
    PrintStartLines(command, s, planned, task_name, input, rt);
  };
  // The emulated board exists: LinkFaultsOf accepted only mock and wire.
  std::optional<runtime::LinkFaultingTask> faulting;
  if (!link_faults.empty()) faulting.emplace(*twin->task, *twin->backend->emulated_board(), link_faults);
  runtime::RunTask& task = faulting ? static_cast<runtime::RunTask&>(*faulting) : *twin->task;
  const runtime::RunReport report = RunSessionOf(std::move(config), task);
  PrintOutcome(role, report, runtime::ToJson(report), "", report_file);
  if (report.fault && report.fault->kind == lifecycle::StopReason::kModelFault &&
      o.plant == kRelbotPlantName) {
    std::fprintf(
        stderr,
        "hiltwin %s: try a higher --rate, --integrator rk4 or check the parameters in --config\n",
        command);
  }
  twin->plant->Finish();
  const int exit_code = static_cast<int>(runtime::ExitCodeFor(report));
  return {report, exit_code};
}

void AddTwinRunOptions(CLI::App& app, TwinRunOptions& o) {
  AddSessionOptions(app, o.session);
  app.add_option("--input", o.input,
                 "input profile: a built-in name (openloop) or a CSV file time,left,right")
      ->capture_default_str();
  app.add_option("--input-rate", o.controller_rate_hz,
                 "rate in Hz at which the input is played into the PWM reader (the ECS's rate; "
                 "default 1000, or --rate if lower)");
  app.add_option("--plant", o.plant,
                 "the plant: a built-in or 20-sim plant's name, or fmu:PATH.fmu for an FMI 2.0 "
                 "co-simulation FMU (docs/plants.md)")
      ->capture_default_str();
  app.add_option("--plant-map", o.plant_map_path,
                 "plant map (TOML): which PWM channel drives which plant input and which output "
                 "each encoder follows, with scales (default: the plant's own; docs/plants.md)");
  app.add_option("--config", o.config_path,
                 "RELbot parameter file (TOML, see app_relbot/relbot.toml)");
  app.add_option("--integrator", o.integrator, "RELbot integrator: euler | rk2 | rk4 (default rk4)");
  app.add_option("--inject-link-fault", o.inject_link_faults,
                 "fault injection (mock and wire): break the link at exchange K, e.g. "
                 "drop-answer,at=4000,count=3; KIND corrupt-request, corrupt-answer, drop-answer, "
                 "delay-answer or stuck-encoder (to the end without count) (repeatable)");
}

}  // namespace hiltwin::app
