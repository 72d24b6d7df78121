// The campaign file (cli/runs, campaign_file.h): defaults and scenarios read by one reader,
// paths made absolute against the file's folder, and every refusal with its place and what to
// do, before any scenario runs.
#include "hiltwin/runs/campaign_file.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "campaign_checks.h"
#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {
namespace {

namespace fs = std::filesystem;

/// A folder with the files a campaign may name: a step setpoint and a reference curve.
class CampaignFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "campaign-file-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    std::ofstream(dir_ / "step.csv")
        << "time,left_m,right_m\n0,0,0\n0.5,0,0\n0.5,0.1,0.1\n3,0.1,0.1\n";
    std::ofstream(dir_ / "ramp.csv") << "time,left_m,right_m\n0,0,0\n3,0.1,0.1\n";
    std::ofstream(dir_ / "ref.csv") << "time_s,wheel_right_m\n0,0\n1,1\n";
    fs::create_directory(dir_ / "ctl");
    std::ofstream(dir_ / "ctl/my.so") << "a library\n";  // lib: names a file that must exist
  }
  void TearDown() override { fs::remove_all(dir_); }

  Campaign Parse(const std::string& text) { return ParseCampaign(text, "c.toml", dir_.string()); }

  /// The message of the refusal `text` gets.
  std::string Refusal(const std::string& text) {
    try {
      static_cast<void>(Parse(text));
    } catch (const CampaignFileError& e) {
      return e.what();
    }
    ADD_FAILURE() << "accepted:\n" << text;
    return "";
  }

  fs::path dir_;
};

TEST_F(CampaignFile, AScenarioStartsFromTheDefaultsAndOverridesThemKeyByKey) {
  const Campaign c = Parse(R"(
[campaign]
name = "course"
[defaults]
twin_rate_hz = 8000
controller = "lib:ctl/my.so"
[defaults.criteria]
verdict = "PASS"
tracking_max_m = 0.003
[[scenario]]
name = "first"
[[scenario]]
name = "second"
twin_rate_hz = 1000
setpoint = "step.csv"
link_faults = ["drop-answer,at=4000,count=20"]
[scenario.criteria]
tracking_max_m = 0.004
settling_time_s = 0.5
)");
  ASSERT_EQ(c.scenarios.size(), 2U);
  EXPECT_EQ(c.name, "course");
  const CampaignScenario& first = c.scenarios[0];
  const CampaignScenario& second = c.scenarios[1];
  EXPECT_EQ(first.index, 0U);
  EXPECT_EQ(second.index, 1U);
  EXPECT_EQ(first.twin_rate_hz, 8000.0);
  EXPECT_EQ(second.twin_rate_hz, 1000.0);
  EXPECT_EQ(first.ecs_rate_hz, 1000.0);  // the built-in default
  EXPECT_EQ(first.clock, "virtual");
  EXPECT_EQ(first.controller, "lib:" + (dir_ / "ctl/my.so").string());
  EXPECT_EQ(first.setpoint, "closedloop");  // a built-in name stays a name
  EXPECT_EQ(second.setpoint, (dir_ / "step.csv").string());
  EXPECT_EQ(first.criteria.tracking_max_m, 0.003);
  EXPECT_EQ(second.criteria.tracking_max_m, 0.004);
  EXPECT_EQ(second.criteria.verdict, "PASS");  // from [defaults.criteria]
  EXPECT_EQ(second.criteria.settling_time_s, 0.5);
  EXPECT_FALSE(first.criteria.settling_time_s.has_value());
  EXPECT_EQ(second.link_faults.size(), 1U);
  EXPECT_EQ(second.where, "c.toml:12:1");
}

TEST_F(CampaignFile, WithoutACampaignTableTheNameIsTheFilesStem) {
  EXPECT_EQ(
      ParseCampaign("[[scenario]]\nname = \"a\"\n", "dir/relbot_course.toml", dir_.string()).name,
      "relbot_course");
}

TEST_F(CampaignFile, AnUnknownKeyIsRefusedAtItsPlaceWithTheKnownOnes) {
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\ntwin_rate = 4000\n")
                .find("c.toml:3:1: unknown key 'twin_rate' in [[scenario]] (known: kind, clock"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\n[scenario.criteria]\ntracking_max = 1\n")
                .find("c.toml:4:1: unknown key 'tracking_max' in criteria"),
            std::string::npos);
  EXPECT_NE(Refusal("[defaults]\nname = \"a\"\n[[scenario]]\nname = \"b\"\n")
                .find("c.toml:2:1: unknown key 'name' in [defaults]"),
            std::string::npos);
  EXPECT_NE(Refusal("[scenarios]\n").find("c.toml:1:2: unknown key 'scenarios'"), std::string::npos)
      << Refusal("[scenarios]\n");
}

TEST_F(CampaignFile, AFaultOverrunOrRuleTheCommandsWouldRefuseIsRefusedAtItsItem) {
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\nlink_faults = [\"drop-answer,at=1\",\n"
                    "  \"lose-everything\"]\n")
                .find("c.toml:4:3: link_faults: "),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\ntwin_overruns = [\"at=5,extra-us=x\"]\n")
                .find("c.toml:3:18: twin_overruns: "),
            std::string::npos);
  EXPECT_NE(
      Refusal("[[scenario]]\nname = \"a\"\ntwin_qos = [\"5:4\"]\n").find("c.toml:3:13: twin_qos: "),
      std::string::npos);
}

TEST_F(CampaignFile, NamesAreRequiredUniqueAndFitForAFileName) {
  EXPECT_NE(Refusal("[[scenario]]\nkind = \"hil\"\n").find("a [[scenario]] needs a name"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\n[[scenario]]\nname = \"a\"\n")
                .find("c.toml:4:8: scenario name \"a\" is used twice"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a/b\"\n").find("use letters, digits"),
            std::string::npos);
  EXPECT_NE(Refusal("[campaign]\nname = \"x\"\n").find("c.toml: no [[scenario]]"),
            std::string::npos);
}

TEST_F(CampaignFile, ValuesOfTheWrongTypeOrRangeAreRefused) {
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\nclock = \"wall\"\n")
                .find("c.toml:3:9: clock = \"wall\": must be one of virtual, realtime"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\ntwin_rate_hz = 0.5\n")
                .find("scenario a: twin_rate_hz: "),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\n[scenario.criteria]\nmissed_deadlines = 1.5\n")
                .find("c.toml:4:20: missed_deadlines must be a whole number >= 0"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\n[scenario.criteria]\ntracking_rms_m = -1\n")
                .find("tracking_rms_m = -1: must be at least 0"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\n[scenario.criteria]\nverdict = \"GOOD\"\n")
                .find("must be one of PASS, FLAGGED, ABORTED"),
            std::string::npos);
}

TEST_F(CampaignFile, ACriterionTheScenarioCannotMeasureIsRefused) {
  EXPECT_NE(Refusal("[[scenario]]\nname = \"ol\"\nmode = \"openloop\"\n[scenario.criteria]\n"
                    "tracking_max_m = 0.003\n")
                .find("c.toml:1:1: scenario ol: tracking, final error, settling and overshoot "
                      "bounds need kind = \"hil\" and mode = \"closedloop\""),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"r\"\nkind = \"run\"\n[scenario.criteria]\n"
                    "duty_saturation_pct = 5\n")
                .find("duty_saturation_pct needs kind = \"hil\""),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"s\"\nsetpoint = \"ramp.csv\"\n[scenario.criteria]\n"
                    "settling_time_s = 0.5\n")
                .find("need a setpoint with a step"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"s\"\n[scenario.criteria]\ncredibility_min = 0.9\n")
                .find("credibility_min needs reference_file and reference_column"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"s\"\n[scenario.criteria]\ncredibility_min = 0.9\n"
                    "reference_file = \"nowhere.csv\"\nreference_column = \"x\"\n")
                .find("reference_file " + (dir_ / "nowhere.csv").string() + ": no such file"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"s\"\n[scenario.criteria]\n"
                    "reference_file = \"ref.csv\"\nreference_column = \"wheel_right_m\"\n")
                .find("reference_file is given without credibility_min"),
            std::string::npos);
}

TEST_F(CampaignFile, AMissingFileIsRefusedNamingItsKeyAndWhereRelativePathsAreRead) {
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\ncontroller = \"lib:missing.so\"\n")
                .find("scenario a: controller " + (dir_ / "missing.so").string() +
                      ": no such file (relative paths are read from the campaign file's folder)"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\nsetpoint = \"missing.csv\"\n").find("missing.csv"),
            std::string::npos);
}

TEST_F(CampaignFile, ParameterOverridesApplyToTheBuiltInSetAndAreWrittenExactly) {
  const Campaign c = Parse(
      "[[scenario]]\nname = \"heavy\"\nparams = { \"body.mass_kg\" = 2.0, "
      "\"wheel.mass_kg\" = 0.11 }\n");
  const RelbotParams params = ScenarioRelbotParams(c.scenarios[0]);
  EXPECT_EQ(params.body_mass_kg, 2.0);
  EXPECT_EQ(params.wheel_mass_kg, 0.11);
  EXPECT_EQ(params.motor_resistance_ohm, DefaultRelbotParams().motor_resistance_ohm);
  // The file the scenario runs with reads back as the same numbers, every one.
  const RelbotParams read = ParseRelbotParams(RelbotParamsToml(params), "written");
  for (const ParamSpec& spec : RelbotParamSpecs()) {
    EXPECT_EQ(read.*spec.member, params.*spec.member) << spec.table << "." << spec.key;
  }
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\nparams = { \"body.mass\" = 2.0 }\n")
                .find("params \"body.mass\": no such RELbot parameter"),
            std::string::npos);
  EXPECT_NE(Refusal("[[scenario]]\nname = \"a\"\nparams = { \"body.mass_kg\" = -2.0 }\n")
                .find("body.mass_kg"),
            std::string::npos);
}

}  // namespace
}  // namespace hiltwin::app
