// `hiltwin run --plant msd20sim`: the hand-written 20-sim class (plants/msd20sim) through the
// twin in virtual time, against the mass-spring-damper's analytic answer, and the rate check.
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

class TwentySimCli : public hiltwin::test::TempDirTest {
 protected:
  static hiltwin::test::RunResult Run(std::vector<std::string> extra) {
    std::vector<std::string> argv = {HILTWIN_BINARY, "run",    "--no-progress", "--clock",
                                     "virtual",      "--plant", "msd20sim",     "--plant-map",
                                     HILTWIN_MSD20SIM_MAP};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return hiltwin::test::Run(argv);
  }
};

TEST_F(TwentySimCli, RunsAtItsStepAndRingsDownAsTheAnalyticSolution) {
  const std::string input = Path("zero.csv");
  std::ofstream(input) << "time,left,right\n0,0,0\n100,0,0\n";
  const auto r = Run({"--rate", "1000", "--duration", "3", "--input", input, "--log",
                      Path("msd.csv"), "--report", Path("r.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const hiltwin::test::CsvTable log = hiltwin::test::ReadCsvTable(Path("msd.csv"));
  ASSERT_EQ(log.rows.size(), 3000U);
  EXPECT_EQ(std::vector<std::string>(log.columns.begin(), log.columns.begin() + 5),
            (std::vector<std::string>{"time_s", "force_n", "position_m", "velocity_m_per_s",
                                      "enc_position"}));
  // m x'' + c x' + k x = 0 from x0 = 0.05 m at rest; m = 1 kg, k = 100 N/m, c = 4 N s/m.
  // RK4 at 1 ms is within 1e-9 m of it (the unit tests measured 8e-12).
  for (const std::vector<double>& row : log.rows) {
    const double t = row[0];
    const double expected = hiltwin::test::UnderdampedFreeResponseM(0.05, 1.0, 100.0, 4.0, t);
    ASSERT_NEAR(row[2], expected, 1e-9) << "t = " << t;
    ASSERT_EQ(row[4], std::floor(row[2] * 1e5) - std::floor(0.05 * 1e5)) << "t = " << t;
  }
  std::ifstream in(Path("r.json"));
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["plant kind"], "20-sim C++ class");
  EXPECT_EQ(report["verdict"], "PASS");
}

TEST_F(TwentySimCli, ARateThatIsNotTheModelsStepIsRefusedWithTheRateToUse) {
  const auto r = Run({"--rate", "4000", "--log", Path("never.csv")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("--rate 4000 Hz gives a step of 0.00025 s"),
                           HasSubstr("generated for a step of 0.001 s"),
                           HasSubstr("run at --rate 1000")));
  EXPECT_FALSE(fs::exists(Path("never.csv")));
}

TEST_F(TwentySimCli, FlagsTheGeneratedCodeCannotHonourAreRefused) {
  const auto r = Run({"--rate", "1000", "--integrator", "euler"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, AllOf(HasSubstr("--plant msd20sim"), HasSubstr("compiled in")));
}

}  // namespace
