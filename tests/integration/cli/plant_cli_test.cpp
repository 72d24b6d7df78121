// End-to-end tests of `hiltwin run --plant --plant-map`: virtual-clock runs are exact, so logs
// are compared value by value (with the RELbot's own map) or against analytic answers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fakes/csv_table.h"
#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "plant_test_support.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class PlantCli : public hiltwin::test::TempDirTest {
 protected:



  static hiltwin::test::RunResult Run(std::vector<std::string> extra) {
    std::vector<std::string> argv = {HILTWIN_BINARY, "run", "--no-progress", "--clock", "virtual"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return hiltwin::test::Run(argv);
  }

  static nlohmann::json ReadJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }

};

TEST_F(PlantCli, TheRelbotsShippedMapGivesTheSameLogAsItsBuiltInOne) {
  const auto built_in = Run({"--duration", "2", "--log", Path("a.csv")});
  const auto shipped = Run({"--duration", "2", "--log", Path("b.csv"), "--plant", "relbot",
                            "--plant-map", HILTWIN_RELBOT_MAP_TOML, "--report", Path("r.json")});
  ASSERT_EQ(built_in.exit_code, 0) << built_in.err;
  ASSERT_EQ(shipped.exit_code, 0) << shipped.err;
  const hiltwin::test::CsvTable a = hiltwin::test::ReadCsvTable(Path("a.csv"));
  const hiltwin::test::CsvTable b = hiltwin::test::ReadCsvTable(Path("b.csv"));
  EXPECT_EQ(a.columns, b.columns);
  ASSERT_EQ(a.rows.size(), 8000U);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  const auto enc = static_cast<std::size_t>(
      std::find(a.columns.begin(), a.columns.end(), "enc_left") - a.columns.begin());
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    // Same model values; counts may differ by the last ulp of counts per metre only at an
    // exact count boundary.
    ASSERT_EQ(a.rows[i][3], b.rows[i][3]) << "row " << i;
    ASSERT_NEAR(a.rows[i][enc], b.rows[i][enc], 1.0) << "row " << i;
  }
  EXPECT_GT(std::abs(a.LastRow().at("wheel_left_m")), 0.05);  // the robot moved
  const nlohmann::json report = ReadJson(Path("r.json"));
  EXPECT_EQ(report["plant"], "relbot");
  EXPECT_EQ(report["plant map"], HILTWIN_RELBOT_MAP_TOML);
  EXPECT_EQ(report["integrator"], "rk4");
}

TEST_F(PlantCli, AnUnknownPlantListsTheKnownOnes) {
  const auto r = Run({"--plant", "pendulum"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("--plant pendulum: no such plant"), HasSubstr("relbot"),
                           HasSubstr("fmu:PATH.fmu")));
}

TEST_F(PlantCli, ABadMapIsRefusedWithItsLineBeforeAnythingRuns) {
  const std::string map = Write("bad.toml",
                                "[[pwm]]\nchannel = 2\ninput = \"duty_left\"\n"
                                "[[pwm]]\nchannel = 1\ninput = \"wheel_right_m\"\n");
  const auto r = Run({"--plant-map", map, "--log", Path("never.csv")});
  EXPECT_EQ(r.exit_code, 2);
  // The line and column of the input key at fault, not of its [[pwm]] header (line 4).
  EXPECT_THAT(r.err, AllOf(HasSubstr(map + ":6:9: "), HasSubstr("'wheel_right_m' is an output")));
  EXPECT_FALSE(fs::exists(Path("never.csv")));
  const std::string unset = Write("unset.toml", "[[pwm]]\nchannel = 2\ninput = \"duty_left\"\n");
  EXPECT_THAT(Run({"--plant-map", unset}).err,
              HasSubstr("plant input 'duty_right' is driven by no PWM channel"));
}

TEST_F(PlantCli, AReversedChannelDrivesTheWheelBackwards) {
  std::ifstream in(HILTWIN_RELBOT_MAP_TOML);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string marker = "input = \"duty_left\"";
  text.replace(text.find(marker), marker.size(), marker + "\nreverse = true");
  const std::string map = Write("reversed.toml", text);
  const auto normal = Run({"--duration", "2", "--log", Path("n.csv")});
  const auto reversed = Run({"--duration", "2", "--log", Path("r.csv"), "--plant-map", map});
  ASSERT_EQ(reversed.exit_code, 0) << reversed.err;
  const auto n = hiltwin::test::ReadCsvTable(Path("n.csv")).rows;
  const auto r = hiltwin::test::ReadCsvTable(Path("r.csv")).rows;
  ASSERT_EQ(n.size(), r.size());
  for (std::size_t i = 0; i < n.size(); i += 97) {
    ASSERT_EQ(r[i][1], -n[i][1]) << "row " << i;  // duty_left as the plant received it
  }
}

}  // namespace
