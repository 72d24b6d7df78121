// Issue 38, `hiltwin test` through the binary as a user runs it, on a small lockstep campaign
// written here (four short scenarios, one of which fails on purpose):
// - a lockstep campaign run twice gives the same JSON, wall-clock figures aside
//   (CampaignCli.RunTwice...);
// - three shards run by GNU parallel and joined by `hiltwin test merge` give the unsharded
//   result, JSON and JUnit (CampaignShards); the cluster's environment picks the shard;
// - --filter, --fail-fast, --keep, a real-time scenario said to run alone, and the refusals:
//   a bad campaign (exit 2 with file:line:col), a controller that cannot be loaded (exit 2
//   before any scenario), an output that cannot be written (exit 5), shards of two campaigns.
// The shipped campaign graded on the three example controllers is campaign_grading_test.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

// Named: the suite's unity batch shares one anonymous namespace with the other CLI tests.
namespace campaign_cli_test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using Json = nlohmann::json;

/// Four short lockstep scenarios: two closed loops at two twin rates, the twin alone, and a
/// closed loop whose bound no controller meets (1 µm), so the campaign exits 3.
constexpr const char* kCampaign = R"(
[campaign]
name = "small"
[defaults]
duration_s = 2
[defaults.criteria]
verdict = "PASS"
[[scenario]]
name = "loop_4k"
[scenario.criteria]
tracking_max_m = 0.003
missed_deadlines = 0
[[scenario]]
name = "loop_1k"
twin_rate_hz = 1000
[scenario.criteria]
tracking_rms_m = 0.003
[[scenario]]
name = "twin_alone"
kind = "run"
[[scenario]]
name = "too_strict"
[scenario.criteria]
tracking_max_m = 0.000001
)";

Json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The JSON result without what the wall clock decides (every "wall_s") and, for comparing a
/// merged result with an unsharded one, without the shards it came from.
Json WithoutWallClock(Json json, bool drop_shards = false) {
  if (json.is_object()) {
    json.erase("wall_s");
    if (drop_shards) json.erase("shards");
    for (auto& [key, value] : json.items()) value = WithoutWallClock(value, drop_shards);
  } else if (json.is_array()) {
    for (Json& value : json) value = WithoutWallClock(value, drop_shards);
  }
  return json;
}

/// JUnit XML without its time attributes (the wall clock's) and the property naming the shards
/// it came from.
std::string WithoutTimesAndShards(const std::string& xml) {
  const std::string timeless =
      std::regex_replace(xml, std::regex(R"( (time|timestamp)="[^"]*")"), "");
  return std::regex_replace(timeless, std::regex(R"( *<property name="shards"[^>]*/>\n)"), "");
}

class CampaignCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "campaign-cli-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    std::ofstream(campaign()) << kCampaign;
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string campaign() const { return (dir_ / "small.toml").string(); }

  /// `hiltwin test ARGS...`.
  hiltwin::test::RunResult Test(std::vector<std::string> args, int timeout_ms = 120'000) {
    args.insert(args.begin(), {HILTWIN_BINARY, "test"});
    return hiltwin::test::Run(args, timeout_ms);
  }

  fs::path dir_;
};

TEST_F(CampaignCli, ALockstepCampaignRunTwiceGivesTheSameJsonWallClockAside) {
  const std::string first = (dir_ / "first.json").string();
  const std::string second = (dir_ / "second.json").string();
  const auto a = Test({campaign(), "--jobs", "2", "--json", first});
  const auto b = Test({campaign(), "--jobs", "2", "--json", second});
  ASSERT_EQ(a.exit_code, 3) << a.out << a.err;  // too_strict fails
  ASSERT_EQ(b.exit_code, 3) << b.out << b.err;
  const Json result = ReadJson(first);
  EXPECT_EQ(WithoutWallClock(result), WithoutWallClock(ReadJson(second)));
  // What the figures are, not only that they repeat: the three that may pass do, in file order.
  ASSERT_EQ(result["scenarios"].size(), 4U);
  std::vector<std::string> names;
  for (const Json& s : result["scenarios"]) names.push_back(s["name"]);
  EXPECT_THAT(names, ::testing::ElementsAre("loop_4k", "loop_1k", "twin_alone", "too_strict"));
  EXPECT_EQ(result["failed"], 1);
  const Json& strict = result["scenarios"][3]["criteria"];
  ASSERT_EQ(strict.size(), 2U);  // verdict (from the defaults), then tracking_max_m
  EXPECT_EQ(strict[1]["name"], "tracking_max_m");
  EXPECT_FALSE(strict[1]["passed"]);
  EXPECT_GT(strict[1]["measured"].get<double>(), 1e-6);
  EXPECT_LT(strict[1]["measured"].get<double>(), 0.003);
  // A line per scenario as it ends, and the summary.
  EXPECT_THAT(a.out, HasSubstr("PASS loop_4k"));
  EXPECT_THAT(a.out, HasSubstr("FAIL too_strict"));
  EXPECT_THAT(a.out, HasSubstr("3 passed, 1 failed of 4"));
}

TEST_F(CampaignCli, ThreeShardsThroughGnuParallelMergeIntoTheUnshardedResult) {
  const std::string whole = (dir_ / "whole.json").string();
  const std::string whole_xml = (dir_ / "whole.xml").string();
  ASSERT_EQ(Test({campaign(), "--json", whole, "--junit", whole_xml}).exit_code, 3);
  // The shards as a job array would run them: three processes at once, each its own K/3.
  const auto shards =
      hiltwin::test::Run({"parallel", "--will-cite", "--halt", "never",
                          std::string(HILTWIN_BINARY) + " test " + campaign() +
                              " --shard {}/3 --json " + (dir_ / "shard{}.json").string(),
                          ":::", "1", "2", "3"},
                         180'000);
  EXPECT_EQ(shards.exit_code, 1) << shards.out << shards.err;  // one shard holds too_strict
  const std::string merged = (dir_ / "merged.json").string();
  const std::string merged_xml = (dir_ / "merged.xml").string();
  const auto merge =
      Test({"merge", (dir_ / "shard1.json").string(), (dir_ / "shard2.json").string(),
            (dir_ / "shard3.json").string(), "--json", merged, "--junit", merged_xml});
  EXPECT_EQ(merge.exit_code, 3) << merge.out << merge.err;
  EXPECT_EQ(WithoutWallClock(ReadJson(merged), true), WithoutWallClock(ReadJson(whole), true));
  EXPECT_EQ(ReadJson(merged)["shards"].size(), 3U);
  EXPECT_EQ(WithoutTimesAndShards(ReadText(merged_xml)),
            WithoutTimesAndShards(ReadText(whole_xml)));
  EXPECT_THAT(ReadText(merged_xml), HasSubstr("<property name=\"shards\" value=\"1/3+2/3+3/3\"/>"));
  // Each shard ran every third scenario: shard 2 of 3 the second.
  const Json two = ReadJson(dir_ / "shard2.json");
  ASSERT_EQ(two["scenarios"].size(), 1U);
  EXPECT_EQ(two["scenarios"][0]["name"], "loop_1k");
}

TEST_F(CampaignCli, TheClustersEnvironmentPicksTheShard) {
  const std::string gitlab = (dir_ / "gitlab.json").string();
  const std::string slurm = (dir_ / "slurm.json").string();
  auto run = [&](std::vector<std::string> env, const std::string& json) {
    std::vector<std::string> argv = {"/usr/bin/env"};
    argv.insert(argv.end(), env.begin(), env.end());
    argv.insert(argv.end(), {HILTWIN_BINARY, "test", campaign(), "--json", json});
    return hiltwin::test::Run(argv, 120'000);
  };
  // GitLab numbers its parallel jobs from 1; a Slurm array here from 0 (--array=0-1).
  EXPECT_EQ(run({"CI_NODE_INDEX=2", "CI_NODE_TOTAL=2"}, gitlab).exit_code, 3);
  EXPECT_EQ(run({"SLURM_ARRAY_TASK_ID=0", "SLURM_ARRAY_TASK_COUNT=2"}, slurm).exit_code, 0);
  std::vector<std::string> names;
  const Json gitlab_result = ReadJson(gitlab);  // kept: a loop over a temporary's member dangles
  for (const Json& s : gitlab_result["scenarios"]) names.push_back(s["name"]);
  EXPECT_THAT(names, ::testing::ElementsAre("loop_1k", "too_strict"));
  names.clear();
  const Json slurm_result = ReadJson(slurm);
  for (const Json& s : slurm_result["scenarios"]) names.push_back(s["name"]);
  EXPECT_THAT(names, ::testing::ElementsAre("loop_4k", "twin_alone"));
  const auto bad = run({"CI_NODE_INDEX=3", "CI_NODE_TOTAL=2"}, gitlab);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("CI_NODE_INDEX=3: must be 1 .. 2"));
}

TEST_F(CampaignCli, FilterFailFastAndKeepDoWhatTheySay) {
  const std::string kept = (dir_ / "kept").string();
  const auto filtered = Test({campaign(), "--filter", "loop_*", "--keep", kept});
  EXPECT_EQ(filtered.exit_code, 0) << filtered.out << filtered.err;
  EXPECT_THAT(filtered.out, HasSubstr("2 of its 4 scenarios (--filter loop_*)"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(kept) / "loop_4k" / "ecs.csv"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(kept) / "loop_1k" / "result.json"));
  EXPECT_FALSE(fs::exists(fs::path(kept) / "twin_alone"));
  // A failing scenario first, one at a time: the scenario after it is not started.
  std::ofstream(dir_ / "fast.toml") << "[[scenario]]\nname = \"fails\"\nduration_s = 2\n"
                                       "[scenario.criteria]\ntracking_max_m = 0.000001\n"
                                       "[[scenario]]\nname = \"after\"\nkind = \"run\"\n"
                                       "duration_s = 0.2\n";
  const auto fast = Test({(dir_ / "fast.toml").string(), "--fail-fast", "--jobs", "1"});
  EXPECT_EQ(fast.exit_code, 3);
  EXPECT_THAT(fast.out, HasSubstr("FAIL fails"));
  EXPECT_THAT(fast.out, Not(HasSubstr("PASS after")));
  EXPECT_THAT(fast.out, HasSubstr("1 scenario(s) not run (--fail-fast)"));
}

TEST_F(CampaignCli, ARealTimeScenarioIsSaidToRunAloneBeforeAndAsItRuns) {
  std::ofstream(dir_ / "rt.toml") << "[[scenario]]\nname = \"rt\"\nkind = \"run\"\nclock = "
                                     "\"realtime\"\nduration_s = 0.2\n[[scenario]]\nname = "
                                     "\"vt\"\nkind = \"run\"\nduration_s = 0.2\n";
  const auto r = Test({(dir_ / "rt.toml").string(), "--jobs", "2"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;  // no criteria: judged on having run
  EXPECT_THAT(r.out, HasSubstr("1 in real time, each alone"));
  EXPECT_THAT(r.out, HasSubstr("rt runs in real time, alone"));
}

TEST_F(CampaignCli, ACtrlCStopsTheRunningScenarioAndWritesWhatEndedExit130) {
  // A lockstep scenario that ends at once, then a real-time one of 30 s that Ctrl-C stops.
  std::ofstream(dir_ / "long.toml") << "[[scenario]]\nname = \"quick\"\nkind = \"run\"\n"
                                       "duration_s = 0.2\n[[scenario]]\nname = \"long\"\n"
                                       "kind = \"run\"\nclock = \"realtime\"\nduration_s = 30\n"
                                       "[[scenario]]\nname = \"never\"\nkind = \"run\"\n"
                                       "duration_s = 0.2\n";
  const std::string json = (dir_ / "r.json").string();
  const std::string out = (dir_ / "out.txt").string();
  hiltwin::kernel_glue::Process test = hiltwin::test::Spawn(
      {HILTWIN_BINARY, "test", (dir_ / "long.toml").string(), "--json", json}, out);
  // Until the real-time scenario has started.
  for (int i = 0; i < 300 && hiltwin::test::ReadOutput(out).find("long runs in real time") ==
                                 std::string::npos;
       ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(test.pid(), SIGINT);
  const std::optional<hiltwin::kernel_glue::ExitStatus> status =
      test.WaitFor(std::chrono::seconds(20));
  ASSERT_TRUE(status.has_value()) << "hiltwin test did not stop within 20 s of SIGINT";
  EXPECT_EQ(status->code, 130) << hiltwin::test::ReadOutput(out);
  const Json result = ReadJson(json);
  ASSERT_EQ(result["scenarios"].size(), 2U);  // quick and the stopped long one; never not run
  EXPECT_EQ(result["scenarios"][1]["name"], "long");
  EXPECT_THAT(hiltwin::test::ReadOutput(out),
              HasSubstr("1 scenario(s) not run (stopped by a signal)"));
}

TEST_F(CampaignCli, ABadCampaignOrControllerIsExit2BeforeAnyScenarioRuns) {
  std::ofstream(dir_ / "bad.toml") << "[[scenario]]\nname = \"a\"\ntwin_rate = 4000\n";
  const auto bad = Test({(dir_ / "bad.toml").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("bad.toml:3:1: unknown key 'twin_rate'"));
  const auto lib = Test({campaign(), "--controller", "lib:" + (dir_ / "none.so").string()});
  EXPECT_EQ(lib.exit_code, 2);
  EXPECT_THAT(lib.err, HasSubstr("none.so"));
  EXPECT_THAT(lib.out, Not(HasSubstr("PASS")));  // nothing ran
  const auto missing = Test({(dir_ / "missing.toml").string()});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("missing.toml"));
}

TEST_F(CampaignCli, AScenarioThatCannotStartIsExit5AndTheOthersStillRunAndReport) {
  // --keep's folder for loop_4k is taken by a file: that scenario cannot start, the rest run.
  const fs::path kept = dir_ / "kept";
  fs::create_directories(kept);
  std::ofstream(kept / "loop_4k") << "in the way\n";
  const std::string json = (dir_ / "r.json").string();
  const auto r = Test({campaign(), "--filter", "loop_*", "--keep", kept.string(), "--json", json});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  const Json result = ReadJson(json);
  ASSERT_EQ(result["scenarios"].size(), 2U);
  EXPECT_THAT(result["scenarios"][0]["error"].get<std::string>(),
              HasSubstr("not started: cannot make its folder"));
  EXPECT_EQ(result["scenarios"][1]["error"], "");
  EXPECT_TRUE(fs::is_regular_file(kept / "loop_1k" / "ecs.csv"));
}

TEST_F(CampaignCli, AnOutputInAFolderThatCannotBeMadeIsExit2BeforeAnyScenarioRuns) {
  const auto r = Test({campaign(), "--json", (dir_ / "no/such/folder/x.json").string()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("--json"));
  EXPECT_THAT(r.out, Not(HasSubstr("loop_4k")));
}

TEST_F(CampaignCli, MergeRefusesShardsOfTwoCampaignsAndATwiceGivenShard) {
  std::ofstream(dir_ / "other.toml")
      << "[[scenario]]\nname = \"x\"\nkind = \"run\"\nduration_s = 0.2\n";
  const std::string one = (dir_ / "one.json").string();
  const std::string other = (dir_ / "other.json").string();
  ASSERT_EQ(Test({campaign(), "--filter", "twin_alone", "--json", one}).exit_code, 0);
  ASSERT_EQ(Test({(dir_ / "other.toml").string(), "--json", other}).exit_code, 0);
  const auto mixed = Test({"merge", one, other});
  EXPECT_EQ(mixed.exit_code, 2);
  const auto twice = Test({"merge", one, one});
  EXPECT_EQ(twice.exit_code, 2);
  const auto not_json = Test({"merge", campaign()});
  EXPECT_EQ(not_json.exit_code, 2);
  EXPECT_THAT(not_json.err, HasSubstr("small.toml: not JSON"));
}

}  // namespace
}  // namespace campaign_cli_test
