// Issue 38, "Done when": the shipped campaign (campaigns/relbot_course.toml) grades the three
// example controllers (examples/grading, built from C here by tests/controllers) as
// docs/testing-campaigns.md and examples/grading/README.md say: the tuned PID passes every
// scenario, the sluggish P-only fails the step's settling (and the tracking of every closed
// loop), the unstable PI fails every closed-loop scenario. Asserted exactly: which criteria of
// which scenarios fail, and that no other does. The JUnit file of each run validates against
// the JUnit schema (tests/unit/campaign/junit.xsd) by xmllint, a tool independent of hiltwin.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

// Named: the suite's unity batch shares one anonymous namespace with the other CLI tests.
namespace campaign_grading_test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using FailedCriteria = std::map<std::string, std::set<std::string>>;  // scenario -> criteria

/// The closed-loop scenarios of the shipped campaign that follow the 2.5 m move.
const std::vector<std::string> kMoveScenarios = {
    "closedloop_2_5m", "lost_frames_20", "twin_overrun_600us", "twin_rate_1khz",
    "twin_rate_4khz",  "twin_rate_8khz", "heavier_robot_10pct"};

FailedCriteria OnEveryMove(const std::set<std::string>& criteria) {
  FailedCriteria failed;
  for (const std::string& scenario : kMoveScenarios) failed[scenario] = criteria;
  return failed;
}

struct Grade {
  std::string controller;  ///< examples/grading's library
  int exit_code;
  FailedCriteria failed;
};

std::ostream& operator<<(std::ostream& out, const Grade& g) { return out << g.controller; }

Grade Tuned() { return {"tuned_pid", 0, {}}; }
Grade Sluggish() {
  FailedCriteria failed = OnEveryMove({"tracking_max_m", "tracking_rms_m"});
  failed["step_10cm"] = {"settling_time_s"};  // the step's only failure: settling
  return {"sluggish_p", 3, failed};
}
Grade Unstable() {
  FailedCriteria failed =
      OnEveryMove({"tracking_max_m", "tracking_rms_m", "final_error_m", "duty_saturation_pct"});
  failed["step_10cm"] = {"final_error_m", "settling_time_s", "overshoot_pct",
                         "duty_saturation_pct"};
  return {"unstable_pi", 3, failed};  // openloop_credibility runs no controller: it passes
}

FailedCriteria FailedIn(const Json& result) {
  FailedCriteria failed;
  for (const Json& scenario : result["scenarios"]) {
    EXPECT_EQ(scenario["error"], "") << scenario["name"];
    for (const Json& criterion : scenario["criteria"]) {
      if (!criterion["passed"].get<bool>()) failed[scenario["name"]].insert(criterion["name"]);
    }
  }
  return failed;
}

class CampaignGrading : public ::testing::TestWithParam<Grade> {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "campaign-grading-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_P(CampaignGrading, TheShippedCampaignGradesTheExampleController) {
  const Grade& grade = GetParam();
  const std::string json = (dir_ / "result.json").string();
  const std::string junit = (dir_ / "result.xml").string();
  const std::string html = (dir_ / "result.html").string();
  const auto r = hiltwin::test::Run(
      {HILTWIN_BINARY, "test", std::string(HILTWIN_SOURCE_DIR) + "/campaigns/relbot_course.toml",
       "--jobs", "2", "--controller",
       "lib:" + std::string(HILTWIN_TEST_CONTROLLER_DIR) + "/" + grade.controller + ".so", "--json",
       json, "--junit", junit, "--html", html},
      300'000);
  ASSERT_EQ(r.exit_code, grade.exit_code) << r.out << r.err;
  std::ifstream in(json);
  const Json result = Json::parse(in);
  ASSERT_EQ(result["scenarios"].size(), 9U);
  EXPECT_EQ(FailedIn(result), grade.failed);
  // The JUnit file as a CI server reads it: valid against the schema, one failure per failed
  // criterion.
  const auto lint = hiltwin::test::Run(
      {"xmllint", "--noout", "--schema",
       std::string(HILTWIN_SOURCE_DIR) + "/tests/unit/campaign/junit.xsd", junit});
  EXPECT_EQ(lint.exit_code, 0) << lint.out << lint.err;
  std::ifstream xml_in(junit);
  const std::string xml{std::istreambuf_iterator<char>(xml_in), std::istreambuf_iterator<char>()};
  std::size_t failures = 0;
  for (const auto& [scenario, criteria] : grade.failed) failures += criteria.size();
  std::size_t found = 0;
  for (std::size_t at = xml.find("<failure "); at != std::string::npos;
       at = xml.find("<failure ", at + 1)) {
    ++found;
  }
  EXPECT_EQ(found, failures);
  // The page holds a plot of every scenario.
  std::ifstream html_in(html);
  const std::string page{std::istreambuf_iterator<char>(html_in), std::istreambuf_iterator<char>()};
  std::size_t plots = 0;
  for (std::size_t at = page.find("<svg"); at != std::string::npos;
       at = page.find("<svg", at + 1)) {
    ++plots;
  }
  EXPECT_GE(plots, 9U);
}

INSTANTIATE_TEST_SUITE_P(ExampleControllers, CampaignGrading,
                         ::testing::Values(Tuned(), Sluggish(), Unstable()),
                         [](const ::testing::TestParamInfo<Grade>& param) {
                           return param.param.controller;
                         });

}  // namespace
}  // namespace campaign_grading_test
