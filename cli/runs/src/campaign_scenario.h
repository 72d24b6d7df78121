#pragma once
// One campaign scenario as a process of this binary: its command line (`hiltwin hil` or
// `hiltwin run`, every output into the scenario's own folder) and, once it has ended, its
// judgement from what it left there.
#include <filesystem>
#include <string>
#include <vector>

#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/runs/campaign_file.h"
#include "hiltwin/runs/campaign_result.h"

namespace hiltwin::app {

/// The files a scenario leaves in its folder.
struct ScenarioFiles {
  std::filesystem::path dir;
  [[nodiscard]] std::filesystem::path report() const { return dir / "result.json"; }
  [[nodiscard]] std::filesystem::path output() const { return dir / "output.txt"; }
  [[nodiscard]] std::filesystem::path params() const { return dir / "relbot.toml"; }
  /// hil's --log-dir holds ecs.csv (the ECS's log) and twin.csv; run's log is twin.csv.
  [[nodiscard]] std::filesystem::path log(const CampaignScenario& s) const {
    return dir / (s.kind == "hil" ? "ecs.csv" : "twin.csv");
  }
};

/// The scenario's command line, argv[0] /proc/self/exe. Writes the scenario's parameter file
/// first when it overrides parameters. Throws CommandError (exit 5) when that file cannot be
/// written.
[[nodiscard]] std::vector<std::string> ScenarioArgv(const CampaignScenario& s,
                                                    const ScenarioFiles& files);

/// The scenario's result from its exit status and its folder: its criteria judged on its
/// report and log, its plot, and an error when it could not be judged.
[[nodiscard]] ScenarioResult JudgeScenario(const CampaignScenario& s, const ScenarioFiles& files,
                                           const kernel_glue::ExitStatus& status, double wall_s);

}  // namespace hiltwin::app
