#pragma once
/// Constant-memory histogram of non-negative nanosecond values with log-linear buckets
/// (HDR-histogram style): exact below 256 ns, then 128 linear sub-buckets per power of two,
/// so any reported percentile is within 1/256 (0.4 %) of a value that was recorded.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
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
  /// Inline and branch-free but for the top bucket: the loop records several values a cycle.
  void Record(std::int64_t value_ns) noexcept {
    value_ns = std::max<std::int64_t>(value_ns, 0);
    last_index_ = BucketIndex(value_ns);
    ++counts_[last_index_];
    // The sentinels of an empty histogram (Reset) make the first value both extremes.
    min_ns_ = std::min(min_ns_, value_ns);
    max_ns_ = std::max(max_ns_, value_ns);
    ++count_;
  }
  /// Adds the value recorded last once more (after at least one Record): its bucket is known
  /// and the extremes cannot move.
  void RecordLastAgain() noexcept {
    ++counts_[last_index_];
    ++count_;
  }
  void Reset() noexcept;

  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  /// Value at quantile q ∈ [0, 1] (nearest rank, the bucket's midpoint, clamped to the
  /// observed min/max). Returns 0 when empty.
  [[nodiscard]] std::int64_t ValueAtQuantile(double q) const noexcept;

  /// Bucket index for a value, and the [low, high) value range of a bucket: public for tests.
  /// Values below 256 are their own index; above, the power of two (shift) and the top
  /// kSubBucketBits + 1 bits of the value: index = shift·128 + (value >> shift).
  [[nodiscard]] static std::size_t BucketIndex(std::int64_t value_ns) noexcept {
    if (value_ns < 0) return 0;
    const auto v = static_cast<std::uint64_t>(value_ns);
    const int msb = 63 - std::countl_zero(v | 1U);
    const int shift = std::max(msb - kSubBucketBits, 0);
    if (shift > kMaxShift) [[unlikely]] return BucketCount() - 1;
    return (static_cast<std::size_t>(shift) << kSubBucketBits) +
           static_cast<std::size_t>(v >> shift);
  }
  [[nodiscard]] static std::int64_t BucketLow(std::size_t index) noexcept;
  [[nodiscard]] static std::int64_t BucketHigh(std::size_t index) noexcept;
  [[nodiscard]] static constexpr std::size_t BucketCount() noexcept {
    return (std::size_t{2} << kSubBucketBits) +
           static_cast<std::size_t>(kMaxShift) * (std::size_t{1} << kSubBucketBits);
  }
  /// Values recorded in bucket `index` (0 past the last bucket): the bins of a plotted histogram.
  [[nodiscard]] std::uint64_t CountAt(std::size_t index) const noexcept {
    return index < counts_.size() ? counts_[index] : 0;
  }

 private:
  static constexpr int kMaxShift = kMaxValueBits - kSubBucketBits;

  std::vector<std::uint64_t> counts_;
  std::uint64_t count_ = 0;
  std::int64_t min_ns_ = std::numeric_limits<std::int64_t>::max();  // of the values recorded
  std::int64_t max_ns_ = 0;
  std::size_t last_index_ = 0;  // bucket of the value recorded last
};

}  // namespace hiltwin::scheduler
