// `hiltwin assess` as a user runs it: CSV files in, report and exit code out. Reproduces the
// thesis's worked numbers (§5.6.2, §7.4.2) from files laid out as appendix C expects.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "fakes/test_paths.h"

namespace {

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

class AssessCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* base = std::getenv("TMPDIR");
    std::string pattern =
        std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/assess-test-XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
    return Path(name);
  }

  // Runs `hiltwin assess ARGS` (with an optional environment prefix) and collects its output.
  Result Run(const std::string& args, const std::string& env = "") const {
    const std::string out = Path("stdout.txt");
    const std::string err = Path("stderr.txt");
    const std::string command = env + " '" + std::string(HILTWIN_BINARY) + "' assess " + args +
                                " >'" + out + "' 2>'" + err + "'";
    const int status = std::system(command.c_str());
    Result r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::stringstream o;
    o << std::ifstream(out).rdbuf();
    r.out = o.str();
    std::stringstream e;
    e << std::ifstream(err).rdbuf();
    r.err = e.str();
    return r;
  }

  // Appendix C layout: time, y_s (column 2), y_e (column 3). The experiment's range is
  // eps_t / Kp and y_e − y_s alternates ±e_t, so the file holds exactly the thesis's numbers.
  std::string ThesisFile(const std::string& name, double eps_t, double e_t) const {
    std::ostringstream csv;
    csv.precision(17);
    csv << "\"time\",\"20-sim position\",\"HiL position\"\n";
    const std::size_t n = 4000;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = static_cast<double>(i) / static_cast<double>(n - 1);
      const double y_e = eps_t / 0.05 * 0.5 * (1.0 - std::cos(std::numbers::pi * x));
      const double y_s = y_e + ((i % 2 == 0) ? e_t : -e_t);
      csv << static_cast<double>(i) * 2.5e-4 << ',' << y_s << ',' << y_e << '\n';
    }
    return Write(name, csv.str());
  }

  static void ExpectUsageError(const Result& r, std::initializer_list<std::string> parts) {
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    for (const std::string& part : parts) {
      EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
    }
  }

  std::filesystem::path dir_;
};

TEST_F(AssessCli, ThesisSection562HardwarePlatform) {
  const std::string file = ThesisFile("platform.csv", 0.1854, 9.101e-4);
  const Result r = Run("'" + file + "' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["time_domain"]["eps_t"].get<double>(), 0.1854, 1e-9);
  EXPECT_NEAR(j["time_domain"]["e_t"].get<double>(), 9.101e-4, 1e-9);
  EXPECT_NEAR(j["time_domain"]["k_e"].get<double>(), 0.75, 1e-12);
  EXPECT_NEAR(j["time_domain"]["eta"].get<double>(), 0.999978, 1e-6);
  EXPECT_NEAR(j["total"].get<double>(), 0.999978, 1e-6);
  EXPECT_TRUE(j["pass"].get<bool>());
}

TEST_F(AssessCli, ThesisSection742Relbot) {
  const std::string file = ThesisFile("relbot.csv", 0.1311, 0.0244);
  const Result r = Run("'" + file + "' --sim '20-sim position' --exp 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("0.970"), std::string::npos) << r.out;  // eta = 0.9706 = 97 %
  EXPECT_NE(r.out.find("97.1 %"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("PASS"), std::string::npos) << r.out;
  const Result j = Run("'" + file + "' --json");
  EXPECT_NEAR(nlohmann::json::parse(j.out)["time_domain"]["eta"].get<double>(), 0.9706, 5e-5);
}

TEST_F(AssessCli, PureDelayAcrossTwoTimeBasesScoresOneAfterCompensation) {
  std::ostringstream sim;
  std::ostringstream exp;
  sim.precision(15);
  exp.precision(15);
  sim << "time,model\n";
  exp << "time,unused,robot\n";
  auto f = [](double t) { return 0.4 * t + 0.3 * std::sin(1.7 * t) + 0.1 * std::sin(5.3 * t); };
  for (int i = 0; i <= 10000; ++i) sim << i * 1e-3 << ',' << f(i * 1e-3) << '\n';  // 0 .. 10 s
  for (int i = 0; i <= 2200; ++i) {
    const double t = 1.0 + i * 4e-3;  // 1 .. 9.8 s at 250 Hz
    exp << t << ",0," << f(t - 0.012) << '\n';
  }
  const std::string s = Write("sim.csv", sim.str());
  const std::string e = Write("exp.csv", exp.str());
  const Result r = Run("--sim '" + s + ":model' --exp '" + e + ":robot' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["delay_s"].get<double>(), 0.012, 1e-4);
  EXPECT_LT(j["time_domain"]["eta"].get<double>(), 0.9999);
  EXPECT_GT(j["time_domain_compensated"]["eta"].get<double>(), 0.99999);
  EXPECT_NEAR(j["inputs"]["overlap_s"][0].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(j["inputs"]["overlap_s"][1].get<double>(), 9.8, 1e-9);
  EXPECT_FALSE(j["inputs"]["same_time_base"].get<bool>());
  EXPECT_TRUE(j["frequency_domain"].is_null());
  EXPECT_TRUE(j.contains("performance_domain"));
}

TEST_F(AssessCli, FailVerdictStillExitsZero) {
  const std::string file = ThesisFile("bad.csv", 0.1, 0.5);  // error 5x the threshold
  const Result r = Run("'" + file + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("FAIL"), std::string::npos) << r.out;
  const Result j = Run("'" + file + "' --json");
  EXPECT_FALSE(nlohmann::json::parse(j.out)["pass"].get<bool>());
}

TEST_F(AssessCli, InputColumnGivesFrequencyDomain) {
  std::ostringstream csv;
  csv.precision(15);
  csv << "time,u,sim,exp\n";
  std::uint64_t seed = 9;
  double state = 0.0;
  for (int i = 0; i < 8192; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    const double u = static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5;
    state = 0.7 * state + 0.3 * u;
    csv << i * 1e-3 << ',' << u << ',' << state << ',' << state << '\n';
  }
  const Result r = Run("'" + Write("f.csv", csv.str()) + "' --sim sim --exp exp --input u --weights 1,0,1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j["frequency_domain"].is_object());
  EXPECT_DOUBLE_EQ(j["frequency_domain"]["eta"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["total"].get<double>(), 1.0);
}

TEST_F(AssessCli, PlotWritesAPng) {
  const std::string file = ThesisFile("p.csv", 0.2, 0.001);
  const std::string png = Path("out.png");
  const Result r = Run("'" + file + "' --plot '" + png + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_GT(std::filesystem::file_size(png), 10000u);
}

TEST_F(AssessCli, PlotWithoutGnuplotNamesThePackage) {
  const std::string file = ThesisFile("p.csv", 0.2, 0.001);
  const Result r = Run("'" + file + "' --plot '" + Path("x.png") + "'", "PATH=/nonexistent");
  ExpectUsageError(r, {"gnuplot", "gnuplot-nox"});
}

TEST_F(AssessCli, BadCellsNameFileLineColumn) {
  const std::string head = "time,sim,exp\n0,0,0\n0.1,1,1.1\n";
  ExpectUsageError(Run("'" + Write("a.csv", head + "0.2,2,x2\n") + "'"),
                   {"a.csv:4:3", "'exp'", "not a number"});
  ExpectUsageError(Run("'" + Write("b.csv", head + "0.2,nan,2\n") + "'"), {"b.csv:4:2", "NaN or Inf"});
  ExpectUsageError(Run("'" + Write("c.csv", head + "0.2,2,inf\n") + "'"), {"c.csv:4:3", "NaN or Inf"});
  ExpectUsageError(Run("'" + Write("d.csv", head + "0.1,2,2\n") + "'"), {"d.csv:4:1", "repeats"});
  ExpectUsageError(Run("'" + Write("e.csv", head + "0.05,2,2\n") + "'"), {"e.csv:4:1", "earlier than the previous row"});
  ExpectUsageError(Run("'" + Write("f.csv", "time,sim,exp\n0,0,0\n") + "'"),
                   {"f.csv:2", "1 data row", "at least two"});
  ExpectUsageError(Run("'" + Write("g.csv", head + "0.2,2\n") + "'"), {"g.csv:4", "2 cells"});
}

TEST_F(AssessCli, BadColumnsAndCurvesAreNamed) {
  const std::string file =
      Write("h.csv", "time,sim,exp\n0,0,5\n0.1,1,5\n0.2,2,5\n");
  ExpectUsageError(Run("'" + file + "' --exp robot"), {"h.csv:1", "--exp 'robot'", "no such column", "2='sim'"});
  ExpectUsageError(Run("'" + file + "' --sim 1"), {"h.csv:1", "time"});
  ExpectUsageError(Run("'" + file + "'"), {"h.csv:2-4:3", "constant"});
  // Whatever the weights: a constant experiment has no step for the performance domain either.
  ExpectUsageError(Run("'" + file + "' --weights 0,1,0"), {"h.csv:2-4:3", "constant"});
  ExpectUsageError(Run("'" + Path("missing.csv") + "'"), {"missing.csv", "cannot open"});
}

TEST_F(AssessCli, FilesWithoutCommonTimeAreRefused) {
  const std::string a = Write("early.csv", "time,y\n0,0\n1,1\n2,0\n");
  const std::string b = Write("late.csv", "time,y\n5,0\n6,1\n7,0\n");
  ExpectUsageError(Run("--sim '" + a + ":y' --exp '" + b + ":y'"),
                   {"no overlap", "early.csv:2-4:1", "[0, 2] s", "late.csv:2-4:1", "[5, 7] s",
                    "start offset"});
}

TEST_F(AssessCli, ByteOrderMarkIsReadAndShortRecordLeavesIsoNotComputed) {
  // Excel's "CSV UTF-8" starts with a byte order mark; 10 samples are too few for ISO 18571.
  std::string csv = "\xEF\xBB\xBF" "time,sim,exp\n";
  for (int i = 0; i < 10; ++i) {
    csv += std::to_string(i * 0.1) + "," + std::to_string(i + 0.01) + "," + std::to_string(i);
    csv += "\n";
  }
  const std::string file = Write("bom.csv", csv);
  const Result j = Run("'" + file + "' --sim sim --exp exp --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto report = nlohmann::json::parse(j.out);
  EXPECT_TRUE(report["cross_checks"]["iso18571"].is_null());
  EXPECT_TRUE(report["not_computed"]["iso18571"].is_string());
  EXPECT_TRUE(report["pass"].get<bool>());
  const Result text = Run("'" + file + "' --sim sim --exp exp");
  EXPECT_NE(text.out.find("ISO/TS 18571: not computed"), std::string::npos) << text.out;
}

TEST_F(AssessCli, BadFlagsAreNamed) {
  const std::string file = ThesisFile("ok.csv", 0.2, 0.001);
  ExpectUsageError(Run("'" + file + "' --weights 1,2"), {"--weights"});
  ExpectUsageError(Run("'" + file + "' --weights 0,0,0"), {"--weights"});
  ExpectUsageError(Run("'" + file + "' --weights 1,0,1"), {"frequency", "--input"});
  ExpectUsageError(Run("'" + file + "' --segment 3"), {"--segment"});
  ExpectUsageError(Run("'" + file + "' --segment 50:60"), {"--segment", "holds 0 samples"});
  ExpectUsageError(Run("'" + file + "' --eta-pass 1"), {"--eta-pass"});
  ExpectUsageError(Run("'" + file + "' --plot '" + Path("no/such/dir/x.png") + "'"),
                   {"--plot", "does not exist"});
  // The library describes the value; the command puts its flag and the value given in front.
  ExpectUsageError(Run("'" + file + "' --segment 5:2"),
                   {"--segment 5:2: segment 5 s to 2 s: the end must come after the start"});
  ExpectUsageError(Run("'" + file + "' --kp 0"), {"--kp 0: confidence interval Kp 0"});
  ExpectUsageError(Run("'" + file + "' --weights 1,0,1"),
                   {"--weights 1,0,1: the frequency domain", "no input curve given (--input)"});
  ExpectUsageError(Run("--sim 2 --exp 3"), {"--sim", "which file"});
  ExpectUsageError(Run(""), {"nothing to compare"});
}

TEST_F(AssessCli, HelpDocumentsExitCodesAndFormulas) {
  const Result r = Run("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* part : {"--sim", "--exp", "--input", "--kp", "--eta-pass", "--weights",
                           "--segment", "--json", "--plot", "Exit code: 0 whenever",
                           "eps_t = Kp*(max y_e - min y_e)"}) {
    EXPECT_NE(r.out.find(part), std::string::npos) << part;
  }
}

}  // namespace
