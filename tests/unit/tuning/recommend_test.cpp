// The bounds and the recommendation on constructed machines: every deciding bound reached with
// an exact rate, and the measurements and policies that cannot be used refused.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "hiltwin/tuning/tuning.h"
#include "tuning_fixtures.h"

namespace hiltwin::analysis {
namespace {

using fixtures::Machine;
using fixtures::ThesisMachine;
using ::testing::HasSubstr;

bool Mentions(const Recommendation& rec, const char* text) {
  for (const std::string& w : rec.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(Recommend, ThesisExampleIsSeventyFivePercentOfTheTimingMaximum) {
  const Recommendation rec = Recommend(ThesisMachine(), 3000.0, TuningPolicy{});
  EXPECT_DOUBLE_EQ(rec.timing_max_hz, 1e9 / 120'000.0);
  EXPECT_NEAR(rec.timing_max_hz, 8333.33, 0.005);
  EXPECT_DOUBLE_EQ(rec.latency_max_hz, 1e9 / (10'000.0 + 90'000.0 + 35'000.0));
  EXPECT_EQ(rec.worst_latency_p999_ns, 10'000.0);
  EXPECT_EQ(rec.heuristic_hz, 6250.0);
  EXPECT_EQ(rec.recommended_hz, 6250.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kTimingFraction);
  EXPECT_EQ(rec.reason, "75 % of the timing maximum 8333 Hz (overhead 35.0 us + compute 85.0 us)");
  EXPECT_TRUE(rec.warnings.empty());
}

TEST(Recommend, SlowMachineIsRaisedToFourTimesTheController) {
  // 1 / 200 us = 5000 Hz; 75 % = 3750 Hz < 4 kHz; latency maximum 1 / 210 us = 4762 Hz.
  const Recommendation rec = Recommend(Machine(50'000.0, 150'000.0, 150'000, 10'000), 2000.0, {});
  EXPECT_EQ(rec.recommended_hz, 4000.0);
  EXPECT_EQ(rec.heuristic_hz, 4000.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kControllerFloor);
  EXPECT_THAT(rec.reason,
              HasSubstr("is 3750 Hz, below 4x the controller rate 1000 Hz: raised to 4000 Hz"));
  EXPECT_TRUE(rec.warnings.empty());
}

TEST(Recommend, FastMachineIsLoweredToTenTimesTheController) {
  // 1 / 15 us = 66667 Hz; 75 % = 50000 Hz > 10 kHz.
  const Recommendation rec = Recommend(Machine(5'000.0, 10'000.0, 10'000, 20'000), 3000.0, {});
  EXPECT_EQ(rec.recommended_hz, 10'000.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kControllerCeiling);
  EXPECT_THAT(rec.reason, HasSubstr("above 10x the controller rate 1000 Hz: lowered to 10000 Hz"));
}

TEST(Recommend, AccuracyBoundAboveTheHeuristicRaisesTheRate) {
  const Recommendation rec = Recommend(Machine(5'000.0, 10'000.0, 10'000, 20'000), 12'000.0, {});
  EXPECT_EQ(rec.heuristic_hz, 10'000.0);
  EXPECT_EQ(rec.recommended_hz, 12'000.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kAccuracy);
  EXPECT_THAT(rec.reason, HasSubstr("the accuracy bound 12000 Hz"));
  EXPECT_TRUE(rec.warnings.empty());
}

TEST(Recommend, LatencyAwareMaximumCapsTheAccuracyBound) {
  // Timing maximum 1 / 10 us = 100 kHz, but 1 / (45 + 5 + 5) us = 18181.8 Hz.
  const Recommendation rec = Recommend(Machine(5'000.0, 5'000.0, 5'000, 45'000), 20'000.0, {});
  EXPECT_DOUBLE_EQ(rec.latency_max_hz, 1e9 / 55'000.0);
  EXPECT_EQ(rec.worst_latency_p999_ns, 45'000.0);
  EXPECT_EQ(rec.recommended_hz, 18'181.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kLatencyMax);
  EXPECT_THAT(rec.reason, HasSubstr("capped at the latency-aware maximum 18181 Hz (p99.9 wake-up "
                                    "latency 45.0 us + p99.9 compute 5.000 us + overhead 5.000 us)"));
  EXPECT_TRUE(Mentions(rec, "the accuracy bound 20000 Hz is above the rate this machine can hold"));
}

TEST(Recommend, TimingMaximumCapsWhenLatencyAddsNothing) {
  // A mean above the p99.9 (rare long steps): 1 / 90 us = 11111.1 Hz < 1 / 87 us = 11494 Hz.
  const Recommendation rec = Recommend(Machine(40'000.0, 50'000.0, 45'000, 2'000), 12'000.0, {});
  EXPECT_EQ(rec.recommended_hz, 11'111.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kTimingMax);
  EXPECT_THAT(rec.reason, HasSubstr("capped at the timing maximum 11111 Hz"));
}

TEST(Recommend, SchedulerLimitCountsAsTiming) {
  TuningPolicy policy;
  policy.max_rate_hz = 9'000.0;
  const Recommendation rec =
      Recommend(Machine(5'000.0, 10'000.0, 10'000, 20'000), 12'000.0, policy);
  EXPECT_EQ(rec.recommended_hz, 9'000.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kTimingMax);
  EXPECT_THAT(rec.reason, HasSubstr("the scheduler's limit 9000 Hz"));
}

TEST(Recommend, WarnsWhenTheMachineCannotReachFourTimesTheController) {
  // 75 % of 3333 Hz is raised to 4 kHz, then capped at 1 / 350 us = 2857.1 Hz.
  const Recommendation rec = Recommend(Machine(100'000.0, 200'000.0, 200'000, 50'000), 2000.0, {});
  EXPECT_EQ(rec.recommended_hz, 2857.0);
  EXPECT_EQ(rec.deciding_bound, DecidingBound::kLatencyMax);
  EXPECT_TRUE(
      Mentions(rec, "this machine cannot run the twin at 4x the controller rate (4000 Hz)"));
}

TEST(Recommend, WarnsWithoutAnAccuracyBound) {
  const Recommendation rec = Recommend(ThesisMachine(), std::nullopt, TuningPolicy{});
  EXPECT_EQ(rec.recommended_hz, 6250.0);
  EXPECT_FALSE(rec.accuracy_bound_hz.has_value());
  EXPECT_TRUE(Mentions(rec, "no accuracy bound"));
}

TEST(Recommend, RefusesUnusableMeasurements) {
  EXPECT_THROW((void)Recommend(Machine(0.0, 0.0, 0, 1000), {}, {}), std::invalid_argument);
  EXPECT_THROW((void)Recommend(Machine(-5.0, 1.0, 0, 1000), {}, {}), std::invalid_argument);
  TimingMeasurements no_latency = ThesisMachine();
  no_latency.wake_latency.clear();
  EXPECT_THROW((void)Recommend(no_latency, {}, {}), std::invalid_argument);
}

TEST(Recommend, RefusesABadPolicy) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double rate_hz : {0.0, -1000.0, nan, inf}) {
    TuningPolicy policy;
    policy.controller_rate_hz = rate_hz;
    EXPECT_THROW((void)Recommend(ThesisMachine(), {}, policy), std::invalid_argument) << rate_hz;
  }
  for (const double tolerance_m : {0.0, -1e-4, nan, inf}) {
    TuningPolicy policy;
    policy.tolerance_m = tolerance_m;
    EXPECT_THROW((void)Recommend(ThesisMachine(), {}, policy), std::invalid_argument)
        << tolerance_m;
  }
}

TEST(Recommend, BoundsHaveStableNames) {
  EXPECT_STREQ(ToString(DecidingBound::kTimingFraction), "timing_fraction");
  EXPECT_STREQ(ToString(DecidingBound::kControllerFloor), "controller_floor");
  EXPECT_STREQ(ToString(DecidingBound::kControllerCeiling), "controller_ceiling");
  EXPECT_STREQ(ToString(DecidingBound::kAccuracy), "accuracy");
  EXPECT_STREQ(ToString(DecidingBound::kTimingMax), "timing_max");
  EXPECT_STREQ(ToString(DecidingBound::kLatencyMax), "latency_max");
}

}  // namespace
}  // namespace hiltwin::analysis
