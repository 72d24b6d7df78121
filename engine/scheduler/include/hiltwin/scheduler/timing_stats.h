#pragma once
/// Streaming statistics of one timing quantity (e.g. wake-up latency): exact count, min,
/// mean and max, percentiles from a log-linear histogram. Constant memory, O(1) per value.

#include <algorithm>
#include <cstdint>
#include <limits>

#include "hiltwin/scheduler/log_linear_histogram.h"

namespace hiltwin::scheduler {

/// Summary figures in nanoseconds, as they go into the run report.
struct TimingSummary {
  std::uint64_t count = 0;
  std::int64_t min_ns = 0;
  double mean_ns = 0.0;
  std::int64_t p50_ns = 0;
  std::int64_t p99_ns = 0;
  std::int64_t p999_ns = 0;
  std::int64_t max_ns = 0;
};

class TimingStats {
 public:
  /// Records a value. Signed quantities (period jitter) keep their signed min/max; the
  /// percentiles are of the magnitude |value|. Inline: the executive records four or five
  /// values a cycle. The count is the histogram's, kept once. A value equal to the one before
  /// (every cycle of a virtual run, and many of a real one at the clock's resolution) needs no
  /// bucket search and cannot move the extremes.
  void Record(std::int64_t value_ns) noexcept {
    sum_ns_ += value_ns;
    if (value_ns == last_ns_) {
      histogram_.RecordLastAgain();
      return;
    }
    last_ns_ = value_ns;
    min_ns_ = std::min(min_ns_, value_ns);
    max_ns_ = std::max(max_ns_, value_ns);
    histogram_.Record(value_ns < 0 ? -value_ns : value_ns);
  }
  void Reset() noexcept;
  [[nodiscard]] TimingSummary Summary() const noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept { return histogram_.count(); }
  [[nodiscard]] std::int64_t max_ns() const noexcept { return count() == 0 ? 0 : max_ns_; }
  [[nodiscard]] const LogLinearHistogram& histogram() const noexcept { return histogram_; }

 private:
  LogLinearHistogram histogram_;
  // Sentinels while empty, so that the first value is both extremes without a branch.
  std::int64_t min_ns_ = std::numeric_limits<std::int64_t>::max();
  std::int64_t max_ns_ = std::numeric_limits<std::int64_t>::min();
  // The value recorded last; the sentinel, which |value| cannot be recorded for, while empty.
  std::int64_t last_ns_ = std::numeric_limits<std::int64_t>::min();
  // Sum in long double-free integer form: 2^63 ns of total time cannot overflow in practice.
  std::int64_t sum_ns_ = 0;
};

}  // namespace hiltwin::scheduler
