// The whole assessment on synthetic curves: alignment, delay compensation, domains, total.
#include "hiltwin/assess/assessment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace hiltwin::analysis {
namespace {

double Position(double t_s) {
  return 0.3 * t_s + 0.2 * std::sin(2.1 * t_s) + 0.05 * std::sin(7.3 * t_s + 0.4);
}

Curve MakeCurve(const std::string& name, double t0_s, double step_s, std::size_t n,
                double delay_s, double offset = 0.0) {
  Curve c;
  c.path = name + ".csv";
  c.label = name;
  c.column = 1;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0_s + static_cast<double>(i) * step_s;
    c.t_s.push_back(t);
    c.y.push_back(Position(t - delay_s) + offset);
    c.lines.push_back(i + 2);
  }
  return c;
}

std::string ErrorOf(const Curve& sim, const Curve& exp, const AssessOptions& options,
                    const Curve* input = nullptr) {
  try {
    (void)Assess(sim, exp, input, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The option an OptionError from Assess concerns, with its message.
struct OptionFailure {
  std::optional<AssessOption> option;  // empty: no OptionError
  std::string message;
};

OptionFailure OptionErrorOf(const Curve& sim, const Curve& exp, const AssessOptions& options,
                            const Curve* input = nullptr) {
  try {
    (void)Assess(sim, exp, input, options);
  } catch (const OptionError& e) {
    return {e.option(), e.what()};
  }
  return {};
}

TEST(Assess, PureDelayScoresAboutOneAfterCompensation) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-3, 10000, 0.0);
  const Curve exp = MakeCurve("exp", 0.0, 1e-3, 10000, 0.0123);  // 12.3 ms late
  const Assessment a = Assess(sim, exp, nullptr, AssessOptions{});
  EXPECT_TRUE(a.same_time_base);
  EXPECT_NEAR(a.delay.delay_s, 0.0123, 2e-5);
  EXPECT_LT(a.time.eta, 0.9999);
  EXPECT_GT(a.time_compensated.eta, 0.999999);
  EXPECT_LT(a.time_compensated.e_t, a.time.e_t / 100.0);
  EXPECT_DOUBLE_EQ(a.total, a.time.eta);  // thesis weights 1,0,0 use the raw score
  AssessOptions compensated;
  compensated.total_uses_compensated = true;
  EXPECT_DOUBLE_EQ(Assess(sim, exp, nullptr, compensated).total,
                   Assess(sim, exp, nullptr, compensated).time_compensated.eta);
}

TEST(Assess, KnownOffsetGivesKnownErrorAndIdenticalGivesOne) {
  const Curve exp = MakeCurve("exp", 0.0, 1e-2, 2000, 0.0);
  const Curve offset = MakeCurve("sim", 0.0, 1e-2, 2000, 0.0, 0.004);
  const Assessment a = Assess(offset, exp, nullptr, AssessOptions{});
  EXPECT_NEAR(a.time.e_t, 0.004, 1e-12);
  EXPECT_NEAR(a.delay.delay_s, 0.0, 1e-9);
  EXPECT_NEAR(a.theil.bias, 1.0, 1e-6);
  const Assessment same = Assess(exp, exp, nullptr, AssessOptions{});
  EXPECT_EQ(same.time.eta, 1.0);
  EXPECT_EQ(same.total, 1.0);
  EXPECT_TRUE(same.pass);
  ASSERT_TRUE(same.iso.has_value());
  EXPECT_DOUBLE_EQ(same.iso->overall, 1.0);
}

TEST(Assess, TwoFilesAreResampledOntoTheExperimentOverTheOverlap) {
  // Simulation at 1 kHz from 0 s, experiment at 300 Hz from 1 s to beyond the simulation.
  const Curve sim = MakeCurve("sim", 0.0, 1e-3, 8001, 0.0);    // 0 .. 8 s
  const Curve exp = MakeCurve("exp", 1.0, 1.0 / 300.0, 3000, 0.0);  // 1 .. ~11 s
  const Assessment a = Assess(sim, exp, nullptr, AssessOptions{});
  EXPECT_FALSE(a.same_time_base);
  EXPECT_NEAR(a.overlap_t0_s, 1.0, 1e-12);
  EXPECT_LE(a.overlap_t1_s, 8.0);
  EXPECT_GT(a.overlap_t1_s, 8.0 - 1.0 / 300.0);
  EXPECT_EQ(a.samples, a.t_s.size());
  // Linear interpolation of a smooth curve at 1 kHz: tiny error, score ~ 1.
  EXPECT_LT(a.time.e_t, 1e-6);
  EXPECT_GT(a.time.eta, 0.999999);
  ASSERT_FALSE(a.notes.empty());
  EXPECT_NE(a.notes.front().find("resampled"), std::string::npos);
}

TEST(Assess, ErrorThresholdUsesTheComparedRangeOnly) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 501, 0.0);   // 0 .. 5 s
  const Curve exp = MakeCurve("exp", 0.0, 1e-2, 1001, 0.0);  // 0 .. 10 s
  const Assessment a = Assess(sim, exp, nullptr, AssessOptions{});
  double lo = 1e300;
  double hi = -1e300;
  for (std::size_t i = 0; i <= 500; ++i) {
    lo = std::min(lo, exp.y[i]);
    hi = std::max(hi, exp.y[i]);
  }
  EXPECT_NEAR(a.time.eps_t, 0.05 * (hi - lo), 1e-12);
  EXPECT_EQ(a.samples, 501u);
}

TEST(Assess, NoOverlapIsAnInputError) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  const Curve exp = MakeCurve("exp", 5.0, 1e-2, 100, 0.0);
  const std::string m = ErrorOf(sim, exp, AssessOptions{});
  EXPECT_NE(m.find("no overlap"), std::string::npos) << m;
  EXPECT_NE(m.find("[0, 0.99] s"), std::string::npos) << m;
  EXPECT_NE(m.find("[5, 5.99] s"), std::string::npos) << m;
  // Where each time column lies in its file (column 1 = time), and what to do.
  EXPECT_NE(m.find("sim.csv:2-101:1"), std::string::npos) << m;
  EXPECT_NE(m.find("exp.csv:2-101:1"), std::string::npos) << m;
  EXPECT_NE(m.find("start offset"), std::string::npos) << m;
}

TEST(Assess, ConstantInputQuotesTheLinesOfTheComparedRange) {
  // Curves over 0 .. 0.99 s; the input file runs to 2.99 s and moves only after 1.5 s, so the
  // message must name the input lines the comparison used (2-101), not the whole file.
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  const Curve exp = MakeCurve("exp", 0.0, 1e-2, 100, 0.0, 0.001);
  Curve u = MakeCurve("u", 0.0, 1e-2, 300, 0.0);
  for (std::size_t i = 0; i < u.y.size(); ++i) u.y[i] = u.t_s[i] <= 1.5 ? 0.5 : u.t_s[i];
  const std::string m = ErrorOf(sim, exp, AssessOptions{}, &u);
  EXPECT_NE(m.find("u.csv:2-101:2:"), std::string::npos) << m;
  EXPECT_NE(m.find("constant (0.5)"), std::string::npos) << m;
  EXPECT_NE(m.find("[0, 0.99] s"), std::string::npos) << m;
  EXPECT_NE(m.find("give the column that drove both systems"), std::string::npos) << m;
  EXPECT_EQ(OptionErrorOf(sim, exp, AssessOptions{}, &u).option, AssessOption::kInput);
}

TEST(Assess, IsoRatingNeedsTwentySamplesElseItIsNullWithAReason) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 19, 0.0, 0.001);
  const Curve exp = MakeCurve("exp", 0.0, 1e-2, 19, 0.0);
  const Assessment a = Assess(sim, exp, nullptr, AssessOptions{});
  EXPECT_FALSE(a.iso.has_value());
  const nlohmann::json j = ToJson(a);
  EXPECT_TRUE(j["cross_checks"]["iso18571"].is_null()) << j["cross_checks"].dump();
  ASSERT_TRUE(j["not_computed"]["iso18571"].is_string());
  const std::string why = j["not_computed"]["iso18571"].get<std::string>();
  EXPECT_NE(why.find("19 samples"), std::string::npos) << why;
  EXPECT_NE(why.find("at least 20"), std::string::npos) << why;
  const std::string text = FormatText(a);
  EXPECT_NE(text.find("ISO/TS 18571: not computed: " + why), std::string::npos) << text;
  EXPECT_TRUE(j["total"].is_number());  // the cross-check never blocks the score

  const Assessment twenty = Assess(MakeCurve("sim", 0.0, 1e-2, 20, 0.0, 0.001),
                                   MakeCurve("exp", 0.0, 1e-2, 20, 0.0), nullptr, AssessOptions{});
  ASSERT_TRUE(twenty.iso.has_value());
  EXPECT_TRUE(ToJson(twenty)["cross_checks"]["iso18571"]["overall"].is_number());
  EXPECT_FALSE(ToJson(twenty)["not_computed"].contains("iso18571"));
}

TEST(Assess, ConstantExperimentNamesFileLinesAndColumn) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  Curve exp = MakeCurve("exp", 0.0, 1e-2, 100, 0.0);
  exp.y.assign(exp.y.size(), 1.5);
  const std::string m = ErrorOf(sim, exp, AssessOptions{});
  EXPECT_NE(m.find("exp.csv:2-101:2"), std::string::npos) << m;
  EXPECT_NE(m.find("constant"), std::string::npos) << m;
}

// Values whose squares leave double precision are refused naming the curve, file, line and
// column (they gave an internal error, exit 1): a curve value, a time, an input value.
TEST(Assess, ValuesBeyondTheScoredMagnitudeNameTheirCell) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  Curve exp = MakeCurve("exp", 0.0, 1e-2, 100, 0.0);
  exp.y[40] = -1e308;  // line 42
  OptionFailure f = OptionErrorOf(sim, exp, AssessOptions{});
  EXPECT_EQ(f.option, AssessOption::kExp);
  EXPECT_EQ(f.message.rfind("exp.csv:42:2: the experiment curve (exp) holds -1e+308, beyond "
                            "+-1e+100, the largest magnitude assess scores",
                            0),
            0U)
      << f.message;
  EXPECT_NE(f.message.find("rescale the column"), std::string::npos) << f.message;
  Curve late = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  late.t_s.back() = 1e300;  // a time far beyond the others, line 101
  f = OptionErrorOf(late, MakeCurve("exp", 0.0, 1e-2, 100, 0.0), AssessOptions{});
  EXPECT_EQ(f.option, AssessOption::kSim);
  EXPECT_EQ(f.message.rfind("sim.csv:101:1: the simulation curve (sim) holds the time 1e+300", 0),
            0U)
      << f.message;
  Curve u = MakeCurve("u", 0.0, 1e-2, 100, 0.0);
  u.y[0] = 1e200;
  f = OptionErrorOf(sim, MakeCurve("exp", 0.0, 1e-2, 100, 0.0, 0.1), AssessOptions{}, &u);
  EXPECT_EQ(f.option, AssessOption::kInput);
  EXPECT_EQ(f.message.rfind("u.csv:2:2: the input curve (u) holds 1e+200", 0), 0U) << f.message;
}

// An experiment that moves less than the scored range would square its errors to 0 and score
// any simulation 1 (a zero simulation against one at 1e-170 passed): refused like a constant.
TEST(Assess, AnExperimentMovingBelowTheScoredRangeIsRefused) {
  Curve sim = MakeCurve("sim", 0.0, 1e-2, 100, 0.0);
  sim.y.assign(sim.y.size(), 0.0);
  Curve exp = MakeCurve("exp", 0.0, 1e-2, 100, 0.0);
  for (double& y : exp.y) y *= 1e-170;
  const OptionFailure f = OptionErrorOf(sim, exp, AssessOptions{});
  EXPECT_EQ(f.option, AssessOption::kExp);
  EXPECT_EQ(f.message.rfind("exp.csv:2-101:2: the experiment curve (exp) moves by only", 0), 0U)
      << f.message;
  EXPECT_NE(f.message.find("less than 1e-100, the smallest range assess scores"),
            std::string::npos)
      << f.message;
}

// A time base whose median step is far finer than its range (a few nanosecond samples, then one
// a million seconds later) would resample onto 1e15 points (std::bad_alloc, "internal error"):
// refused naming the experiment's time column, the grid it would need and the cap.
TEST(Assess, AnUnevenTimeBaseNeedingAHugeGridIsRefused) {
  Curve sim = MakeCurve("sim", 0.0, 1e-9, 40, 0.0);
  Curve exp = MakeCurve("exp", 0.0, 1e-9, 40, 0.0, 0.001);
  for (Curve* c : {&sim, &exp}) {
    for (double& y : c->y) y = (&y - c->y.data()) % 2 == 0 ? 1.0 : 0.0;
    c->t_s.back() = 1e6;
  }
  const OptionFailure f = OptionErrorOf(sim, exp, AssessOptions{});
  EXPECT_EQ(f.option, AssessOption::kExp);
  EXPECT_EQ(f.message.rfind("exp.csv:2-41:1: the time base is uneven", 0), 0U) << f.message;
  EXPECT_NE(f.message.find("would hold 1e+15 samples, more than 16 per compared sample (40)"),
            std::string::npos)
      << f.message;
}

TEST(Assess, WeightedDomainThatCannotBeComputedIsAnInputError) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 500, 0.0);
  AssessOptions freq;
  freq.weights = {1.0, 0.0, 1.0};
  const OptionFailure f = OptionErrorOf(sim, sim, freq);
  EXPECT_EQ(f.option, AssessOption::kWeights);
  EXPECT_NE(f.message.find("the frequency domain has weight 1 but cannot be computed: no input "
                           "curve given"),
            std::string::npos)
      << f.message;
  AssessOptions seg;
  seg.segment = std::pair{100.0, 200.0};
  const OptionFailure s = OptionErrorOf(sim, sim, seg);
  EXPECT_EQ(s.option, AssessOption::kSegment);
  EXPECT_NE(s.message.find("segment 100 s to 200 s holds 0 samples"), std::string::npos)
      << s.message;
}

// The library describes domain values and leaves flag names to the command line: no message
// or note holds "--", and every bad choice says which AssessOption it concerns.
TEST(Assess, LibraryMessagesNameDomainValuesNotFlags) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 500, 0.0);
  Curve constant = sim;
  constant.y.assign(constant.y.size(), 1.0);
  const Curve short_input = MakeCurve("u", 0.0, 1e-2, 10, 0.0);
  struct Case {
    AssessOptions options;
    const Curve* exp;
    const Curve* input;
    AssessOption option;
    const char* what;
  };
  std::vector<Case> cases;
  auto add = [&](auto change, AssessOption option, const char* what,
                 const Curve* exp = nullptr, const Curve* input = nullptr) {
    AssessOptions o;
    change(o);
    cases.push_back({o, exp != nullptr ? exp : &sim, input, option, what});
  };
  add([](AssessOptions& o) { o.params.kp = 0.0; }, AssessOption::kKp, "confidence interval Kp 0:");
  add([](AssessOptions& o) { o.params.eta_pass = 1.0; }, AssessOption::kEtaPass,
      "passing score eta_pass 1:");
  add([](AssessOptions& o) { o.weights = {1.0, -1.0, 0.0}; }, AssessOption::kWeights,
      "weights 1,-1,0: every weight");
  add([](AssessOptions& o) { o.weights = {0.0, 0.0, 0.0}; }, AssessOption::kWeights,
      "at least one weight must be > 0");
  add([](AssessOptions& o) { o.segment = std::pair{5.0, 2.0}; }, AssessOption::kSegment,
      "segment 5 s to 2 s: the end must come after the start");
  add([](AssessOptions& o) { o.max_delay_s = -1.0; }, AssessOption::kMaxDelay,
      "delay search range -1 s");
  add([](AssessOptions& o) { o.band_hz = std::pair{20.0, 0.0}; }, AssessOption::kBand,
      "frequency band 20 Hz to 0 Hz");
  add([](AssessOptions& o) { o.coherence_min = 1.0; }, AssessOption::kCoherence,
      "coherence threshold 1:");
  add([](AssessOptions& o) { o.welch_segment = 4; }, AssessOption::kWelchSegment,
      "Welch segment of 4 samples", nullptr, &sim);
  add([](AssessOptions&) {}, AssessOption::kExp, "the experiment curve", &constant);
  add([](AssessOptions&) {}, AssessOption::kInput, "fewer than 16 samples", nullptr,
      &short_input);
  add([](AssessOptions& o) { o.weights = {1.0, 0.0, 1.0}; }, AssessOption::kWeights,
      "no input curve given");
  for (const Case& c : cases) {
    const OptionFailure f = OptionErrorOf(sim, *c.exp, c.options, c.input);
    EXPECT_EQ(f.option, c.option) << c.what << " -> " << f.message;
    EXPECT_NE(f.message.find(c.what), std::string::npos) << f.message;
    EXPECT_EQ(f.message.find("--"), std::string::npos) << f.message;
  }
}

TEST(Assess, NotesNameOptionsOnlyThroughTheNamer) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-3, 2000, 0.0);
  const Curve exp = MakeCurve("exp", 0.0, 1e-3, 2000, 0.05);  // 50 ms late
  AssessOptions options;
  options.max_delay_s = 0.01;
  options.segment = std::pair{0.0, 1.0};
  const Assessment plain = Assess(sim, exp, nullptr, options);
  ASSERT_TRUE(plain.delay.at_search_limit);
  std::vector<std::string> texts = plain.notes;
  texts.push_back(plain.frequency_note);
  for (const std::string& text : texts) EXPECT_EQ(text.find("--"), std::string::npos) << text;
  EXPECT_EQ(plain.frequency_note, "no input curve given");

  options.name_option = [](AssessOption option) -> std::string_view {
    return option == AssessOption::kMaxDelay ? "--max-delay"
           : option == AssessOption::kInput  ? "--input"
                                             : "";
  };
  const Assessment named = Assess(sim, exp, nullptr, options);
  EXPECT_EQ(named.frequency_note, "no input curve given (--input)");
  EXPECT_NE(named.notes.back().find("widen the search range (--max-delay)"), std::string::npos)
      << named.notes.back();
}

TEST(Assess, StepSegmentGivesPerformanceDomainAndWeightedTotal) {
  Curve exp;
  Curve sim;
  exp.path = sim.path = "step.csv";
  exp.label = "exp";
  sim.label = "sim";
  for (std::size_t i = 0; i < 4000; ++i) {
    const double t = static_cast<double>(i) * 1e-3;  // step at 1 s
    const double e = t < 1.0 ? 0.0 : 1.0 - std::exp(-(t - 1.0) / 0.1);
    const double s = t < 1.0 ? 0.0 : 1.0 - std::exp(-(t - 1.0) / 0.102);
    exp.t_s.push_back(t);
    sim.t_s.push_back(t);
    exp.y.push_back(e);
    sim.y.push_back(s);
    exp.lines.push_back(i + 2);
    sim.lines.push_back(i + 2);
  }
  AssessOptions options;
  options.segment = std::pair{1.0, 4.0};
  options.weights = {1.0, 1.0, 0.0};
  const Assessment a = Assess(sim, exp, nullptr, options);
  ASSERT_TRUE(a.performance.has_value());
  EXPECT_NEAR(a.performance->t0_s, 1.0, 1e-9);
  const MetricScore& rise = a.performance->metrics.at(0);
  ASSERT_TRUE(rise.exp.has_value());
  EXPECT_NEAR(*rise.exp, 0.1 * std::log(9.0), 2e-3);
  EXPECT_NEAR(a.total, 0.5 * (a.time.eta + a.performance->eta), 1e-12);
  const nlohmann::json j = ToJson(a);
  EXPECT_TRUE(j["performance_domain"].is_object());
  EXPECT_TRUE(j["frequency_domain"].is_null());
  EXPECT_DOUBLE_EQ(j["performance_domain"]["eta"].get<double>(), a.performance->eta);
}

TEST(Assess, InputColumnEnablesTheFrequencyDomain) {
  Curve u;
  Curve y;
  u.path = y.path = "f.csv";
  u.label = "u";
  y.label = "y";
  std::uint64_t s = 42;
  double state = 0.0;
  for (std::size_t i = 0; i < 16384; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    const double v = static_cast<double>(s >> 11) / 9007199254740992.0 - 0.5;
    state = 0.8 * state + 0.2 * v;
    u.t_s.push_back(static_cast<double>(i) * 1e-3);
    y.t_s.push_back(static_cast<double>(i) * 1e-3);
    u.y.push_back(v);
    y.y.push_back(state);
    u.lines.push_back(i + 2);
    y.lines.push_back(i + 2);
  }
  AssessOptions options;
  options.weights = {1.0, 0.0, 1.0};
  const Assessment a = Assess(y, y, &u, options);
  ASSERT_TRUE(a.frequency.has_value()) << a.frequency_note;
  EXPECT_DOUBLE_EQ(a.frequency->eta, 1.0);
  EXPECT_DOUBLE_EQ(a.total, 1.0);
}

TEST(Assess, StepInputLeavesTheFrequencyDomainNotComputed) {
  // A single step at 1 s: after each Welch segment's line is removed only the 2 segments that
  // hold the step carry input power, too few for a coherence estimate.
  Curve u;
  Curve y;
  u.path = y.path = "step.csv";
  u.label = "u";
  y.label = "y";
  double state = 0.0;
  for (std::size_t i = 0; i < 4000; ++i) {
    const double t = static_cast<double>(i) * 1e-3;
    const double duty = i < 1000 ? 0.0 : 1.0;
    state = 0.98 * state + 0.02 * duty;
    u.t_s.push_back(t);
    y.t_s.push_back(t);
    u.y.push_back(duty);
    y.y.push_back(state);
    u.lines.push_back(i + 2);
    y.lines.push_back(i + 2);
  }
  const Assessment a = Assess(y, y, &u, AssessOptions{});
  EXPECT_FALSE(a.frequency.has_value());
  EXPECT_NE(a.frequency_note.find("only 2 of 30 Welch segments"), std::string::npos)
      << a.frequency_note;
  EXPECT_TRUE(ToJson(a)["frequency_domain"].is_null());
  EXPECT_NE(FormatText(a).find("Frequency domain: not computed: only 2 of 30"), std::string::npos);
  AssessOptions weighted;
  weighted.weights = {1.0, 0.0, 1.0};
  const std::string m = ErrorOf(y, y, weighted, &u);
  EXPECT_NE(m.find("frequency domain has weight 1"), std::string::npos) << m;
  EXPECT_NE(m.find("carry input power"), std::string::npos) << m;
}

TEST(Assess, JsonHasTheContractKeys) {
  const Curve sim = MakeCurve("sim", 0.0, 1e-2, 600, 0.0, 0.01);
  const Curve exp = MakeCurve("exp", 0.0, 1e-2, 600, 0.0);
  const nlohmann::json j = ToJson(Assess(sim, exp, nullptr, AssessOptions{}));
  for (const char* key : {"e_t", "eps_t", "k_e", "eta"}) {
    EXPECT_TRUE(j["time_domain"][key].is_number()) << key;
    EXPECT_TRUE(j["time_domain_compensated"][key].is_number()) << key;
  }
  EXPECT_TRUE(j["delay_s"].is_number());
  EXPECT_TRUE(j.contains("performance_domain"));
  EXPECT_TRUE(j["frequency_domain"].is_null());
  EXPECT_TRUE(j["total"].is_number());
  EXPECT_TRUE(j["pass"].is_boolean());
  EXPECT_TRUE(j["cross_checks"]["theil"]["u"].is_number());
  EXPECT_TRUE(j["cross_checks"]["iso18571"]["overall"].is_number());
  const std::string text = FormatText(Assess(sim, exp, nullptr, AssessOptions{}));
  EXPECT_NE(text.find("e_t"), std::string::npos);
  EXPECT_NE(text.find("PASS"), std::string::npos);
}

}  // namespace
}  // namespace hiltwin::analysis
