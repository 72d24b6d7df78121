// `hiltwin test`'s run (hiltwin/runs/campaign_run.h): the selected scenarios as processes of
// this binary, `jobs` lockstep ones at once (a real-time one alone: its timing is what it
// measures, and a neighbour would disturb it), each judged as it ends, then the outputs.
#include "hiltwin/runs/campaign_run.h"

#include <fnmatch.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>
#include <vector>

#include "campaign_scenario.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/runs/campaign_file.h"
#include "hiltwin/runs/campaign_report.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/controllers.h"
#include "hiltwin/runs/output_files.h"

namespace hiltwin::app {
namespace campaign_pool {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The scenarios this run covers: --filter's glob, then every N-th of those for --shard K/N.
std::vector<CampaignScenario> SelectScenarios(const Campaign& campaign,
                                              const CampaignRunOptions& o) {
  std::vector<CampaignScenario> filtered;
  for (const CampaignScenario& s : campaign.scenarios) {
    if (o.filter.empty() || ::fnmatch(o.filter.c_str(), s.name.c_str(), 0) == 0) {
      filtered.push_back(s);
    }
  }
  std::vector<CampaignScenario> selected;
  for (std::size_t i = 0; i < filtered.size(); ++i) {
    if (i % o.shard.count == o.shard.index - 1) selected.push_back(filtered[i]);
  }
  return selected;
}

/// --controller (and --controller-map) replace every closed-loop scenario's controller: the
/// campaign grades the code it is given. The built-in PID's gains go with the built-in PID.
void OverrideController(std::vector<CampaignScenario>& scenarios, const CampaignRunOptions& o) {
  if (o.controller.empty()) return;
  for (CampaignScenario& s : scenarios) {
    s.controller = o.controller;
    if (!o.controller_map.empty()) s.controller_map = o.controller_map;
    s.gains.clear();
  }
}

/// Every controller the closed-loop scenarios name, made and bound once here: one that cannot
/// be loaded or does not fit its map is the campaign's exit 2 before any scenario runs.
void PreflightControllers(const std::vector<CampaignScenario>& scenarios) {
  std::set<std::tuple<std::string, std::string, std::string, std::string>> checked;
  for (const CampaignScenario& s : scenarios) {
    if (s.kind != "hil" || s.mode != "closedloop") continue;
    if (!checked.insert({s.controller, s.controller_map, s.gains, s.config}).second) continue;
    try {
      static_cast<void>(MakeBoundController({s.controller, s.controller_map, s.gains, s.config}));
    } catch (const CommandError& e) {
      throw CommandError(e.code(), "scenario " + s.name + " (" + s.where + "): " + e.what());
    }
  }
}

/// A scenario's process while it runs.
struct RunningScenario {
  const CampaignScenario* scenario;
  ScenarioFiles files;
  kernel_glue::Process process;
  Clock::time_point started;
};

RunningScenario StartScenario(const CampaignScenario& s, const fs::path& work) {
  ScenarioFiles files{work / s.name};
  std::error_code error;
  fs::create_directories(files.dir, error);
  if (error)
    throw std::runtime_error("cannot make its folder " + files.dir.string() + ": " +
                             error.message());
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::File(files.output());
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  return RunningScenario{&s, files, kernel_glue::Process::Start(ScenarioArgv(s, files), options),
                         Clock::now()};
}

/// The pool: starts scenarios in campaign order while a slot is free, judges each as it ends.
class ScenarioPool {
 public:
  ScenarioPool(const std::vector<CampaignScenario>& scenarios, const CampaignRunOptions& o,
               fs::path work)
      : scenarios_(scenarios), o_(o), work_(std::move(work)) {}

  std::vector<ScenarioResult> Run() {
    while ((!stopping_ && next_ < scenarios_.size()) || !running_.empty()) {
      StartWhatFits();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      Reap();
      if (kernel_glue::StopRequested()) StopAll();
    }
    return std::move(results_);
  }
  [[nodiscard]] std::size_t not_run() const noexcept { return scenarios_.size() - started_; }
  /// A scenario could not be started (its folder, its parameter file, the process).
  [[nodiscard]] bool io_fault() const noexcept { return io_fault_; }

 private:
  [[nodiscard]] bool RealTimeRunning() const {
    for (const RunningScenario& r : running_) {
      if (r.scenario->clock == "realtime") return true;
    }
    return false;
  }

  void StartWhatFits() {
    while (!stopping_ && next_ < scenarios_.size() && running_.size() < o_.jobs &&
           !RealTimeRunning()) {
      const CampaignScenario& s = scenarios_[next_];
      if (s.clock == "realtime" && !running_.empty()) return;  // it waits to run alone
      if (s.clock == "realtime" && o_.progress) {
        std::printf("  %s runs in real time, alone: no other scenario beside it\n", s.name.c_str());
        std::fflush(stdout);
      }
      ++next_;
      ++started_;
      try {
        running_.push_back(StartScenario(s, work_));
      } catch (const std::exception& e) {  // its folder, its parameter file, the spawn
        ScenarioResult result = NotStarted(s, e.what());
        io_fault_ = true;
        Finish(std::move(result));
      }
    }
  }

  static ScenarioResult NotStarted(const CampaignScenario& s, const std::string& why) {
    ScenarioResult r;
    r.index = s.index;
    r.name = s.name;
    r.kind = s.kind;
    r.clock = s.clock;
    r.exit_code = static_cast<int>(ExitCode::kIo);
    r.error = "not started: " + why;
    return r;
  }

  /// Records a scenario's result and prints its line.
  void Finish(ScenarioResult result) {
    results_.push_back(std::move(result));
    const ScenarioResult& done = results_.back();
    std::printf("%s\n", FormatScenarioLine(done, results_.size(), scenarios_.size()).c_str());
    std::fflush(stdout);
    if (!done.passed() && o_.fail_fast) stopping_ = true;
  }

  void Reap() {
    for (auto it = running_.begin(); it != running_.end();) {
      const std::optional<kernel_glue::ExitStatus> status =
          it->process.WaitFor(std::chrono::milliseconds(0));
      if (!status) {
        ++it;
        continue;
      }
      Finish(JudgeScenario(*it->scenario, it->files, *status, SecondsSince(it->started)));
      it = running_.erase(it);
    }
  }

  /// A stop signal: no scenario is started any more and the running ones are told to stop
  /// (hil passes it on to its sides, which write their reports).
  void StopAll() {
    if (stopping_signalled_) return;
    stopping_ = stopping_signalled_ = true;
    for (RunningScenario& r : running_) ::kill(r.process.pid(), SIGTERM);
  }

  const std::vector<CampaignScenario>& scenarios_;
  const CampaignRunOptions& o_;
  fs::path work_;
  std::vector<RunningScenario> running_;
  std::vector<ScenarioResult> results_;
  std::size_t next_ = 0;
  std::size_t started_ = 0;
  bool stopping_ = false;
  bool stopping_signalled_ = false;
  bool io_fault_ = false;
};

/// The JSON text: a scenario's error may quote a program's raw output, so bytes that are not
/// UTF-8 are replaced rather than refused.
std::string DumpResult(const nlohmann::ordered_json& json) {
  return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + '\n';
}

/// The outputs, each opened before anything runs (a path that cannot be written is exit 2 at
/// once, not after the campaign) and written whole at the end (a disk that fills then: exit 5).
struct OutputFiles {
  ReportFile json, junit, html;
  explicit OutputFiles(const CampaignOutputs& o)
      : json(o.json_path, "--json"), junit(o.junit_path, "--junit"), html(o.html_path, "--html") {}

  int WriteAll(const CampaignResult& result, int exit_code) {
    if (json.wanted()) exit_code = json.WriteAtEnd(DumpResult(ToJson(result)), "test", exit_code);
    if (junit.wanted()) exit_code = junit.WriteAtEnd(ToJunitXml(result), "test", exit_code);
    if (html.wanted()) exit_code = html.WriteAtEnd(ToHtml(result), "test", exit_code);
    return exit_code;
  }
};

void CheckOutputsDistinct(const std::vector<NamedFile>& inputs, const CampaignOutputs& o) {
  std::vector<NamedFile> files = inputs;
  files.insert(files.end(), {{"--json", o.json_path, true},
                             {"--junit", o.junit_path, true},
                             {"--html", o.html_path, true}});
  CheckFilesDistinct(files);
}

void PrintHead(const Campaign& campaign, const std::vector<CampaignScenario>& selected,
               const CampaignRunOptions& o) {
  std::size_t realtime = 0;
  for (const CampaignScenario& s : selected) realtime += s.clock == "realtime" ? 1U : 0U;
  std::printf("hiltwin test: campaign %s, %zu of its %zu scenarios", campaign.name.c_str(),
              selected.size(), campaign.scenarios.size());
  if (!o.filter.empty()) std::printf(" (--filter %s)", o.filter.c_str());
  if (o.shard.count > 1) std::printf(" (shard %zu/%zu)", o.shard.index, o.shard.count);
  std::printf(", %zu at a time", o.jobs);
  if (realtime > 0) std::printf("; %zu in real time, each alone", realtime);
  std::printf("\n");
  std::fflush(stdout);
}

/// A whole number from text, or nullopt.
std::optional<std::size_t> WholeNumber(std::string_view text) {
  std::size_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

/// K of N from two environment variables; `first` is the number of the first shard (0 or 1).
std::optional<ShardSpec> ShardFromVariables(const std::map<std::string, std::string>& env,
                                            const char* index_name, const char* count_name,
                                            std::size_t first) {
  const auto index = env.find(index_name);
  const auto count = env.find(count_name);
  if (index == env.end() || count == env.end()) return std::nullopt;
  const std::optional<std::size_t> k = WholeNumber(index->second);
  const std::optional<std::size_t> n = WholeNumber(count->second);
  if (!n || *n == 0) {
    throw std::invalid_argument(std::string(count_name) + "=" + count->second +
                                ": must be a whole number of shards, at least 1");
  }
  if (!k || *k < first || *k - first >= *n) {
    throw std::invalid_argument(std::string(index_name) + "=" + index->second + ": must be " +
                                std::to_string(first) + " .. " + std::to_string(first + *n - 1) +
                                " (" + count_name + "=" + count->second + ")");
  }
  return ShardSpec{*k - first + 1, *n};
}

}  // namespace campaign_pool

ShardSpec ParseShard(const std::string& text) {
  using namespace campaign_pool;  // this file's helpers
  const std::size_t slash = text.find('/');
  const std::optional<std::size_t> k = slash == std::string::npos
                                           ? std::nullopt
                                           : WholeNumber(std::string_view(text).substr(0, slash));
  const std::optional<std::size_t> n = slash == std::string::npos
                                           ? std::nullopt
                                           : WholeNumber(std::string_view(text).substr(slash + 1));
  if (!k || !n || *n == 0 || *k == 0 || *k > *n) {
    throw std::invalid_argument("\"" + text + "\": expected K/N with 1 <= K <= N, e.g. 2/3");
  }
  return ShardSpec{*k, *n};
}

std::optional<ShardSpec> ShardFromEnvironment(const std::map<std::string, std::string>& env) {
  using namespace campaign_pool;  // this file's helpers
  // A Slurm array's task ids run from SLURM_ARRAY_TASK_MIN (--array=0-2 or 1-3); GitLab's
  // parallel: numbers its jobs 1 .. CI_NODE_TOTAL.
  std::size_t slurm_first = 0;
  if (const auto min = env.find("SLURM_ARRAY_TASK_MIN"); min != env.end()) {
    const std::optional<std::size_t> first = WholeNumber(min->second);
    if (!first) {
      throw std::invalid_argument("SLURM_ARRAY_TASK_MIN=" + min->second +
                                  ": must be a whole number");
    }
    slurm_first = *first;
  }
  if (auto slurm =
          ShardFromVariables(env, "SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", slurm_first)) {
    return slurm;
  }
  return ShardFromVariables(env, "CI_NODE_INDEX", "CI_NODE_TOTAL", 1);
}

int RunCampaign(const CampaignRunOptions& o) {
  using namespace campaign_pool;  // this file's helpers
  kernel_glue::InstallStopSignalHandlers();
  CheckOutputsDistinct({{"the campaign file", o.campaign_path, false}}, o.outputs);
  Campaign campaign;
  try {
    campaign = LoadCampaign(o.campaign_path);
  } catch (const CampaignFileError& e) {
    ThrowUsage(e.what());
  }
  std::vector<CampaignScenario> selected = SelectScenarios(campaign, o);
  OverrideController(selected, o);
  PreflightControllers(selected);
  OutputFiles outputs(o.outputs);
  // Every scenario's own folder is made in it: --keep's, or a temporary one removed at the end.
  const WorkFolder work(o.keep_dir, "--keep", "hiltwin-test");
  PrintHead(campaign, selected, o);
  const Clock::time_point start = Clock::now();
  ScenarioPool pool(selected, o, work.path());
  CampaignResult result;
  result.name = campaign.name;
  result.file = o.campaign_path;
  result.scenarios_in_file = campaign.scenarios.size();
  result.filter = o.filter;
  result.shards = {o.shard};
  result.scenarios = pool.Run();
  std::sort(result.scenarios.begin(), result.scenarios.end(),
            [](const ScenarioResult& a, const ScenarioResult& b) { return a.index < b.index; });
  result.wall_s = SecondsSince(start);
  std::fputs(FormatCampaignSummary(result).c_str(), stdout);
  if (pool.not_run() > 0) {
    std::printf("hiltwin test: %zu scenario(s) not run (%s)\n", pool.not_run(),
                kernel_glue::StopRequested() ? "stopped by a signal" : "--fail-fast");
  }
  if (!o.keep_dir.empty())
    std::printf("hiltwin test: logs and reports kept in %s\n", o.keep_dir.c_str());
  std::fflush(stdout);
  const int exit_code = outputs.WriteAll(
      result, pool.io_fault() ? static_cast<int>(ExitCode::kIo) : result.exit_code());
  if (kernel_glue::StopRequested()) return 128 + kernel_glue::StopSignal();
  return exit_code;
}

int RunCampaignMerge(const std::vector<std::string>& inputs, const CampaignOutputs& outputs) {
  using namespace campaign_pool;  // this file's helpers
  std::vector<NamedFile> files;
  for (const std::string& input : inputs) files.push_back({"a shard result", input, false});
  CheckOutputsDistinct(files, outputs);
  std::vector<CampaignResult> shards;
  for (const std::string& input : inputs) {
    std::ifstream file(input);
    if (!file) ThrowUsage(input + ": cannot be read (a shard's --json result)");
    try {
      shards.push_back(CampaignResultFromJson(nlohmann::json::parse(file), input));
    } catch (const nlohmann::json::exception& e) {
      ThrowUsage(input + ": not JSON (" + e.what() + "); give the files shards wrote with --json");
    } catch (const CampaignResultError& e) {
      ThrowUsage(e.what());
    }
  }
  CampaignResult merged;
  try {
    merged = MergeCampaignResults(std::move(shards));
  } catch (const CampaignResultError& e) {
    ThrowUsage(e.what());
  }
  OutputFiles files_out(outputs);
  std::fputs(FormatCampaignSummary(merged).c_str(), stdout);
  std::fflush(stdout);
  return files_out.WriteAll(merged, merged.exit_code());
}

}  // namespace hiltwin::app
