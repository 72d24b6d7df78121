// `hiltwin test`'s pass criteria (campaign_criteria.h): every criterion judged with a figure just
// inside, exactly at and just outside its bound; the step figures on synthetic step responses
// whose overshoot and settling are known in closed form or by construction; the saturation
// share; the verdict order; and the figures read from a scenario's report and logs written to
// a temporary folder, credibility included (assess's score of two curves).
#include "hiltwin/runs/campaign_criteria.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace hiltwin::app {
// Named, not anonymous: this suite compiles in one unity unit with the other campaign tests.
namespace criteria_test {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Judge: each bound just inside, at and just outside.

struct BoundCase {
  const char* name;
  const char* unit;
  const char* relation;
  double bound;
  double inside;
  double outside;
  std::function<void(CampaignCriteria&, double)> set_bound;
  std::function<void(ScenarioMeasures&, double)> set_measured;
};

std::ostream& operator<<(std::ostream& out, const BoundCase& c) { return out << c.name; }

double Below(double x) { return std::nextafter(x, -std::numeric_limits<double>::infinity()); }
double Above(double x) { return std::nextafter(x, std::numeric_limits<double>::infinity()); }

std::vector<BoundCase> BoundCases() {
  return {
      {"tracking_max_m", "m", "<=", 0.002, Below(0.002), Above(0.002),
       [](CampaignCriteria& c, double v) { c.tracking_max_m = v; },
       [](ScenarioMeasures& m, double v) { m.tracking_max_m = v; }},
      {"tracking_rms_m", "m", "<=", 0.001, Below(0.001), Above(0.001),
       [](CampaignCriteria& c, double v) { c.tracking_rms_m = v; },
       [](ScenarioMeasures& m, double v) { m.tracking_rms_m = v; }},
      {"final_error_m", "m", "<=", 0.0005, Below(0.0005), Above(0.0005),
       [](CampaignCriteria& c, double v) { c.final_error_m = v; },
       [](ScenarioMeasures& m, double v) { m.final_error_m = v; }},
      {"settling_time_s", "s", "<=", 0.8, Below(0.8), Above(0.8),
       [](CampaignCriteria& c, double v) { c.settling_time_s = v; },
       [](ScenarioMeasures& m, double v) { m.settling_time_s = v; }},
      {"overshoot_pct", "%", "<=", 5.0, Below(5.0), Above(5.0),
       [](CampaignCriteria& c, double v) { c.overshoot_pct = v; },
       [](ScenarioMeasures& m, double v) { m.overshoot_pct = v; }},
      {"duty_saturation_pct", "%", "<=", 10.0, Below(10.0), Above(10.0),
       [](CampaignCriteria& c, double v) { c.duty_saturation_pct = v; },
       [](ScenarioMeasures& m, double v) { m.duty_saturation_pct = v; }},
      {"missed_deadlines", "1", "<=", 3.0, 2.0, 4.0,
       [](CampaignCriteria& c, double v) { c.missed_deadlines = static_cast<std::uint64_t>(v); },
       [](ScenarioMeasures& m, double v) { m.missed_deadlines = static_cast<std::uint64_t>(v); }},
      {"credibility_min", "1", ">=", 0.6, Above(0.6), Below(0.6),
       [](CampaignCriteria& c, double v) { c.credibility_min = v; },
       [](ScenarioMeasures& m, double v) { m.credibility = v; }},
  };
}

class EachBound : public ::testing::TestWithParam<BoundCase> {
 protected:
  // The one result of judging `measured` (nullopt: not measured) against the case's bound.
  [[nodiscard]] CriterionResult JudgeOne(std::optional<double> measured) const {
    const BoundCase& p = GetParam();
    CampaignCriteria criteria;
    p.set_bound(criteria, p.bound);
    ScenarioMeasures measures;
    if (measured) p.set_measured(measures, *measured);
    const std::vector<CriterionResult> results = Judge(criteria, measures);
    EXPECT_EQ(results.size(), 1U);
    return results.empty() ? CriterionResult{} : results.front();
  }
};

TEST_P(EachBound, JustInsidePasses) {
  const CriterionResult r = JudgeOne(GetParam().inside);
  EXPECT_EQ(r.name, GetParam().name);
  EXPECT_EQ(r.unit, GetParam().unit);
  EXPECT_EQ(r.relation, GetParam().relation);
  ASSERT_TRUE(r.required.has_value());
  EXPECT_EQ(*r.required, GetParam().bound);
  ASSERT_TRUE(r.measured.has_value());
  EXPECT_EQ(*r.measured, GetParam().inside);
  EXPECT_TRUE(r.passed);
}

TEST_P(EachBound, JustOutsideFails) {
  const CriterionResult r = JudgeOne(GetParam().outside);
  EXPECT_EQ(r.name, GetParam().name);
  ASSERT_TRUE(r.measured.has_value());
  EXPECT_EQ(*r.measured, GetParam().outside);
  EXPECT_FALSE(r.passed);
}

TEST_P(EachBound, ExactlyAtTheBoundPasses) { EXPECT_TRUE(JudgeOne(GetParam().bound).passed); }

TEST_P(EachBound, NotMeasuredFails) {
  const CriterionResult r = JudgeOne(std::nullopt);
  EXPECT_FALSE(r.measured.has_value());
  EXPECT_FALSE(r.passed);
}

INSTANTIATE_TEST_SUITE_P(CampaignCriteria, EachBound, ::testing::ValuesIn(BoundCases()),
                         [](const ::testing::TestParamInfo<BoundCase>& param_info) {
                           return std::string(param_info.param.name);
                         });

CriterionResult JudgeVerdict(const std::string& required, const std::string& measured) {
  CampaignCriteria criteria;
  criteria.verdict = required;
  ScenarioMeasures measures;
  measures.verdict = measured;
  const std::vector<CriterionResult> results = Judge(criteria, measures);
  EXPECT_EQ(results.size(), 1U);
  return results.empty() ? CriterionResult{} : results.front();
}

// The ninth criterion: a text, judged on the order PASS < FLAGGED < ABORTED < NONE < "".
TEST(CampaignVerdict, JustInsideAtAndJustOutsideItsBound) {
  const CriterionResult inside = JudgeVerdict("FLAGGED", "PASS");
  EXPECT_EQ(inside.name, "verdict");
  EXPECT_EQ(inside.unit, "");
  EXPECT_EQ(inside.relation, "at most");
  EXPECT_EQ(inside.required_text, "FLAGGED");
  EXPECT_EQ(inside.measured_text, "PASS");
  EXPECT_FALSE(inside.required.has_value());
  EXPECT_TRUE(inside.passed);
  EXPECT_TRUE(JudgeVerdict("FLAGGED", "FLAGGED").passed);
  EXPECT_FALSE(JudgeVerdict("FLAGGED", "ABORTED").passed);
  EXPECT_TRUE(JudgeVerdict("PASS", "PASS").passed);
  EXPECT_FALSE(JudgeVerdict("PASS", "FLAGGED").passed);
  EXPECT_FALSE(JudgeVerdict("PASS", "").passed);  // a side without a report
  EXPECT_FALSE(JudgeVerdict("FLAGGED", "NONE").passed);
}

TEST(CampaignJudge, OneResultPerBoundInTheHeadersOrder) {
  CampaignCriteria c;
  c.credibility_min = 0.5;  // set in a different order than judged
  c.missed_deadlines = 0;
  c.tracking_max_m = 1.0;
  c.verdict = "PASS";
  c.duty_saturation_pct = 1.0;
  c.overshoot_pct = 1.0;
  c.settling_time_s = 1.0;
  c.final_error_m = 1.0;
  c.tracking_rms_m = 1.0;
  std::vector<std::string> names;
  for (const CriterionResult& r : Judge(c, ScenarioMeasures{})) names.push_back(r.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{
                "verdict", "tracking_max_m", "tracking_rms_m", "final_error_m", "settling_time_s",
                "overshoot_pct", "duty_saturation_pct", "missed_deadlines", "credibility_min"}));
  EXPECT_TRUE(Judge(CampaignCriteria{}, ScenarioMeasures{}).empty());
}

TEST(CampaignJudge, AnUnsettledStepFailsAnySettlingBound) {
  CampaignCriteria c;
  c.settling_time_s = 1e9;
  ScenarioMeasures m;
  m.settling_time_s = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(Judge(c, m).at(0).passed);
}

TEST(CampaignVerdict, WorseVerdictOrdersPassFlaggedAbortedNoneMissing) {
  const std::vector<std::string> order{"PASS", "FLAGGED", "ABORTED", "NONE", ""};
  for (std::size_t i = 0; i < order.size(); ++i) {
    for (std::size_t j = 0; j < order.size(); ++j) {
      const std::string& worse = order[std::max(i, j)];
      EXPECT_EQ(WorseVerdict(order[i], order[j]), worse) << order[i] << " vs " << order[j];
    }
  }
}

TEST(CampaignCriteriaLog, OnlyLogFiguresNeedTheLog) {
  CampaignCriteria c;
  c.verdict = "PASS";
  c.tracking_max_m = 0.01;
  c.tracking_rms_m = 0.01;
  c.final_error_m = 0.01;
  c.missed_deadlines = 0;
  EXPECT_FALSE(NeedsLog(c));
  const std::vector<std::function<void(CampaignCriteria&)>> log_bounds{
      [](CampaignCriteria& k) { k.settling_time_s = 1.0; },
      [](CampaignCriteria& k) { k.overshoot_pct = 1.0; },
      [](CampaignCriteria& k) { k.duty_saturation_pct = 1.0; },
      [](CampaignCriteria& k) { k.credibility_min = 0.6; }};
  for (const auto& set : log_bounds) {
    CampaignCriteria with = c;
    set(with);
    EXPECT_TRUE(NeedsLog(with));
  }
}

// ---------------------------------------------------------------------------------------------
// MeasureStep and DutySaturationPct on synthetic signals.

struct StepSignal {
  std::vector<double> time_s, setpoint_m, position_m;
};

// A step of `step_m` at `step_time_s` on a 1 ms grid of `duration_s`, the position given by
// `response(t since the step)` as a fraction of the step (0 before it).
StepSignal MakeStep(double step_time_s, double step_m, double duration_s,
                    const std::function<double(double)>& response) {
  StepSignal s;
  const auto samples = static_cast<std::size_t>(std::lround(duration_s / 0.001)) + 1;
  for (std::size_t i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) * 0.001;
    const bool after = t >= step_time_s - 1e-12;
    s.time_s.push_back(t);
    s.setpoint_m.push_back(after ? step_m : 0.0);
    s.position_m.push_back(after ? step_m * response(t - step_time_s) : 0.0);
  }
  return s;
}

constexpr double kZeta = 0.3;
constexpr double kOmegaN = 10.0;  // rad/s

// Unit step response of 1 / (s²/ω² + 2ζs/ω + 1), underdamped.
double SecondOrder(double t) {
  const double root = std::sqrt(1.0 - kZeta * kZeta);
  const double omega_d = kOmegaN * root;
  return 1.0 - std::exp(-kZeta * kOmegaN * t) / root * std::sin(omega_d * t + std::acos(kZeta));
}

TEST(CampaignStep, SecondOrderOvershootAndSettlingMatchTheClosedForm) {
  const StepSignal s = MakeStep(1.0, 0.2, 4.0, SecondOrder);
  const StepResponse r = MeasureStep(s.time_s, s.setpoint_m, s.position_m, 2.0);
  EXPECT_NEAR(r.step_time_s, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.step_m, 0.2);
  // Peak overshoot exp(-πζ/√(1-ζ²)) = 37.23 %; the 1 ms grid misses the peak by < 0.01 %.
  const double overshoot_pct =
      100.0 * std::exp(-std::numbers::pi * kZeta / std::sqrt(1.0 - kZeta * kZeta));
  EXPECT_NEAR(r.overshoot_pct, overshoot_pct, 0.01);
  // The k-th extremum (t_k = kπ/ω_d) lies exp(-ζω t_k)·100 % off the target: 5.2 % for k = 3
  // (outside the 2 % band), 1.9 % for k = 4: the response settles between the two.
  const double omega_d = kOmegaN * std::sqrt(1.0 - kZeta * kZeta);
  EXPECT_GT(r.settling_time_s, 3.0 * std::numbers::pi / omega_d);
  EXPECT_LT(r.settling_time_s, 4.0 * std::numbers::pi / omega_d);
}

TEST(CampaignStep, SettlesAtTheFirstSampleAfterTheLastOutsideTheBand) {
  // Step 0 -> 1 at row 2 (t = 0.2); band 10 %: rows 2..6 lie outside, row 7 inside, row 8 is
  // outside again (1.12), from row 9 on all inside: settled at row 9, 0.7 s after the step.
  const std::vector<double> time_s{0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1};
  const std::vector<double> setpoint{0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  const std::vector<double> position{0, 0, 0.0, 0.5, 0.8, 1.15, 1.2, 1.05, 1.12, 1.0, 0.95, 1.02};
  const StepResponse r = MeasureStep(time_s, setpoint, position, 10.0);
  EXPECT_DOUBLE_EQ(r.step_time_s, 0.2);
  EXPECT_DOUBLE_EQ(r.settling_time_s, 0.9 - 0.2);
  EXPECT_NEAR(r.overshoot_pct, 20.0, 1e-9);
  // A band of 25 %: only rows 2 and 3 lie outside, settled at row 4.
  EXPECT_DOUBLE_EQ(MeasureStep(time_s, setpoint, position, 25.0).settling_time_s, 0.4 - 0.2);
}

TEST(CampaignStep, AResponseThatNeverSettlesTakesForever) {
  const StepSignal s =
      MakeStep(0.5, 0.1, 3.0, [](double t) { return 1.0 + 0.1 * std::sin(20.0 * t); });
  const StepResponse r = MeasureStep(s.time_s, s.setpoint_m, s.position_m, 2.0);
  EXPECT_TRUE(std::isinf(r.settling_time_s));
  EXPECT_GT(r.settling_time_s, 0.0);
  EXPECT_NEAR(r.overshoot_pct, 10.0, 0.01);
  // Only the last sample outside the band is enough.
  std::vector<double> position = s.position_m;
  for (std::size_t i = 600; i < position.size(); ++i) position[i] = 0.1;
  position.back() = 0.103;
  EXPECT_TRUE(std::isinf(MeasureStep(s.time_s, s.setpoint_m, position, 2.0).settling_time_s));
}

TEST(CampaignStep, ANegativeStepMeasuresItsOvershootBelowTheTarget) {
  // 0.2 -> 0 at t = 1; the wheel goes down to -0.01 m (5 % beyond), then back to 0.
  std::vector<double> time_s, setpoint, position;
  for (int i = 0; i <= 30; ++i) {
    const double t = 0.1 * i;
    time_s.push_back(t);
    setpoint.push_back(i < 10 ? 0.2 : 0.0);
    position.push_back(i < 12 ? 0.2 : (i == 14 ? -0.01 : (i < 14 ? 0.1 : 0.0)));
  }
  const StepResponse r = MeasureStep(time_s, setpoint, position, 2.0);
  EXPECT_DOUBLE_EQ(r.step_m, -0.2);
  EXPECT_DOUBLE_EQ(r.step_time_s, 1.0);
  EXPECT_NEAR(r.overshoot_pct, 5.0, 1e-9);
  EXPECT_NEAR(r.settling_time_s, 1.5 - 1.0, 1e-12);  // row 15 is the first inside for good
}

TEST(CampaignStep, AMonotoneApproachHasNoOvershoot) {
  const StepSignal s = MakeStep(0.5, 0.1, 3.0, [](double t) { return 1.0 - std::exp(-t / 0.1); });
  const StepResponse r = MeasureStep(s.time_s, s.setpoint_m, s.position_m, 2.0);
  EXPECT_EQ(r.overshoot_pct, 0.0);
  // 2 % of the step is left after τ·ln 50 = 0.391 s: the first 1 ms sample past it.
  EXPECT_NEAR(r.settling_time_s, 0.1 * std::log(50.0), 0.001);
}

TEST(CampaignStep, ACsvStepAtARepeatedTimeAndTheTargetIsTheLastSetpoint) {
  // A setpoint file's step: two knots at t = 1. The target is the setpoint's last value.
  const std::vector<double> time_s{0.0, 1.0, 1.0, 2.0, 3.0};
  const std::vector<double> setpoint{0.0, 0.0, 1.0, 1.0, 1.0};
  const std::vector<double> position{0.0, 0.0, 0.0, 1.1, 1.0};
  const StepResponse r = MeasureStep(time_s, setpoint, position, 2.0);
  EXPECT_DOUBLE_EQ(r.step_time_s, 1.0);
  EXPECT_DOUBLE_EQ(r.step_m, 1.0);
  EXPECT_NEAR(r.overshoot_pct, 10.0, 1e-9);
  EXPECT_DOUBLE_EQ(r.settling_time_s, 2.0);
}

TEST(CampaignStep, BadInputIsRefused) {
  const std::vector<double> t{0.0, 1.0, 2.0};
  const std::vector<double> flat{0.5, 0.5, 0.5};
  const std::vector<double> step{0.0, 1.0, 1.0};
  EXPECT_THROW((void)MeasureStep(t, flat, flat, 2.0), std::invalid_argument);  // no step
  EXPECT_THROW((void)MeasureStep(t, step, std::vector<double>{0.0, 1.0}, 2.0),
               std::invalid_argument);
  const std::vector<double> one{0.0};
  EXPECT_THROW((void)MeasureStep(one, one, one, 2.0), std::invalid_argument);
}

TEST(CampaignDuty, SaturationIsTheShareOfSamplesWithEitherWheelAtFullDuty) {
  // 10 samples: rows 0, 1, 2 left at +-1, row 5 right at -0.9995 (>= 0.999), row 7 at 0.998
  // (not saturated): 4 of 10.
  const std::vector<double> left{1.0, -1.0, 1.0, 0.2, 0.0, 0.3, 0.1, 0.998, 0.0, 0.0};
  const std::vector<double> right{0.0, 0.0, 1.0, 0.2, 0.0, -0.9995, 0.1, 0.0, 0.0, 0.5};
  EXPECT_DOUBLE_EQ(DutySaturationPct(left, right), 40.0);
  // Against a limit of 0.5: also row 9 (0.5), and row 7 (0.998): 6 of 10.
  EXPECT_DOUBLE_EQ(DutySaturationPct(left, right, 0.5), 60.0);
  EXPECT_DOUBLE_EQ(DutySaturationPct({}, {}), 0.0);
  const std::vector<double> just_below{0.9989};
  const std::vector<double> at{0.999};
  EXPECT_DOUBLE_EQ(DutySaturationPct(just_below, just_below), 0.0);
  EXPECT_DOUBLE_EQ(DutySaturationPct(at, just_below), 100.0);
  EXPECT_DOUBLE_EQ(DutySaturationPct(just_below, at), 100.0);
}

// ---------------------------------------------------------------------------------------------
// The figures read from a scenario's files.

class CampaignMeasure : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_campaign_criteria_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] fs::path Write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  // A closed-loop ECS log, 1 ms rows for 2 s, both setpoints stepping at 0.5 s: left to 0.1 m
  // (first order, τ = 0.1 s: settles 0.391 s after the step), right to 0.05 m (τ = 0.05 s and a
  // one-row spike 5 % beyond its target at 0.6 s). Rows 0..99 have the left duty at 1.0. The
  // error columns hold 0.5, a figure the measures must not take (tracking comes from the
  // report).
  [[nodiscard]] fs::path WriteClosedLoopLog() const {
    std::string text =
        "time_s,setpoint_left_m,setpoint_right_m,wheel_left_m,wheel_right_m,error_left_m,"
        "error_right_m,duty_left,duty_right,enc_left,enc_right,cycle\n";
    for (int i = 0; i <= 2000; ++i) {
      const double t = 0.001 * i;
      const bool after = i >= 500;
      const double since = t - 0.5;
      const double left = after ? 0.1 * (1.0 - std::exp(-since / 0.1)) : 0.0;
      double right = after ? 0.05 * (1.0 - std::exp(-since / 0.05)) : 0.0;
      if (i == 600) right = 0.05 * 1.05;
      char row[300];
      std::snprintf(row, sizeof row, "%.3f,%.17g,%.17g,%.17g,%.17g,0.5,0.5,%g,0.1,0,0,%d\n", t,
                    after ? 0.1 : 0.0, after ? 0.05 : 0.0, left, right, i < 100 ? 1.0 : 0.2, i);
      text += row;
    }
    return Write("ecs.csv", text);
  }

  // A log of `column` = amplitude·sin(2π t) over [0, 2] s at `step_s`, and `other` beside it.
  [[nodiscard]] fs::path WriteSine(const std::string& name, const std::string& column,
                                   double step_s, double amplitude) const {
    std::string text = "time_s,other," + column + "\n";
    const auto rows = static_cast<int>(std::lround(2.0 / step_s));
    for (int i = 0; i <= rows; ++i) {
      const double t = step_s * i;
      char row[120];
      std::snprintf(row, sizeof row, "%.6f,0,%.17g\n", t,
                    amplitude * std::sin(2.0 * std::numbers::pi * t));
      text += row;
    }
    return Write(name, text);
  }

  fs::path dir_;
};

nlohmann::json HilReport() {
  return nlohmann::json::parse(R"({
    "exit_code": 3, "wire": "wire:x", "mode": "closedloop",
    "tracking_error_max_m": {"left": 0.002, "right": 0.003},
    "tracking_error_rms_m": 0.001,
    "final_error_m": 0.0005,
    "twin": {"verdict": "PASS", "deadline_misses": 2},
    "ecs": {"verdict": "FLAGGED", "deadline_misses": 5}
  })");
}

TEST_F(CampaignMeasure, HilTakesTrackingFromTheReportAndTheStepFromTheLog) {
  CampaignCriteria c;
  c.settling_time_s = 0.5;
  c.overshoot_pct = 6.0;
  c.duty_saturation_pct = 5.0;
  const ScenarioMeasures m = MeasureHil(HilReport(), WriteClosedLoopLog(), c);
  EXPECT_EQ(m.verdict, "FLAGGED");
  ASSERT_TRUE(m.tracking_max_m && m.tracking_rms_m && m.final_error_m && m.missed_deadlines);
  EXPECT_DOUBLE_EQ(*m.tracking_max_m, 0.003);
  EXPECT_DOUBLE_EQ(*m.tracking_rms_m, 0.001);
  EXPECT_DOUBLE_EQ(*m.final_error_m, 0.0005);
  EXPECT_EQ(*m.missed_deadlines, 7U);
  ASSERT_TRUE(m.settling_time_s && m.overshoot_pct && m.duty_saturation_pct);
  EXPECT_NEAR(*m.settling_time_s, 0.1 * std::log(50.0), 0.001);  // the left wheel's, the worse
  EXPECT_NEAR(*m.overshoot_pct, 5.0, 1e-9);                      // the right wheel's spike
  EXPECT_DOUBLE_EQ(*m.duty_saturation_pct, 100.0 * 100.0 / 2001.0);
  EXPECT_FALSE(m.credibility.has_value());  // not asked for
  for (const CriterionResult& r : Judge(c, m)) EXPECT_TRUE(r.passed) << r.name;
}

TEST_F(CampaignMeasure, HilWithoutTheEcsReportHasNoVerdictTrackingOrMisses) {
  nlohmann::json report = HilReport();
  report["ecs"] = nullptr;
  report["tracking_error_max_m"] = nullptr;
  report["tracking_error_rms_m"] = nullptr;
  report["final_error_m"] = nullptr;
  const ScenarioMeasures m = MeasureHil(report, dir_ / "absent.csv", CampaignCriteria{});
  EXPECT_EQ(m.verdict, "");
  EXPECT_FALSE(m.tracking_max_m.has_value());
  EXPECT_FALSE(m.tracking_rms_m.has_value());
  EXPECT_FALSE(m.final_error_m.has_value());
  EXPECT_FALSE(m.missed_deadlines.has_value());
}

TEST_F(CampaignMeasure, AMissingColumnIsAnErrorNamingTheFileAndTheColumn) {
  const fs::path log = Write("ecs.csv", "time_s,duty_left,wheel_left_m\n0,0.1,0\n0.001,1,0\n");
  CampaignCriteria c;
  c.duty_saturation_pct = 5.0;
  try {
    (void)MeasureHil(HilReport(), log, c);
    FAIL() << "a log without duty_right was measured";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(log.string()), std::string::npos) << what;
    EXPECT_NE(what.find("duty_right"), std::string::npos) << what;
    EXPECT_NE(what.find("duty_saturation_pct"), std::string::npos) << what;
  }
  c = CampaignCriteria{};
  c.settling_time_s = 1.0;
  const fs::path absent = dir_ / "absent.csv";
  try {
    (void)MeasureHil(HilReport(), absent, c);
    FAIL() << "an absent log was measured";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(absent.string()), std::string::npos) << e.what();
  }
}

TEST_F(CampaignMeasure, RunTakesVerdictAndMissesFromItsReportAndDutyFromTheTwinLog) {
  const fs::path log = Write("twin.csv",
                             "time_s,duty_left,duty_right,wheel_left_m,wheel_right_m,x_m\n"
                             "0,1,0,0,0,0\n0.001,0.5,0,0,0,0\n0.002,0.5,-1,0,0,0\n"
                             "0.003,0,0,0,0,0\n");
  const nlohmann::json report = {{"verdict", "ABORTED"}, {"deadline_misses", 12}};
  CampaignCriteria c;
  c.duty_saturation_pct = 50.0;
  const ScenarioMeasures m = MeasureRun(report, log, c);
  EXPECT_EQ(m.verdict, "ABORTED");
  ASSERT_TRUE(m.missed_deadlines.has_value());
  EXPECT_EQ(*m.missed_deadlines, 12U);
  EXPECT_FALSE(m.tracking_max_m.has_value());
  ASSERT_TRUE(m.duty_saturation_pct.has_value());
  EXPECT_DOUBLE_EQ(*m.duty_saturation_pct, 50.0);
  // The twin's log has no setpoint: a settling bound names the column it lacks.
  c.settling_time_s = 1.0;
  try {
    (void)MeasureRun(report, log, c);
    FAIL() << "a step was measured without a setpoint";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("setpoint_left_m"), std::string::npos) << e.what();
  }
}

TEST_F(CampaignMeasure, IdenticalCurvesOnDifferentTimeBasesAreCredible) {
  CampaignCriteria c;
  c.credibility_min = 0.6;
  c.compare_column = "wheel_right_m";
  c.reference_file = WriteSine("reference.csv", "y_e", 0.002, 0.1).string();
  c.reference_column = "y_e";
  const fs::path log = WriteSine("twin.csv", "wheel_right_m", 0.001, 0.1);
  const ScenarioMeasures m = MeasureRun(nlohmann::json::object(), log, c);
  ASSERT_TRUE(m.credibility.has_value());
  EXPECT_GT(*m.credibility, 0.999);
  EXPECT_LE(*m.credibility, 1.0);
  // On the same time base the curves are the same samples: e_t = 0, η = 1.
  c.reference_file = log.string();
  c.reference_column = "wheel_right_m";
  EXPECT_DOUBLE_EQ(*MeasureRun(nlohmann::json::object(), log, c).credibility, 1.0);
}

TEST_F(CampaignMeasure, AnInvertedCurveScoresAsTheFormulaSays) {
  CampaignCriteria c;
  c.credibility_min = 0.6;
  c.compare_column = "wheel_right_m";
  c.reference_file = WriteSine("reference.csv", "y_e", 0.001, 0.1).string();
  c.reference_column = "y_e";
  c.credibility_max_delay_s = 0.05;
  const fs::path log = WriteSine("twin.csv", "wheel_right_m", 0.001, -0.1);
  const ScenarioMeasures m = MeasureRun(nlohmann::json::object(), log, c);
  ASSERT_TRUE(m.credibility.has_value());
  // e_t = RMS(2·0.1·sin) = 0.1·√2, ε_t = 0.05·0.2 = 0.01, K_e = 0.6/0.8:
  // η = K_e·ε / √((K_e·ε)² + e²) = 0.0075 / √(0.0075² + 0.02) = 0.0530.
  const double scaled = 0.75 * 0.01;
  const double expected = scaled / std::sqrt(scaled * scaled + 0.02);
  EXPECT_NEAR(*m.credibility, expected, 0.001);
  EXPECT_FALSE(Judge(c, m).at(0).passed);
}

TEST_F(CampaignMeasure, CredibilityErrorsNameTheReferenceColumnAndTheDelay) {
  CampaignCriteria c;
  c.credibility_min = 0.6;
  c.reference_file = WriteSine("reference.csv", "y_e", 0.001, 0.1).string();
  c.reference_column = "y_x";
  const fs::path log = WriteSine("twin.csv", "wheel_right_m", 0.001, 0.1);
  try {
    (void)MeasureRun(nlohmann::json::object(), log, c);
    FAIL() << "a reference column that is not there was read";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(c.reference_file), std::string::npos) << what;
    EXPECT_NE(what.find("y_x"), std::string::npos) << what;
  }
  c.reference_column = "y_e";
  c.credibility_max_delay_s = -1.0;
  try {
    (void)MeasureRun(nlohmann::json::object(), log, c);
    FAIL() << "a negative delay search range was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("credibility_min"), std::string::npos) << e.what();
  }
}

TEST_F(CampaignMeasure, PlotThinsToAtMost400PointsKeepingTheEnds) {
  const ScenarioPlot plot = PlotOf(WriteClosedLoopLog());
  EXPECT_EQ(plot.y_unit, "m");
  ASSERT_EQ(plot.time_s.size(), ScenarioPlot::kMaxPlotPoints);
  EXPECT_DOUBLE_EQ(plot.time_s.front(), 0.0);
  EXPECT_DOUBLE_EQ(plot.time_s.back(), 2.0);
  for (std::size_t i = 1; i < plot.time_s.size(); ++i) {
    EXPECT_GT(plot.time_s[i], plot.time_s[i - 1]);
  }
  ASSERT_EQ(plot.series.size(), 2U);
  EXPECT_EQ(plot.series[0].name, "setpoint_left_m");
  EXPECT_EQ(plot.series[1].name, "wheel_left_m");
  ASSERT_EQ(plot.series[0].values.size(), plot.time_s.size());
  EXPECT_DOUBLE_EQ(plot.series[0].values.back(), 0.1);
  EXPECT_DOUBLE_EQ(plot.series[1].values.front(), 0.0);
  EXPECT_NEAR(plot.series[1].values.back(), 0.1 * (1.0 - std::exp(-15.0)), 1e-12);
}

TEST_F(CampaignMeasure, PlotOfAnOpenLoopLogShowsBothWheelsAndAnUnreadableLogNothing) {
  const ScenarioPlot plot = PlotOf(Write("twin.csv",
                                         "time_s,duty_left,duty_right,wheel_left_m,wheel_right_m\n"
                                         "0,1,1,0,0\n0.1,1,1,0.01,0.02\n0.2,1,1,0.03,0.05\n"));
  ASSERT_EQ(plot.time_s.size(), 3U);  // fewer than the most: every row
  ASSERT_EQ(plot.series.size(), 2U);
  EXPECT_EQ(plot.series[0].name, "wheel_left_m");
  EXPECT_EQ(plot.series[1].name, "wheel_right_m");
  EXPECT_EQ(plot.series[1].values, (std::vector<double>{0.0, 0.02, 0.05}));
  const ScenarioPlot none = PlotOf(dir_ / "absent.csv");
  EXPECT_TRUE(none.time_s.empty());
  EXPECT_TRUE(none.series.empty());
}

}  // namespace criteria_test
}  // namespace hiltwin::app
