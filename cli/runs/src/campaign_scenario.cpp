// One campaign scenario as a process of this binary (campaign_scenario.h).
#include "campaign_scenario.h"

#include <charconv>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "campaign_checks.h"
#include "hiltwin/runs/campaign_criteria.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/output_files.h"
#include "hiltwin/runs/session_assembly.h"

namespace hiltwin::app {
namespace campaign_scenario_detail {

void Add(std::vector<std::string>& argv, std::initializer_list<std::string> args) {
  argv.insert(argv.end(), args);
}

/// Flags of the twin's own command line: given to `run` directly, to `hil` through --twin-arg.
std::vector<std::string> TwinFlags(const CampaignScenario& s) {
  std::vector<std::string> flags;
  if (!s.plant.empty()) Add(flags, {"--plant", s.plant});
  if (!s.plant_map.empty()) Add(flags, {"--plant-map", s.plant_map});
  for (const std::string& spec : s.link_faults) Add(flags, {"--inject-link-fault", spec});
  for (const std::string& spec : s.twin_overruns) Add(flags, {"--inject-overrun", spec});
  return flags;
}

/// The parameter file the scenario runs with: its overrides written to its folder, or its own.
std::string ConfigPath(const CampaignScenario& s, const ScenarioFiles& files) {
  if (s.params.empty()) return s.config;
  std::ofstream file(files.params());
  file << RelbotParamsToml(ScenarioRelbotParams(s));
  if (!file.flush()) {
    throw CommandError(ExitCode::kIo, "cannot write " + files.params().string());
  }
  return files.params().string();
}

std::vector<std::string> HilArgv(const CampaignScenario& s, const ScenarioFiles& files,
                                 const std::string& config) {
  std::vector<std::string> argv = {"/proc/self/exe", "hil",
                                   "--clock",        s.clock,
                                   "--mode",         s.mode,
                                   "--twin-rate",    ExactNum(s.twin_rate_hz),
                                   "--ecs-rate",     ExactNum(s.ecs_rate_hz),
                                   "--report",       files.report().string(),
                                   "--log-dir",      files.dir.string(),
                                   "--no-progress"};
  if (s.mode == "closedloop") {
    Add(argv, {"--setpoint", s.setpoint, "--controller", s.controller});
    if (!s.controller_map.empty()) Add(argv, {"--controller-map", s.controller_map});
    if (!s.gains.empty()) Add(argv, {"--gains", s.gains});
  } else {
    Add(argv, {"--input", s.input});
  }
  if (s.duration_s > 0.0) Add(argv, {"--duration", ExactNum(s.duration_s)});
  if (!config.empty()) Add(argv, {"--config", config});
  for (const std::string& rule : s.twin_qos) Add(argv, {"--twin-qos", rule});
  for (const std::string& rule : s.ecs_qos) Add(argv, {"--ecs-qos", rule});
  if (s.twin_max_miss_pct) Add(argv, {"--twin-max-miss-pct", ExactNum(*s.twin_max_miss_pct)});
  if (s.ecs_max_miss_pct) Add(argv, {"--ecs-max-miss-pct", ExactNum(*s.ecs_max_miss_pct)});
  for (const std::string& flag : TwinFlags(s)) argv.push_back("--twin-arg=" + flag);
  for (const std::string& spec : s.ecs_overruns) {
    Add(argv, {"--ecs-arg=--inject-overrun", "--ecs-arg=" + spec});
  }
  return argv;
}

std::vector<std::string> RunArgv(const CampaignScenario& s, const ScenarioFiles& files,
                                 const std::string& config) {
  std::vector<std::string> argv = {"/proc/self/exe", "run",
                                   "--io",           "mock",
                                   "--clock",        s.clock,
                                   "--rate",         ExactNum(s.twin_rate_hz),
                                   "--input",        s.input,
                                   "--input-rate",   ExactNum(s.ecs_rate_hz),
                                   "--report",       files.report().string(),
                                   "--log",          files.log(s).string(),
                                   "--no-progress"};
  if (s.duration_s > 0.0) Add(argv, {"--duration", ExactNum(s.duration_s)});
  if (!config.empty()) Add(argv, {"--config", config});
  for (const std::string& rule : s.twin_qos) Add(argv, {"--qos", rule});
  if (s.twin_max_miss_pct) Add(argv, {"--max-miss-pct", ExactNum(*s.twin_max_miss_pct)});
  const std::vector<std::string> twin = TwinFlags(s);
  argv.insert(argv.end(), twin.begin(), twin.end());
  return argv;
}

/// The last lines of the scenario's output, for a message about why it could not be judged.
std::string OutputTail(const ScenarioFiles& files) {
  std::ifstream file(files.output());
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  std::string tail;
  for (std::size_t i = lines.size() > 3 ? lines.size() - 3 : 0; i < lines.size(); ++i) {
    tail += (tail.empty() ? "" : " | ") + lines[i];
  }
  return tail.empty() ? "no output" : tail;
}


}  // namespace campaign_scenario_detail

std::vector<std::string> ScenarioArgv(const CampaignScenario& s, const ScenarioFiles& files) {
  using namespace campaign_scenario_detail;  // this file's helpers
  const std::string config = ConfigPath(s, files);
  return s.kind == "hil" ? HilArgv(s, files, config) : RunArgv(s, files, config);
}

ScenarioResult JudgeScenario(const CampaignScenario& s, const ScenarioFiles& files,
                             const kernel_glue::ExitStatus& status, double wall_s) {
  using namespace campaign_scenario_detail;  // this file's helpers
  ScenarioResult r;
  r.index = s.index;
  r.name = s.name;
  r.kind = s.kind;
  r.clock = s.clock;
  r.controller = s.kind == "hil" && s.mode == "closedloop" ? s.controller : "";
  r.exit_code = status.exited ? status.code : 1;
  r.wall_s = wall_s;
  // Exit 0, 3 (FLAGGED) and 4 (ABORTED) are verdicts the criteria judge; anything else (a
  // crash, a model fault, bad input, an I/O error) means the run itself did not hold.
  const bool judged_exit =
      status.exited && (status.code == 0 || status.code == 3 || status.code == 4);
  const std::string command = "hiltwin " + s.kind;
  if (!judged_exit) {
    r.error = command + " ended with " + status.Describe() + ": " + OutputTail(files) + " (" +
              files.output().string() + ")";
  }
  const std::optional<nlohmann::ordered_json> report = ReadReportFile(files.report());
  if (!report) {
    if (r.error.empty()) r.error = command + " wrote no report (" + files.output().string() + ")";
  } else {
    try {
      const ScenarioMeasures measures = s.kind == "hil"
                                            ? MeasureHil(*report, files.log(s), s.criteria)
                                            : MeasureRun(*report, files.log(s), s.criteria);
      r.verdict = measures.verdict;
      r.criteria = Judge(s.criteria, measures);
    } catch (const std::exception& e) {
      if (r.error.empty()) r.error = e.what();
    }
  }
  r.plot = PlotOf(files.log(s));
  return r;
}

}  // namespace hiltwin::app
