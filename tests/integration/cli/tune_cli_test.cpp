// End-to-end tests of `hiltwin tune`: exit 2 with a message for every bad input the issue
// names, the whole procedure on the virtual clock with the thesis's injected costs (exact and
// repeatable, JSON, text table and HTML plot), and a short real-clock tune.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;

hiltwin::test::RunResult Tune(std::vector<std::string> extra, int timeout_ms = 240'000) {
  std::vector<std::string> argv = {HILTWIN_BINARY, "tune", "--no-progress"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return hiltwin::test::Run(argv, timeout_ms);
}

/// The thesis's costs (§3.8.2: overhead 35 us, compute 85 us) on the virtual clock, short runs.
std::vector<std::string> ThesisVirtual(std::vector<std::string> extra) {
  std::vector<std::string> argv = {"--clock",
                                   "virtual",
                                   "--inject-compute-us",
                                   "85",
                                   "--inject-overhead-us",
                                   "35",
                                   "--inject-latency-us",
                                   "0",
                                   "--validate-seconds",
                                   "3"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return argv;
}

struct TuneBadInput {
  std::vector<std::string> args;
  std::string says;  ///< a part of the message
};

TEST(TuneCli, BadInputExitsTwoAndSaysWhatIsWrong) {
  const std::vector<TuneBadInput> cases = {
      {{"--controller-rate", "0"}, "--controller-rate 0"},
      {{"--controller-rate", "-1000"}, "--controller-rate -1000"},
      {{"--candidates", ""}, "--candidates"},
      {{"--candidates", "4000,2000"}, "ascending"},
      {{"--candidates", "1000,60000"}, "50000"},
      {{"--tolerance-m", "0"}, "--tolerance-m 0"},
      {{"--tolerance-m", "-0.001"}, "--tolerance-m"},
      {{"--inject-compute-us", "85"}, "--clock virtual"},
  };
  for (const TuneBadInput& c : cases) {
    const hiltwin::test::RunResult r = Tune(c.args);
    std::string joined;
    for (const std::string& a : c.args) joined += a + " ";
    EXPECT_EQ(r.exit_code, 2) << joined << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << joined << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << joined;  // refused before anything was measured
  }
}

TEST(TuneCli, HelpNamesEveryFlagOfTheIssue) {
  const hiltwin::test::RunResult r = hiltwin::test::Run({HILTWIN_BINARY, "tune", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--controller-rate", "--tolerance-m", "--candidates",
                           "--validate-seconds", "--clock", "--json", "--plot"}) {
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
  }
}

class TuneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hiltwin_tune_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(TuneFiles, TheVirtualProcedureIsExactRepeatableAndWritesItsPlot) {
  const hiltwin::test::RunResult a = Tune(ThesisVirtual({"--json", "--plot", Path("tune.html")}));
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const nlohmann::json j = nlohmann::json::parse(a.out);
  EXPECT_NEAR(j.at("max_rate_hz").get<double>(), 1e6 / 120.0, 1e-6);
  EXPECT_EQ(j.at("recommended_rate_hz").get<double>(), 6250.0);
  EXPECT_EQ(j.at("deciding_bound"), "timing_fraction");
  ASSERT_FALSE(j.at("accuracy_bound_hz").is_null());
  const nlohmann::json& candidates = j.at("candidates");
  ASSERT_EQ(candidates.size(), 6U);
  std::vector<double> rates;
  for (const nlohmann::json& c : candidates) {
    rates.push_back(c.at("rate_hz").get<double>());
    EXPECT_TRUE(c.contains("miss_pct") && c.contains("qos_verdict") && c.contains("rms_error_m"));
    const bool fits = c.at("rate_hz").get<double>() <= 1e6 / 120.0;
    EXPECT_EQ(c.at("qos_verdict"), fits ? "PASS" : "FLAGGED") << c.dump();
    EXPECT_EQ(c.at("miss_pct").get<double>(), fits ? 0.0 : 100.0) << c.dump();
  }
  EXPECT_EQ(rates, (std::vector<double>{1000, 2000, 4000, 6250, 8000, 16000}));
  EXPECT_EQ(j.at("highest_passing_hz").get<double>(), 8000.0);
  // The same command again gives the same document, byte for byte.
  const hiltwin::test::RunResult b = Tune(ThesisVirtual({"--json"}));
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(a.out, b.out);
  std::ifstream html(Path("tune.html"));
  std::stringstream page;
  page << html.rdbuf();
  EXPECT_NE(page.str().find("<svg"), std::string::npos);
  EXPECT_EQ(page.str().find("<script"), std::string::npos);
}

TEST(TuneCli, TheTextReportHasTheValidationTableAndNamesTheDecidingBound) {
  const hiltwin::test::RunResult r = Tune(ThesisVirtual({}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("6250"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("75 %"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FLAGGED"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("16000"), std::string::npos) << r.out;
}

TEST(TuneCli, AMachineTooSlowForTheControllerRateExitsThree) {
  // 300 us of work and 1 ms of wake-up latency: the latency-aware maximum is 1 / 1.3 ms =
  // 769 Hz, below the 1 kHz controller, so no rate can answer every controller sample.
  const hiltwin::test::RunResult r = Tune(
      {"--clock", "virtual", "--inject-compute-us", "250", "--inject-overhead-us", "50",
       "--inject-latency-us", "1000", "--validate-seconds", "0.5", "--candidates", "1000,2000"});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("769"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("below the controller"), std::string::npos) << r.err;
}

TEST(TuneCli, OnTheRealClockItMeasuresThisMachineAndValidatesEveryCandidate) {
  const hiltwin::test::RunResult r =
      Tune({"--json", "--candidates", "1000,2000", "--validate-seconds", "0.3", "--latency-seconds",
            "0.2", "--priority", "0"});
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;  // a stalled VM may flag it
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j.at("measured").at("step_compute_us").at("mean").get<double>(), 0.0);
  EXPECT_GT(j.at("max_rate_hz").get<double>(), 0.0);
  EXPECT_GE(j.at("candidates").size(), 2U);
  EXPECT_FALSE(j.at("measured").at("injected").get<bool>());
}

TEST_F(TuneFiles, OnTheRealClockSigintStopsTheProcedureAndRecommendsNothing) {
  // Without --no-progress and without a terminal, tune prints one line per step on stderr.
  hiltwin::kernel_glue::Process tune = hiltwin::test::Spawn(
      {HILTWIN_BINARY, "tune", "--candidates", "1000,2000", "--validate-seconds", "10",
       "--latency-seconds", "0.2", "--priority", "0"},
      Path("out.txt"));
  bool validating = false;
  for (int i = 0; i < 600 && !validating; ++i) {  // up to 60 s for the measuring steps
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::ifstream err(Path("out.txt.err"));
    std::stringstream text;
    text << err.rdbuf();
    validating = text.str().find("validating 1000 Hz") != std::string::npos;
  }
  ASSERT_TRUE(validating) << "tune never reached its first validation run";
  ASSERT_EQ(kill(tune.pid(), SIGINT), 0);
  const auto status = tune.WaitFor(std::chrono::seconds(20));
  ASSERT_TRUE(status.has_value()) << "still running 20 s after SIGINT";
  EXPECT_TRUE(status->exited && status->code == 4) << status->Describe();
  std::ifstream err(Path("out.txt.err"));
  std::stringstream text;
  text << err.rdbuf();
  EXPECT_NE(text.str().find("stopped by SIGINT"), std::string::npos) << text.str();
  std::ifstream out(Path("out.txt"));
  std::stringstream report;
  report << out.rdbuf();
  EXPECT_EQ(report.str().find("Recommendation"), std::string::npos) << report.str();
}

}  // namespace
