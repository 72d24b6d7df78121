#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <random>
#include <vector>

#include "hiltwin/scheduler/log_linear_histogram.h"
#include "hiltwin/scheduler/timing_stats.h"

namespace hiltwin::scheduler {
namespace {

std::int64_t NearestRank(std::vector<std::int64_t> sorted, double q) {
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

TEST(LogLinearHistogram, BucketsTileTheRangeWithoutGaps) {
  for (std::size_t i = 0; i + 1 < LogLinearHistogram::BucketCount(); ++i) {
    ASSERT_EQ(LogLinearHistogram::BucketHigh(i), LogLinearHistogram::BucketLow(i + 1)) << i;
  }
  for (std::int64_t v : {0LL, 1LL, 255LL, 256LL, 257LL, 511LL, 512LL, 123456789LL, (1LL << 40) - 1}) {
    const std::size_t i = LogLinearHistogram::BucketIndex(v);
    EXPECT_LE(LogLinearHistogram::BucketLow(i), v) << v;
    EXPECT_GT(LogLinearHistogram::BucketHigh(i), v) << v;
    // Width relative to value: the 1 % accuracy promise.
    EXPECT_LE(static_cast<double>(LogLinearHistogram::BucketHigh(i) - LogLinearHistogram::BucketLow(i)),
              std::max(1.0, static_cast<double>(v) / 128.0)) << v;
  }
}

TEST(LogLinearHistogram, SmallValuesAreExact) {
  LogLinearHistogram h;
  for (std::int64_t v = 1; v <= 100; ++v) h.Record(v);
  EXPECT_EQ(h.ValueAtQuantile(0.5), 50);
  EXPECT_EQ(h.ValueAtQuantile(0.99), 99);
  EXPECT_EQ(h.ValueAtQuantile(1.0), 100);
  EXPECT_EQ(h.ValueAtQuantile(0.0), 1);
}

TEST(LogLinearHistogram, PercentilesWithinOnePercentOfExactSortedData) {
  std::mt19937_64 rng(42);
  // Heavy-tailed like real latencies: mostly ~15 µs, a tail to a few hundred µs.
  std::lognormal_distribution<double> dist(std::log(15'000.0), 0.6);
  std::vector<std::int64_t> values;
  LogLinearHistogram h;
  for (int i = 0; i < 200'000; ++i) {
    const auto v = static_cast<std::int64_t>(dist(rng));
    values.push_back(v);
    h.Record(v);
  }
  std::sort(values.begin(), values.end());
  for (double q : {0.01, 0.5, 0.9, 0.99, 0.999, 0.9999}) {
    const double exact = static_cast<double>(NearestRank(values, q));
    const double got = static_cast<double>(h.ValueAtQuantile(q));
    EXPECT_NEAR(got, exact, 0.01 * exact) << "q=" << q;
  }
  EXPECT_EQ(h.ValueAtQuantile(1.0), values.back());
  EXPECT_EQ(h.ValueAtQuantile(0.0), values.front());
}

TEST(LogLinearHistogram, HugeAndNegativeValuesAreClampedNotLost) {
  LogLinearHistogram h;
  h.Record(-5);
  h.Record(std::int64_t{1} << 50);
  EXPECT_EQ(h.count(), 2U);
  EXPECT_EQ(h.ValueAtQuantile(0.0), 0);
  EXPECT_EQ(h.ValueAtQuantile(1.0), std::int64_t{1} << 50);  // exact max survives
}

// The bucket index before it became branch-free (issue 36), kept as the reference.
std::size_t ReferenceBucketIndex(std::int64_t value_ns) {
  constexpr std::int64_t kSub = std::int64_t{1} << LogLinearHistogram::kSubBucketBits;
  if (value_ns < 2 * kSub) return value_ns < 0 ? 0 : static_cast<std::size_t>(value_ns);
  const auto v = static_cast<std::uint64_t>(value_ns);
  const int shift = 63 - std::countl_zero(v) - LogLinearHistogram::kSubBucketBits;
  if (shift > LogLinearHistogram::kMaxValueBits - LogLinearHistogram::kSubBucketBits) {
    return LogLinearHistogram::BucketCount() - 1;
  }
  const auto mantissa = static_cast<std::size_t>(v >> shift);
  return static_cast<std::size_t>(2 * kSub) +
         static_cast<std::size_t>(shift - 1) * static_cast<std::size_t>(kSub) +
         (mantissa - static_cast<std::size_t>(kSub));
}

TEST(LogLinearHistogram, BucketIndexEqualsTheReferenceEverywhere) {
  for (std::int64_t v = -1000; v < (std::int64_t{1} << 20); ++v) {
    ASSERT_EQ(LogLinearHistogram::BucketIndex(v), ReferenceBucketIndex(v)) << v;
  }
  for (int bit = 20; bit < 63; ++bit) {  // every power of two and its neighbours
    const std::int64_t p = std::int64_t{1} << bit;
    for (const std::int64_t v : {p - 1, p, p + 1, p + p / 3}) {
      ASSERT_EQ(LogLinearHistogram::BucketIndex(v), ReferenceBucketIndex(v)) << v;
    }
  }
  std::mt19937_64 rng(36);
  for (int i = 0; i < 1'000'000; ++i) {
    const auto v = static_cast<std::int64_t>(rng() >> (rng() % 64));
    ASSERT_EQ(LogLinearHistogram::BucketIndex(v), ReferenceBucketIndex(v)) << v;
  }
  EXPECT_EQ(LogLinearHistogram::BucketIndex(INT64_MIN), 0U);
  EXPECT_EQ(LogLinearHistogram::BucketIndex(INT64_MAX), LogLinearHistogram::BucketCount() - 1);
}

TEST(TimingStats, EmptyAndResetReadAsZeroWhateverWasRecorded) {
  TimingStats s;
  EXPECT_EQ(s.max_ns(), 0);
  EXPECT_EQ(s.count(), 0U);
  s.Record(-7);  // a single negative value is both extremes
  EXPECT_EQ(s.Summary().min_ns, -7);
  EXPECT_EQ(s.Summary().max_ns, -7);
  EXPECT_EQ(s.max_ns(), -7);
  EXPECT_EQ(s.Summary().p50_ns, 7);
  s.Reset();
  EXPECT_EQ(s.max_ns(), 0);
  const TimingSummary empty = s.Summary();
  EXPECT_EQ(empty.count, 0U);
  EXPECT_EQ(empty.min_ns, 0);
  EXPECT_EQ(empty.max_ns, 0);
  s.Record(5);
  EXPECT_EQ(s.Summary().min_ns, 5);  // not the sentinels of the empty statistics
  EXPECT_EQ(s.Summary().max_ns, 5);
  EXPECT_EQ(s.Summary().p999_ns, 5);
}

TEST(TimingStats, RunsOfEqualValuesCountLikeAnyOther) {
  // Runs of repeated values (the cheap path) mixed with changes, signed, against a histogram
  // fed every |value| and the exact figures.
  std::mt19937_64 rng(11);
  TimingStats s;
  LogLinearHistogram reference;
  std::int64_t lo = INT64_MAX, hi = INT64_MIN, sum = 0;
  std::int64_t v = 0;
  for (int i = 0; i < 200'000; ++i) {
    if (rng() % 4 == 0) v = static_cast<std::int64_t>(rng() % 2'000'001) - 1'000'000;
    s.Record(v);
    reference.Record(v < 0 ? -v : v);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
  }
  const TimingSummary got = s.Summary();
  EXPECT_EQ(got.count, 200'000U);
  EXPECT_EQ(got.min_ns, lo);
  EXPECT_EQ(got.max_ns, hi);
  EXPECT_DOUBLE_EQ(got.mean_ns, static_cast<double>(sum) / 200'000.0);
  for (const double q : {0.0, 0.5, 0.99, 0.999, 1.0}) {
    EXPECT_EQ(s.histogram().ValueAtQuantile(q), reference.ValueAtQuantile(q)) << q;
  }
  for (std::size_t i = 0; i < LogLinearHistogram::BucketCount(); ++i) {
    ASSERT_EQ(s.histogram().CountAt(i), reference.CountAt(i)) << i;
  }
  s.Reset();  // a value equal to the last before the reset is a first value again
  s.Record(v);
  EXPECT_EQ(s.Summary().count, 1U);
  EXPECT_EQ(s.Summary().min_ns, v);
  EXPECT_EQ(s.Summary().max_ns, v);
}

TEST(TimingStats, ExactMinMeanMaxAndSignedJitter) {
  TimingStats s;
  for (std::int64_t v : {-300, 100, 200, 1000}) s.Record(v);
  const TimingSummary sum = s.Summary();
  EXPECT_EQ(sum.count, 4U);
  EXPECT_EQ(sum.min_ns, -300);
  EXPECT_EQ(sum.max_ns, 1000);
  EXPECT_DOUBLE_EQ(sum.mean_ns, 250.0);
  EXPECT_EQ(sum.p50_ns, 200);  // percentiles of |value|: {100,200,300,1000}
  s.Reset();
  EXPECT_EQ(s.Summary().count, 0U);
}


TEST(LogLinearHistogram, PercentilesWithinOnePercentFromNanosecondsToMilliseconds) {
  // Log-uniform over 100 ns .. 10 ms: every octave of a VM's latencies, hypervisor stalls
  // included, weighs the same, so each power-of-two range of buckets is exercised.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> log_ns(std::log(100.0), std::log(10'000'000.0));
  std::vector<std::int64_t> values;
  LogLinearHistogram h;
  for (int i = 0; i < 200'000; ++i) {
    const auto v = static_cast<std::int64_t>(std::exp(log_ns(rng)));
    values.push_back(v);
    h.Record(v);
  }
  std::sort(values.begin(), values.end());
  for (double q : {0.001, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999, 0.9999}) {
    const double exact = static_cast<double>(NearestRank(values, q));
    const double got = static_cast<double>(h.ValueAtQuantile(q));
    EXPECT_NEAR(got, exact, 0.01 * exact) << "q=" << q;
  }
}

}  // namespace
}  // namespace hiltwin::scheduler
