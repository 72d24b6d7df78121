// `hiltwin run --plant fmu:...`: FMUs compiled from C in this build (tests/fmus) run through the
// twin in virtual time, their logged outputs checked against the analytic solution; a failing
// FMU is a model fault with safe outputs and the failing call in the report; a slow one shows
// in the verdict; every refused FMU is exit 2 with its reason.
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
using hiltwin::test::CsvTable;

std::string Fmu(const std::string& name) { return std::string(HILTWIN_TEST_FMU_DIR) + "/" + name + ".fmu"; }

// Board channel 1 drives the lag's u (the profile's "right" column, thesis appendix G's
// channel1); encoder channel 1 follows y at 1000 counts per radian.
constexpr const char* kLagMap = R"(
[[pwm]]
channel = 1
input = "u"
[[encoder]]
channel = 1
output = "y"
unit = "rad"
counts_per_unit = 1000
)";

// Channel 1 drives the force at 10 N per unit duty; encoder 1 follows x at 5000 counts per m.
constexpr const char* kMsdMap = R"(
[[pwm]]
channel = 1
input = "F"
gain = 10.0
[[encoder]]
channel = 1
output = "x"
unit = "m"
counts_per_unit = 5000
)";

class FmuCli : public hiltwin::test::TempDirTest {
 protected:

  /// A constant duty on board channel 1 from t = 0.
  std::string ConstantInput(double duty) const {
    return Write("input.csv", "time,left,right\n0,0," + std::to_string(duty) + "\n100,0," +
                                  std::to_string(duty) + "\n");
  }
  static hiltwin::test::RunResult Run(std::vector<std::string> extra, bool virtual_clock = true) {
    std::vector<std::string> argv = {HILTWIN_BINARY, "run", "--no-progress"};
    if (virtual_clock) argv.insert(argv.end(), {"--clock", "virtual"});
    argv.insert(argv.end(), extra.begin(), extra.end());
    return hiltwin::test::Run(argv);
  }
  static nlohmann::json ReadJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }
  static std::size_t Column(const CsvTable& t, const std::string& name) {
    const auto it = std::find(t.columns.begin(), t.columns.end(), name);
    EXPECT_NE(it, t.columns.end()) << name;
    return static_cast<std::size_t>(it - t.columns.begin());
  }

};

TEST_F(FmuCli, AFirstOrderLagFollowsItsAnalyticStepResponse) {
  const auto r = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map", Write("lag.toml", kLagMap),
                      "--rate", "1000", "--duration", "3", "--input", ConstantInput(0.5),
                      "--log", Path("lag.csv"), "--report", Path("r.json")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("plant fmu:" + Fmu("lag") + " twin at 1000 Hz"));
  const CsvTable log = hiltwin::test::ReadCsvTable(Path("lag.csv"));
  ASSERT_EQ(log.rows.size(), 3000U);
  EXPECT_EQ(std::vector<std::string>(log.columns.begin(), log.columns.begin() + 4),
            (std::vector<std::string>{"time_s", "u", "y", "enc1"}));
  // The step reaches the plant within the twin's one-period delay (thesis §3.7): from the first
  // row whose u is 0.5 on, y(t) = K u (1 - exp(-(t - t0) / tau)) with K = 2, tau = 0.5 s, exactly
  // (the FMU integrates the held input exactly).
  std::size_t first = 0;
  while (first < log.rows.size() && log.rows[first][1] != 0.5) ++first;
  ASSERT_LE(first, 1U) << "the step arrived after more than one period";
  const double t0 = log.rows[first][0] - 1e-3;  // the step held over the row's whole step
  for (std::size_t i = first; i < log.rows.size(); ++i) {
    const double t = log.rows[i][0];
    const double expected = 2.0 * 0.5 * (1.0 - std::exp(-(t - t0) / 0.5));
    ASSERT_NEAR(log.rows[i][2], expected, 1e-12) << "t = " << t;
    ASSERT_EQ(log.rows[i][3], std::floor(log.rows[i][2] * 1000.0)) << "t = " << t;
  }
  const nlohmann::json report = ReadJson(Path("r.json"));
  EXPECT_EQ(report["plant kind"], "FMI 2.0 co-simulation");
  EXPECT_EQ(report["modelName"], "FirstOrderLag");
  EXPECT_EQ(report["verdict"], "PASS");
}

TEST_F(FmuCli, AMassSpringDamperRingsDownFromItsInitialPositionAsTheAnalyticSolution) {
  const auto r = Run({"--plant", "fmu:" + Fmu("msd"), "--plant-map", Write("msd.toml", kMsdMap),
                      "--rate", "2000", "--duration", "4", "--input", ConstantInput(0.0),
                      "--log", Path("msd.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable log = hiltwin::test::ReadCsvTable(Path("msd.csv"));
  ASSERT_EQ(log.rows.size(), 8000U);
  const std::size_t x = Column(log, "x");
  const std::size_t enc = Column(log, "enc1");
  // m x'' + c x' + k x = 0 from x0 = 0.1 m at rest: m = 1 kg, k = 40 N/m, c = 0.8 N s/m.
  for (const std::vector<double>& row : log.rows) {
    const double t = row[0];
    const double expected = hiltwin::test::UnderdampedFreeResponseM(0.1, 1.0, 40.0, 0.8, t);
    ASSERT_NEAR(row[x], expected, 1e-9) << "t = " << t;
    // An incremental encoder counts from where the mass started.
    ASSERT_EQ(row[enc], std::floor(row[x] * 5000.0) - std::floor(0.1 * 5000.0)) << "t = " << t;
  }
}

TEST_F(FmuCli, AnFmuErrorIsAModelFaultWithTheCallInTheReportAndEveryRowBeforeItKept) {
  const auto r = Run({"--plant", "fmu:" + Fmu("lag_fail"), "--plant-map",
                      Write("lag.toml", kLagMap), "--rate", "1000", "--duration", "2", "--input",
                      ConstantInput(0.5), "--log", Path("fail.csv"), "--report", Path("r.json")});
  EXPECT_EQ(r.exit_code, 1) << r.err;  // a model fault (docs/lifecycle.md)
  const nlohmann::json report = ReadJson(Path("r.json"));
  EXPECT_EQ(report["fault"]["kind"], "model_fault");
  EXPECT_EQ(report["fault"]["reason"], "fmi2DoStep returned fmi2Error");
  EXPECT_EQ(report["outputs_safe"], true);
  EXPECT_THAT(r.out + r.err, HasSubstr("fmi2DoStep returned fmi2Error"));
  const CsvTable log = hiltwin::test::ReadCsvTable(Path("fail.csv"));
  // lag_fail's fmi2DoStep answers fmi2Error from its step 100 on (counting from 0): 100 steps
  // succeeded and were logged, the fault is in cycle 100.
  EXPECT_EQ(log.rows.size(), 100U);
  EXPECT_EQ(report["fault"]["cycle"], 100);
  EXPECT_EQ(log.rows.size(), report["log_rows_written"].get<std::size_t>());
}

TEST_F(FmuCli, ASlowDoStepShowsInTheVerdict) {
  // 2 ms of work in a 1 ms period: every deadline is missed, however quiet the machine.
  const auto r = Run({"--plant", "fmu:" + Fmu("lag_slow"), "--plant-map",
                      Write("lag.toml", kLagMap), "--rate", "1000", "--duration", "0.5",
                      "--input", ConstantInput(0.5), "--report", Path("r.json")},
                     /*virtual_clock=*/false);
  EXPECT_TRUE(r.exit_code == 3 || r.exit_code == 4) << r.exit_code << r.err;
  const nlohmann::json report = ReadJson(Path("r.json"));
  EXPECT_NE(report["verdict"], "PASS");
  EXPECT_GT(report["miss_pct"].get<double>(), 50.0);
}

TEST_F(FmuCli, EveryRefusedFmuIsExitTwoWithItsReason) {
  const std::string map = Write("lag.toml", kLagMap);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bad_corrupt", "zip"},          {"bad_no_xml", "modelDescription.xml"},
      {"bad_malformed", "modelDescription.xml:"}, {"bad_fmi1", "1.0"},
      {"bad_me_only", "ModelExchange"}, {"bad_no_binary", "binaries/" HILTWIN_FMU_PLATFORM "/bad_no_binary.so"},
      {"bad_no_dostep", "fmi2DoStep"}};
  for (const auto& [name, reason] : cases) {
    const auto r = Run({"--plant", "fmu:" + Fmu(name), "--plant-map", map});
    EXPECT_EQ(r.exit_code, 2) << name << ": " << r.err;
    EXPECT_THAT(r.err, AllOf(HasSubstr("--plant fmu:" + Fmu(name)), HasSubstr(reason))) << name;
  }
  const auto missing = Run({"--plant", "fmu:" + Path("nowhere.fmu"), "--plant-map", map});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("nowhere.fmu"));
}

TEST_F(FmuCli, AMapThatDoesNotFitTheFmuSaysWhichVariableAndWhy) {
  const auto parameter = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map",
                              Write("k.toml", "[[pwm]]\nchannel = 1\ninput = \"K\"\n")});
  EXPECT_EQ(parameter.exit_code, 2);
  EXPECT_THAT(parameter.err, HasSubstr("k.toml:3:9: PWM channel input 'K' is a parameter of "
                                       "lag.fmu"));
  const auto reversed = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map",
                             Write("rev.toml", "[[pwm]]\nchannel = 1\ninput = \"y\"\n")});
  EXPECT_EQ(reversed.exit_code, 2);
  EXPECT_THAT(reversed.err, HasSubstr("'y' is an output of the plant"));
  const auto unknown = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map",
                            Write("x.toml", "[[pwm]]\nchannel = 1\ninput = \"torque\"\n")});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, AllOf(HasSubstr("'torque'"), HasSubstr("inputs: u")));
  const auto no_map = Run({"--plant", "fmu:" + Fmu("lag")});
  EXPECT_EQ(no_map.exit_code, 2);
  EXPECT_THAT(no_map.err, HasSubstr("needs --plant-map"));
  const auto config = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map", Write("l.toml", kLagMap),
                           "--integrator", "euler"});
  EXPECT_EQ(config.exit_code, 2);
  EXPECT_THAT(config.err, HasSubstr("--integrator"));
}

// The map's [inputs] constants are set while the FMU initialises: lag_steady starts in
// equilibrium with u = 0.5 (y = K u = 1) and stays there, so its encoder reads 0 all run. It
// was initialised with u = 0 and rose to 1 over the run: 1000 counts of motion nothing drove.
TEST_F(FmuCli, TheMapsConstantInputsAreSetBeforeTheFirstStep) {
  const auto r = Run({"--plant", "fmu:" + Fmu("lag_steady"), "--plant-map",
                      Write("steady.toml", "[[encoder]]\nchannel = 1\noutput = \"y\"\n"
                                           "unit = \"rad\"\ncounts_per_unit = 1000\n"
                                           "[inputs]\nu = 0.5\n"),
                      "--rate", "1000", "--duration", "0.5", "--log", Path("steady.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable log = hiltwin::test::ReadCsvTable(Path("steady.csv"));
  ASSERT_EQ(log.rows.size(), 500U);
  const std::size_t y = Column(log, "y");
  const std::size_t enc = Column(log, "enc1");
  for (const std::vector<double>& row : log.rows) {
    ASSERT_EQ(row[y], 1.0) << "t = " << row[0];
    ASSERT_EQ(row[enc], 0.0) << "t = " << row[0];
  }
}

// An FMU that fails while starting is a plant error, not a --rate one: --rate was not given.
TEST_F(FmuCli, AStartErrorNamesThePlantNotTheRate) {
  const auto r = Run({"--plant", "fmu:" + Fmu("bad_init"), "--plant-map",
                      Write("lag.toml", kLagMap)});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, AllOf(HasSubstr("hiltwin run: --plant fmu:" + Fmu("bad_init") + ": " +
                                     Fmu("bad_init") + ": fmi2ExitInitializationMode returned "
                                     "fmi2Error while starting the FMU"),
                           ::testing::Not(HasSubstr("--rate"))));
}

// A scale the board cannot follow is refused on the FMU side too (1e15 counts per radian ran
// and passed with wrapped counts).
TEST_F(FmuCli, AnEncoderScaleBeyondTheBoardIsRefused) {
  const auto r = Run({"--plant", "fmu:" + Fmu("lag"), "--plant-map",
                      Write("huge.toml", "[[pwm]]\nchannel = 1\ninput = \"u\"\n[[encoder]]\n"
                                         "channel = 1\noutput = \"y\"\nunit = \"rad\"\n"
                                         "counts_per_unit = 1e15\n")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("huge.toml:8:19: [[encoder]] #1: 1e+15 counts per rad is more "
                               "than 2.5e+07, the most counts the board emits in a second"));
}

}  // namespace
