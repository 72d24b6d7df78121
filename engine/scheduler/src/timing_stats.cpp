#include "hiltwin/scheduler/timing_stats.h"

#include <limits>

namespace hiltwin::scheduler {

void TimingStats::Reset() noexcept {
  histogram_.Reset();
  min_ns_ = std::numeric_limits<std::int64_t>::max();
  max_ns_ = std::numeric_limits<std::int64_t>::min();
  sum_ns_ = 0;
  last_ns_ = std::numeric_limits<std::int64_t>::min();
}

TimingSummary TimingStats::Summary() const noexcept {
  TimingSummary s;
  s.count = count();
  if (s.count == 0) return s;
  s.min_ns = min_ns_;
  s.max_ns = max_ns_;
  s.mean_ns = static_cast<double>(sum_ns_) / static_cast<double>(s.count);
  s.p50_ns = histogram_.ValueAtQuantile(0.50);
  s.p99_ns = histogram_.ValueAtQuantile(0.99);
  s.p999_ns = histogram_.ValueAtQuantile(0.999);
  return s;
}

}  // namespace hiltwin::scheduler
