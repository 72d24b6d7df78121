// `hiltwin test`: a campaign of HiL scenarios with pass criteria, graded into JUnit XML, a
// JSON result and an HTML page; `hiltwin test merge` joins the results of shards.
// Flags -> CampaignRunOptions (checked, read once; the shard from --shard or the cluster's
// environment) -> RunCampaign / RunCampaignMerge (hiltwin/runs/campaign_run.h).
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "hiltwin/runs/campaign_run.h"

extern char** environ;  // POSIX: the process's environment, for the cluster's shard variables

namespace hiltwin::app {
namespace {

std::map<std::string, std::string> Environment() {
  std::map<std::string, std::string> env;
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const std::string text = *entry;
    const std::size_t equals = text.find('=');
    if (equals != std::string::npos) env[text.substr(0, equals)] = text.substr(equals + 1);
  }
  return env;
}

/// The flags as typed, before they are checked.
struct TestFlags {
  CampaignRunOptions run;
  std::string shard;
  std::vector<std::string> merge_inputs;
  CampaignOutputs merge_outputs;
};

CampaignRunOptions CampaignRunOptionsOf(TestFlags& f) {
  CampaignRunOptions o = f.run;
  if (o.campaign_path.empty()) {
    ThrowUsage(
        "give a campaign file: hiltwin test CAMPAIGN.toml (or hiltwin test merge "
        "SHARD.json...); docs/testing-campaigns.md");
  }
  if (o.jobs == 0) ThrowUsage("--jobs 0: give at least 1 scenario at a time");
  if (!o.controller_map.empty() && o.controller.empty()) {
    ThrowUsage(
        "--controller-map goes with --controller (the campaign's own scenarios name "
        "their maps)");
  }
  try {
    if (!f.shard.empty()) {
      o.shard = ParseShard(f.shard);
    } else if (const std::optional<ShardSpec> env = ShardFromEnvironment(Environment())) {
      o.shard = *env;
    }
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string(f.shard.empty() ? "" : "--shard ") + e.what());
  }
  return o;
}

void AddOutputFlags(CLI::App& app, CampaignOutputs& o) {
  app.add_option("--json", o.json_path,
                 "write the JSON result (what `hiltwin test merge` reads) to this file");
  app.add_option("--junit", o.junit_path,
                 "write JUnit XML (Jenkins, GitLab, GitHub test reports) to this file");
  app.add_option("--html", o.html_path,
                 "write one self-contained HTML page (table and tracking plots) to this file");
}

void AddMergeCommand(CLI::App& test, const std::shared_ptr<TestFlags>& f) {
  CLI::App* merge = test.add_subcommand(
      "merge",
      "Join the --json results of a campaign's shards (hiltwin test --shard K/N) into one\n"
      "result: JUnit XML, JSON and HTML as an unsharded run writes them. Exit: 0 every\n"
      "scenario passed, 3 some failed, 2 a file that is not a shard result or shards that do\n"
      "not join (another campaign, a shard twice), 5 an output that cannot be written.");
  merge->add_option("SHARD_JSON", f->merge_inputs, "the shards' --json results")->required();
  AddOutputFlags(*merge, f->merge_outputs);
}

Command AddTestCommand(CLI::App& parent) {
  auto f = std::make_shared<TestFlags>();
  CLI::App* app = parent.add_subcommand(
      "test",
      "Run a test campaign: HiL scenarios with pass criteria, graded (docs/testing-campaigns.md).\n"
      "Each scenario is a `hiltwin hil` (your controller against the twin) or `hiltwin run`\n"
      "(the twin alone) with its setpoint, rates, parameters, link faults and overruns, judged\n"
      "on its criteria: verdict, tracking, settling, overshoot, duty saturation, missed\n"
      "deadlines, credibility against a reference. A line per scenario as it ends, a summary,\n"
      "and --junit, --json, --html. Lockstep scenarios run --jobs at a time; a real-time one\n"
      "runs alone. Exit: 0 every scenario passed, 3 some failed, 2 bad campaign or flags, 5 I/O\n"
      "(an output or folder that cannot be written), 128+N stopped by signal N.");
  app->add_option("CAMPAIGN", f->run.campaign_path, "the campaign file (TOML)");
  app->add_option("--controller", f->run.controller,
                  "grade this controller: replaces every closed-loop scenario's (pid, "
                  "lib:PATH.so, 20sim:NAME, fmu:PATH.fmu)");
  app->add_option("--controller-map", f->run.controller_map,
                  "with --controller: its controller map (TOML)");
  app->add_option("--jobs,-j", f->run.jobs,
                  "lockstep scenarios run at once (real-time ones always run alone); a lockstep "
                  "hil scenario keeps two CPUs busy, so give it two per job")
      ->capture_default_str();
  app->add_option("--shard", f->shard,
                  "run every N-th scenario, the K-th of each N: K/N (default: from "
                  "SLURM_ARRAY_TASK_ID/COUNT or CI_NODE_INDEX/TOTAL when set, else 1/1)");
  app->add_option("--filter", f->run.filter,
                  "run only scenarios whose name matches this glob (e.g. 'twin_rate_*')");
  app->add_flag("--fail-fast", f->run.fail_fast, "start no scenario after the first that failed");
  app->add_option("--keep", f->run.keep_dir,
                  "keep every scenario's logs, reports and output in DIR/SCENARIO");
  AddOutputFlags(*app, f->run.outputs);
  app->add_flag(
      "--no-progress", [f](std::int64_t) { f->run.progress = false; },
      "no line when a real-time scenario starts");
  AddMergeCommand(*app, f);
  app->require_subcommand(0, 1);
  return {app, [f, app] {
            if (app->get_subcommand("merge")->parsed()) {
              return RunCampaignMerge(f->merge_inputs, f->merge_outputs);
            }
            return RunCampaign(CampaignRunOptionsOf(*f));
          }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(35, AddTestCommand);

}  // namespace hiltwin::app
