#pragma once
/// Constant-memory histogram of non-negative nanosecond values with log-linear buckets
/// (HDR-histogram style): exact below 256 ns, then 128 linear sub-buckets per power of two,
/// so any reported percentile is within 1/256 (0.4 %) of a value that was recorded.

#include <cstdint>
#include <vector>

namespace hiltwin::scheduler {

class LogLinearHistogram {
 public:
  /// Sub-buckets per power of two above the exact range (bucket width / value ≤ 1/128).
  static constexpr int kSubBucketBits = 7;
  /// Largest value kept apart from the top bucket: 2^40 ns ≈ 18 minutes.
  static constexpr int kMaxValueBits = 40;

  /// Allocates all buckets (about 36 KiB); Record never allocates.
  LogLinearHistogram();

  /// Adds one value; negative values count as 0, values ≥ 2^40 ns land in the top bucket.
  void Record(std::int64_t value_ns) noexcept;
  void Reset() noexcept;

  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  /// Value at quantile q ∈ [0, 1] (nearest rank, the bucket's midpoint, clamped to the
  /// observed min/max). Returns 0 when empty.
  [[nodiscard]] std::int64_t ValueAtQuantile(double q) const noexcept;

  /// Bucket index for a value, and the [low, high) value range of a bucket: public for tests.
  [[nodiscard]] static std::size_t BucketIndex(std::int64_t value_ns) noexcept;
  [[nodiscard]] static std::int64_t BucketLow(std::size_t index) noexcept;
  [[nodiscard]] static std::int64_t BucketHigh(std::size_t index) noexcept;
  [[nodiscard]] static std::size_t BucketCount() noexcept;
  /// Values recorded in bucket `index` (0 past the last bucket): the bins of a plotted histogram.
  [[nodiscard]] std::uint64_t CountAt(std::size_t index) const noexcept {
    return index < counts_.size() ? counts_[index] : 0;
  }

 private:
  std::vector<std::uint64_t> counts_;
  std::uint64_t count_ = 0;
  std::int64_t min_ns_ = 0;
  std::int64_t max_ns_ = 0;
};

}  // namespace hiltwin::scheduler
