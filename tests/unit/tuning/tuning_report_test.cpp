// The three outputs of one TuneReport: JSON keys and values, the text with its Table 5.1-like
// table and the deciding bound, and the self-contained HTML plot.

#include "hiltwin/tuning/tuning_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tuning_fixtures.h"

namespace hiltwin::analysis {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

CandidateResult Candidate(double rate_hz, const char* verdict, std::uint64_t misses,
                          double rms_error_mm) {
  CandidateResult c;
  c.rate_hz = rate_hz;
  c.releases = 10'000;
  c.deadline_misses = misses;
  c.miss_pct = 100.0 * static_cast<double>(misses) / 10'000.0;
  c.qos_verdict = verdict;
  c.rms_error_m = rms_error_mm * 1e-3;
  return c;
}

// The thesis machine, an accuracy search on e(f) = 0.3 mm * 1000 / f and Table 5.1-like runs
// with the recommended 6250 Hz added.
TuneReport ThesisReport() {
  TuneReport r;
  r.clock = "virtual";
  r.model = "RELbot twin, rk4";
  r.input = "step";
  r.validate_seconds = 10.0;
  r.policy.tolerance_m = 0.1e-3;
  r.measured = fixtures::ThesisMachine();
  r.accuracy = AccuracyBound([](double f_hz) { return 0.3e-3 * 1000.0 / f_hz; }, r.policy);
  r.recommendation = Recommend(r.measured, r.accuracy.bound_hz, r.policy);
  r.candidates = {Candidate(1000, "PASS", 0, 0.30),      Candidate(2000, "PASS", 0, 0.15),
                  Candidate(4000, "PASS", 1, 0.08),      Candidate(6250, "FLAGGED", 12, 0.078),
                  Candidate(8000, "FLAGGED", 40, 0.075), Candidate(16000, "FLAGGED", 900, 0.2)};
  r.candidates[3].recommended = true;
  r.validation = SummariseValidation(r.candidates);
  r.machine_warnings = {
      {"governor", "CPU frequency governor is powersave", "set it to performance"}};
  return r;
}

TEST(TuneJson, CarriesTheRecommendationAndEveryFigure) {
  const nlohmann::ordered_json j = ToJson(ThesisReport());
  EXPECT_DOUBLE_EQ(j.at("max_rate_hz").get<double>(), 1e9 / 120'000.0);
  EXPECT_DOUBLE_EQ(j.at("latency_max_rate_hz").get<double>(), 1e9 / 135'000.0);
  EXPECT_EQ(j.at("recommended_rate_hz").get<double>(), 6250.0);
  EXPECT_EQ(j.at("deciding_bound"), "timing_fraction");
  EXPECT_EQ(j.at("deciding_reason"),
            "75 % of the timing maximum 8333 Hz (overhead 35.0 us + compute 85.0 us)");
  EXPECT_EQ(j.at("accuracy_bound_hz").get<double>(), 3000.0);
  EXPECT_EQ(j.at("tolerance_m").get<double>(), 0.1e-3);
  EXPECT_EQ(j.at("controller_rate_hz").get<double>(), 1000.0);
  EXPECT_EQ(j.at("highest_passing_hz").get<double>(), 4000.0);
  EXPECT_EQ(j.at("error_stops_improving_hz").get<double>(), 4000.0);
  EXPECT_EQ(j.at("clock"), "virtual");
  EXPECT_EQ(j.at("validate_seconds").get<double>(), 10.0);
  const auto& measured = j.at("measured");
  EXPECT_EQ(measured.at("step_compute_us").at("mean").get<double>(), 85.0);
  EXPECT_EQ(measured.at("step_compute_us").at("p999").get<double>(), 90.0);
  EXPECT_EQ(measured.at("step_compute_us").at("count").get<std::uint64_t>(), 10'000u);
  EXPECT_EQ(measured.at("loop_overhead_us").get<double>(), 35.0);
  EXPECT_EQ(measured.at("wake_latency").size(), 2u);
  EXPECT_EQ(measured.at("wake_latency").at(1).at("rate_hz").get<double>(), 4000.0);
  EXPECT_EQ(measured.at("wake_latency").at(1).at("p999_us").get<double>(), 10.0);
  EXPECT_EQ(measured.at("injected"), false);
  EXPECT_EQ(j.at("accuracy_search").size(), 7u);
  EXPECT_EQ(j.at("machine_warnings").at(0).at("id"), "governor");
  const auto& row = j.at("candidates").at(3);
  std::vector<std::string> keys;
  for (const auto& item : row.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"rate_hz", "miss_pct", "qos_verdict", "rms_error_m",
                                            "releases", "deadline_misses", "recommended"}));
  EXPECT_EQ(row.at("rate_hz").get<double>(), 6250.0);
  EXPECT_EQ(row.at("deadline_misses").get<std::uint64_t>(), 12u);
  EXPECT_EQ(row.at("qos_verdict"), "FLAGGED");
  EXPECT_EQ(row.at("recommended"), true);
}

TEST(TuneJson, AbsentOptionalsAreNull) {
  TuneReport r = ThesisReport();
  r.recommendation.accuracy_bound_hz.reset();
  r.validation = {};
  const nlohmann::ordered_json j = ToJson(r);
  EXPECT_TRUE(j.at("accuracy_bound_hz").is_null());
  EXPECT_TRUE(j.at("highest_passing_hz").is_null());
  EXPECT_TRUE(j.at("error_stops_improving_hz").is_null());
}

TEST(TuneText, ShowsTheBoundsTheDecisionAndTheTable) {
  const std::string text = FormatTuneText(ThesisReport());
  EXPECT_THAT(text,
              HasSubstr("Recommendation: 6250 Hz (decided by: 75 % of the timing maximum 8333 Hz "
                        "(overhead 35.0 us + compute 85.0 us))"));
  EXPECT_THAT(text, HasSubstr("timing maximum            8333 Hz"));
  EXPECT_THAT(text, HasSubstr("accuracy bound            3000 Hz"));
  EXPECT_THAT(text, HasSubstr("  rate [Hz]   misses [%]   QoS       RMS error [mm]\n"));
  EXPECT_THAT(text, HasSubstr("       1000        0.000   PASS               0.300\n"));
  EXPECT_THAT(text, HasSubstr("       4000        0.010   PASS               0.080\n"));
  EXPECT_THAT(text,
              HasSubstr("       6250        0.120   FLAGGED            0.078   <- recommended\n"));
  EXPECT_THAT(text, HasSubstr("highest rate passing QoS: 4000 Hz"));
  EXPECT_THAT(text, HasSubstr("the error stops improving at 4000 Hz"));
  EXPECT_THAT(text, HasSubstr("warning [governor]: CPU frequency governor is powersave"));
  EXPECT_THAT(text, HasSubstr("advice: set it to performance"));
}

TEST(TuneText, SaysWhenNothingPassedAndTheErrorStillImproves) {
  TuneReport r = ThesisReport();
  r.validation = {};
  r.recommendation.accuracy_bound_hz.reset();
  const std::string text = FormatTuneText(r);
  EXPECT_THAT(text, HasSubstr("highest rate passing QoS: none passed"));
  EXPECT_THAT(text, HasSubstr("the error still improves at the highest candidate"));
  EXPECT_THAT(text, HasSubstr("accuracy bound               none"));
}

class TunePlot : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("hiltwin_tune_plot_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(TunePlot, WritesASelfContainedPageWithBothCharts) {
  const std::string path = (dir_ / "tune.html").string();
  WriteTunePlotHtml(ThesisReport(), path);
  std::ifstream in(path);
  ASSERT_TRUE(in.good());
  std::stringstream html;
  html << in.rdbuf();
  const std::string page = html.str();
  EXPECT_THAT(page, HasSubstr("<svg"));
  EXPECT_THAT(page, HasSubstr("deadline misses against rate"));
  EXPECT_THAT(page, HasSubstr("RMS error as the controller sees it"));
  EXPECT_THAT(page, HasSubstr("recommended 6250 Hz"));
  EXPECT_THAT(page, HasSubstr("accuracy bound 3000 Hz"));
  EXPECT_THAT(page, HasSubstr("timing maximum 8333 Hz"));
  EXPECT_THAT(page, HasSubstr("tolerance 0.100 mm"));
  EXPECT_THAT(page, HasSubstr(">0</text>"));  // the zero-miss runs, labelled on the floor
  EXPECT_THAT(page, Not(HasSubstr("<script")));
  EXPECT_THAT(page, Not(HasSubstr("http")));
}

TEST_F(TunePlot, NamesThePathItCannotWrite) {
  const std::string path = (dir_ / "missing" / "tune.html").string();
  try {
    WriteTunePlotHtml(ThesisReport(), path);
    FAIL() << "wrote into a missing directory";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
  }
}

}  // namespace
}  // namespace hiltwin::analysis
