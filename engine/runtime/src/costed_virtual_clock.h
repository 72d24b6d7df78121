#pragma once
// The virtual clock with a wake-up latency table (virtual_costs.h): sleeping to a future
// release jumps there plus the next latency of the table. Private to the runtime: RunSession
// builds it for a virtual session that has wake-up latencies to charge.

#include <cstddef>
#include <utility>
#include <vector>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::runtime {

class CostedVirtualClock final : public kernel_glue::Clock {
 public:
  /// `wake_latency_ns` must not be empty (use kernel_glue::VirtualClock then).
  explicit CostedVirtualClock(std::vector<kernel_glue::TimeNs> wake_latency_ns)
      : wake_latency_ns_(std::move(wake_latency_ns)) {}
  [[nodiscard]] kernel_glue::TimeNs NowNs() const noexcept override { return now_ns_; }
  void SleepUntilNs(kernel_glue::TimeNs deadline_ns) noexcept override {
    if (deadline_ns <= now_ns_) return;  // already late: no sleep, so no wake-up latency
    now_ns_ = deadline_ns + wake_latency_ns_[next_];
    next_ = next_ + 1 == wake_latency_ns_.size() ? 0 : next_ + 1;
  }
  void SpendNs(kernel_glue::TimeNs duration_ns) noexcept override {
    if (duration_ns > 0) now_ns_ += duration_ns;
  }
  [[nodiscard]] bool IsVirtual() const noexcept override { return true; }

 private:
  std::vector<kernel_glue::TimeNs> wake_latency_ns_;
  std::size_t next_ = 0;
  kernel_glue::TimeNs now_ns_ = 0;
};

}  // namespace hiltwin::runtime
