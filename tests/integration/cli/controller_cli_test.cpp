// `hiltwin ecs --controller SPEC --controller-map FILE` and `hiltwin hil` passing them on, as a
// user runs them: a bad spec, a bad map and --gains beside another controller are exit 2 with
// a message that says what and where; the start line and the report name the controller.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "plant_test_support.h"

namespace {

using ::testing::HasSubstr;
using ::testing::Not;

class ControllerCli : public hiltwin::test::TempDirTest {
 protected:
  static hiltwin::test::RunResult Ecs(std::vector<std::string> extra) {
    std::vector<std::string> argv = {HILTWIN_BINARY, "ecs",        "--no-progress", "--clock",
                                     "virtual",      "--duration", "0.05"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return hiltwin::test::Run(argv);
  }
};

TEST_F(ControllerCli, AnUnknownSpecIsExit2ListingTheControllersThatExist) {
  const auto r = Ecs({"--controller", "pdi"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("--controller pdi: no such controller; give one of: pid (the "
                               "built-in position PID per wheel, thesis 7.2 (--gains))"));
  EXPECT_THAT(r.err, HasSubstr("(docs/controllers.md)"));
  // Each kind says what follows its prefix: a file, or a 20-sim controller's name.
  EXPECT_THAT(r.err, HasSubstr("; lib:PATH ("));
  EXPECT_THAT(r.err, HasSubstr("; 20sim:NAME ("));
  const auto bare = Ecs({"--controller", "20sim:"});
  EXPECT_EQ(bare.exit_code, 2) << bare.out << bare.err;
  EXPECT_THAT(bare.err, HasSubstr("--controller 20sim:: nothing after '20sim:': give 20sim:NAME"));
}

TEST_F(ControllerCli, ABadMapIsExit2WithItsPlace) {
  const std::string map = Write("bad.toml", "[[encoder]]\nchannel = 2\ninptu = \"x\"\n");
  const auto r = Ecs({"--controller-map", map});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr(map + ":3:1: unknown key 'inptu' in [[encoder]] (known: channel, "
                                     "input, unit,"));
}

TEST_F(ControllerCli, AMapThatDoesNotFitTheControllerIsExit2NamingThePort) {
  const std::string map = Write("other.toml", "[[pwm]]\nchannel = 1\noutput = \"torque\"\n");
  const auto r = Ecs({"--controller-map", map});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr(map + ": controller input 'setpoint_left_m' is fed by nothing"));
}

TEST_F(ControllerCli, GainsBesideAnotherControllerIsRefusedNamingBothFlags) {
  const auto r = Ecs({"--controller", "lib:./my_pd.so", "--gains", "g.toml"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("--gains g.toml gives the built-in PID's gains, but --controller "
                               "lib:./my_pd.so is another controller: drop --gains"));
}

TEST_F(ControllerCli, AControllerInOpenLoopIsRefused) {
  const auto r = Ecs({"--mode", "openloop", "--controller", "pid"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr("--controller is for --mode closedloop; open loop plays --input's "
                               "duties without a controller: drop it, or use --mode closedloop"));
}

TEST_F(ControllerCli, TheStartLineAndTheReportNameThePidAsBuiltIn) {
  const auto r = Ecs({"--report", Path("r.json")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_THAT(r.out, HasSubstr("controller pid (built-in): pid; inputs setpoint_left_m [m], "
                               "setpoint_right_m [m], wheel_left_m [m], wheel_right_m [m]; "
                               "outputs duty_left [1], duty_right [1]; map the built-in RELbot "
                               "controller map\n"));
  std::ifstream in(Path("r.json"));
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["controller"]["spec"], "pid");
  EXPECT_EQ(report["controller"]["kind"], "built-in");
  EXPECT_EQ(report["controller"]["file"], "");
  EXPECT_EQ(report["controller"]["outputs"][1]["name"], "duty_right");
  EXPECT_TRUE(report["controller"]["fault"].is_null());
  EXPECT_EQ(report["controller_map"], "the built-in RELbot controller map");
}

TEST_F(ControllerCli, HilRefusesAMapThatDoesNotParseBeforeEitherSideStarts) {
  const std::string map = Write("bad.toml", "[[pwm]]\nchannel = 7\n");
  const auto r = hiltwin::test::Run(
      {HILTWIN_BINARY, "hil", "--clock", "virtual", "--no-progress", "--controller-map", map});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr(map + ":2:11: [[pwm]] #1: channel must be an integer 1..4"));
  EXPECT_THAT(r.out, Not(HasSubstr("twin ")));
}

}  // namespace
