// The accuracy search (bisection over whole multiples, each rate run once), the validation
// summary and the check of a user's candidate list.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "hiltwin/tuning/tuning.h"

namespace hiltwin::analysis {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Counts the evaluations and remembers every rate asked for.
struct CountingError {
  std::function<double(double)> error_m;
  std::vector<double> asked_hz;

  [[nodiscard]] std::function<double(double)> Probe() {
    return [this](double rate_hz) {
      asked_hz.push_back(rate_hz);
      return error_m(rate_hz);
    };
  }
};

std::vector<double> Rates(const AccuracySearch& search) {
  std::vector<double> rates_hz;
  for (const AccuracyPoint& p : search.points) rates_hz.push_back(p.rate_hz);
  return rates_hz;
}

TEST(AccuracyBound, FindsTheLowestPassingMultipleByBisection) {
  // e(f) = 0.3 mm * 1000 / f is within 0.1 mm from 3 kHz on.
  CountingError error{[](double f_hz) { return 0.3e-3 * 1000.0 / f_hz; }, {}};
  TuningPolicy policy;
  policy.tolerance_m = 0.1e-3;
  const AccuracySearch search = AccuracyBound(error.Probe(), policy);
  ASSERT_TRUE(search.bound_hz.has_value());
  EXPECT_EQ(*search.bound_hz, 3000.0);
  // Highest multiple (50) first, then bisection on [1, 50]: 25, 12, 6, 3, 1, 2.
  EXPECT_THAT(error.asked_hz,
              ElementsAre(50'000.0, 25'000.0, 12'000.0, 6'000.0, 3'000.0, 1'000.0, 2'000.0));
  EXPECT_EQ(std::set<double>(error.asked_hz.begin(), error.asked_hz.end()).size(),
            error.asked_hz.size());
  EXPECT_THAT(Rates(search),
              ElementsAre(1'000.0, 2'000.0, 3'000.0, 6'000.0, 12'000.0, 25'000.0, 50'000.0));
  EXPECT_DOUBLE_EQ(search.points.front().rms_error_m, 0.3e-3);
  EXPECT_DOUBLE_EQ(search.points.back().rms_error_m, 0.3e-3 * 1000.0 / 50'000.0);
}

TEST(AccuracyBound, NoBoundWhenTheHighestMultipleFails) {
  CountingError error{[](double) { return 1.0; }, {}};
  const AccuracySearch search = AccuracyBound(error.Probe(), TuningPolicy{});
  EXPECT_FALSE(search.bound_hz.has_value());
  EXPECT_THAT(error.asked_hz, ElementsAre(50'000.0));
  EXPECT_THAT(Rates(search), ElementsAre(50'000.0));
}

TEST(AccuracyBound, NanErrorCountsAsFailing) {
  CountingError error{[](double) { return std::numeric_limits<double>::quiet_NaN(); }, {}};
  EXPECT_FALSE(AccuracyBound(error.Probe(), TuningPolicy{}).bound_hz.has_value());
  EXPECT_EQ(error.asked_hz.size(), 1u);
}

TEST(AccuracyBound, ControllerRateItselfWhenEverythingPasses) {
  CountingError error{[](double) { return 0.0; }, {}};
  TuningPolicy policy;
  policy.max_rate_hz = 4'500.0;  // multiples 1..4
  const AccuracySearch search = AccuracyBound(error.Probe(), policy);
  EXPECT_EQ(search.bound_hz, 1000.0);
  EXPECT_THAT(error.asked_hz, ElementsAre(4'000.0, 2'000.0, 1'000.0));
}

TEST(AccuracyBound, RefusesABadPolicy) {
  TuningPolicy policy;
  policy.tolerance_m = 0.0;
  EXPECT_THROW((void)AccuracyBound([](double) { return 0.0; }, policy), std::invalid_argument);
}

CandidateResult Candidate(double rate_hz, const char* verdict, double rms_error_mm) {
  CandidateResult c;
  c.rate_hz = rate_hz;
  c.qos_verdict = verdict;
  c.rms_error_m = rms_error_mm * 1e-3;
  return c;
}

TEST(SummariseValidation, TableFiveOneLikeRuns) {
  const ValidationSummary s = SummariseValidation(
      {Candidate(1000, "PASS", 0.30), Candidate(2000, "PASS", 0.15), Candidate(4000, "PASS", 0.08),
       Candidate(8000, "FLAGGED", 0.075), Candidate(16000, "FLAGGED", 0.2)});
  EXPECT_EQ(s.highest_passing_hz, 4000.0);
  // From 4 kHz no higher rate lowers 0.08 mm by more than 10 % (0.075 >= 0.072).
  EXPECT_EQ(s.error_stops_improving_hz, 4000.0);
}

TEST(SummariseValidation, StillImprovingAtTheHighestCandidate) {
  const ValidationSummary s =
      SummariseValidation({Candidate(1000, "FLAGGED", 0.30), Candidate(2000, "ABORTED", 0.15),
                           Candidate(4000, "FLAGGED", 0.08), Candidate(8000, "FLAGGED", 0.04)});
  EXPECT_FALSE(s.highest_passing_hz.has_value());
  EXPECT_FALSE(s.error_stops_improving_hz.has_value());
}

TEST(SummariseValidation, SkipsErrorsThatAreNotNumbers) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ValidationSummary s =
      SummariseValidation({Candidate(1000, "PASS", 0.30), Candidate(2000, "PASS", nan),
                           Candidate(4000, "PASS", 0.10), Candidate(8000, "PASS", 0.099)});
  EXPECT_EQ(s.highest_passing_hz, 8000.0);
  EXPECT_EQ(s.error_stops_improving_hz, 4000.0);
}

TEST(SummariseValidation, EmptyAndSingleRunSayNothing) {
  EXPECT_FALSE(SummariseValidation({}).error_stops_improving_hz.has_value());
  const ValidationSummary one = SummariseValidation({Candidate(1000, "PASS", 0.3)});
  EXPECT_EQ(one.highest_passing_hz, 1000.0);
  EXPECT_FALSE(one.error_stops_improving_hz.has_value());
}

std::string RefusalOf(const std::vector<double>& rates_hz) {
  try {
    CheckCandidateRates(rates_hz, 50'000.0);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CheckCandidateRates, AcceptsAnAscendingListWithinTheLimits) {
  EXPECT_NO_THROW(CheckCandidateRates({1.0, 1000.0, 2000.0, 50'000.0}, 50'000.0));
}

TEST(CheckCandidateRates, NamesTheProblem) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(RefusalOf({}),
              HasSubstr("the candidate list is empty; give rates in Hz, e.g. 1000,2000,4000"));
  EXPECT_THAT(RefusalOf({1000.0, 4000.0, 2000.0}),
              HasSubstr("strictly ascending: entry 3 (2000 Hz) is below entry 2 (4000 Hz)"));
  EXPECT_THAT(RefusalOf({1000.0, 2000.0, 2000.0}),
              HasSubstr("entry 3 (2000 Hz) duplicates entry 2 (2000 Hz)"));
  EXPECT_THAT(RefusalOf({1000.0, 60'000.0}),
              HasSubstr("candidate rate 60000 Hz (entry 2) is above 50000 Hz: 50000 Hz is the "
                        "scheduler's limit"));
  EXPECT_THAT(RefusalOf({0.0, 1000.0}), HasSubstr("candidate rate 0 Hz (entry 1) is below 1 Hz"));
  EXPECT_THAT(RefusalOf({1000.0, nan}),
              HasSubstr("candidate rate nan Hz (entry 2) is not a finite number"));
}

}  // namespace
}  // namespace hiltwin::analysis
