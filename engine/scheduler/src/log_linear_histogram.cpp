#include "hiltwin/scheduler/log_linear_histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hiltwin::scheduler {
namespace {

constexpr std::int64_t kSubBuckets = std::int64_t{1} << LogLinearHistogram::kSubBucketBits;
// Values below 2*kSubBuckets get one bucket each (exact); above, each power of two gets
// kSubBuckets buckets of width 2^shift.
constexpr std::size_t kExactBuckets = static_cast<std::size_t>(2 * kSubBuckets);

}  // namespace

LogLinearHistogram::LogLinearHistogram() : counts_(BucketCount(), 0) {}

std::int64_t LogLinearHistogram::BucketLow(std::size_t index) noexcept {
  if (index < kExactBuckets) return static_cast<std::int64_t>(index);
  const std::size_t rest = index - kExactBuckets;
  const int shift = static_cast<int>(rest / static_cast<std::size_t>(kSubBuckets)) + 1;
  const auto mantissa = static_cast<std::int64_t>(rest % static_cast<std::size_t>(kSubBuckets)) + kSubBuckets;
  return mantissa << shift;
}

std::int64_t LogLinearHistogram::BucketHigh(std::size_t index) noexcept {
  if (index < kExactBuckets) return static_cast<std::int64_t>(index) + 1;
  const std::size_t rest = index - kExactBuckets;
  const int shift = static_cast<int>(rest / static_cast<std::size_t>(kSubBuckets)) + 1;
  return BucketLow(index) + (std::int64_t{1} << shift);
}

void LogLinearHistogram::Reset() noexcept {
  std::fill(counts_.begin(), counts_.end(), 0);
  count_ = 0;
  min_ns_ = std::numeric_limits<std::int64_t>::max();
  max_ns_ = 0;
}

std::int64_t LogLinearHistogram::ValueAtQuantile(double q) const noexcept {
  if (count_ == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  // Nearest rank: the smallest value with at least ceil(q*n) values at or below it.
  auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  rank = std::clamp<std::uint64_t>(rank, 1, count_);
  // The extremes are known exactly; the top bucket is open-ended, so never estimate them.
  if (rank == count_) return max_ns_;
  if (rank == 1) return min_ns_;
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    seen += counts_[i];
    if (seen >= rank) {
      const std::int64_t low = BucketLow(i);
      const std::int64_t high = BucketHigh(i);
      // Exact buckets hold a single value; wider ones report their midpoint.
      const std::int64_t mid = (high - low == 1) ? low : low + (high - low) / 2;
      return std::clamp(mid, min_ns_, max_ns_);
    }
  }
  return max_ns_;
}

}  // namespace hiltwin::scheduler
