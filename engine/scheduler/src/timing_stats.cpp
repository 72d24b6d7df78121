#include "hiltwin/scheduler/timing_stats.h"

#include <algorithm>

namespace hiltwin::scheduler {

void TimingStats::Record(std::int64_t value_ns) noexcept {
  if (count_ == 0) {
    min_ns_ = max_ns_ = value_ns;
  } else {
    min_ns_ = std::min(min_ns_, value_ns);
    max_ns_ = std::max(max_ns_, value_ns);
  }
  ++count_;
  sum_ns_ += value_ns;
  histogram_.Record(value_ns < 0 ? -value_ns : value_ns);
}

void TimingStats::Reset() noexcept {
  histogram_.Reset();
  count_ = 0;
  min_ns_ = max_ns_ = sum_ns_ = 0;
}

TimingSummary TimingStats::Summary() const noexcept {
  TimingSummary s;
  s.count = count_;
  if (count_ == 0) return s;
  s.min_ns = min_ns_;
  s.max_ns = max_ns_;
  s.mean_ns = static_cast<double>(sum_ns_) / static_cast<double>(count_);
  s.p50_ns = histogram_.ValueAtQuantile(0.50);
  s.p99_ns = histogram_.ValueAtQuantile(0.99);
  s.p999_ns = histogram_.ValueAtQuantile(0.999);
  return s;
}

}  // namespace hiltwin::scheduler
