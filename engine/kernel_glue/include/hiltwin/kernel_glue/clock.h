#pragma once
/// Clocks: one interface for the real monotonic clock and a virtual clock for tests and
/// as-fast-as-possible simulation. All times are integer nanoseconds on one timeline.

#include <cstdint>

namespace hiltwin::kernel_glue {

/// Time in nanoseconds on a clock's own timeline (CLOCK_MONOTONIC for the real clock).
using TimeNs = std::int64_t;

constexpr TimeNs kNsPerUs = 1'000;
constexpr TimeNs kNsPerMs = 1'000'000;
constexpr TimeNs kNsPerS = 1'000'000'000;

/// The loop's only source of time. Implementations never throw and never allocate.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Current time on this clock.
  [[nodiscard]] virtual TimeNs NowNs() const noexcept = 0;
  /// Blocks until the clock reads at least `deadline_ns` (absolute). Returns at once when
  /// that time has passed. The real clock retries on EINTR, so a signal never shortens a sleep.
  virtual void SleepUntilNs(TimeNs deadline_ns) noexcept = 0;
  /// Spends `duration_ns` of busy time: the real clock spins, the virtual clock advances.
  /// Used to inject compute time (fault injection, tests) identically on both clocks.
  virtual void SpendNs(TimeNs duration_ns) noexcept = 0;
  /// True when time only moves when told (virtual); lets callers skip wall-clock-only work.
  [[nodiscard]] virtual bool IsVirtual() const noexcept = 0;
};

/// CLOCK_MONOTONIC with absolute sleeps (clock_nanosleep TIMER_ABSTIME): releases computed
/// as t0 + k*period never drift, whatever the sleep's own latency.
class MonotonicClock final : public Clock {
 public:
  [[nodiscard]] TimeNs NowNs() const noexcept override;
  void SleepUntilNs(TimeNs deadline_ns) noexcept override;
  void SpendNs(TimeNs duration_ns) noexcept override;
  [[nodiscard]] bool IsVirtual() const noexcept override { return false; }
};

/// A clock that advances only when told: sleeping jumps to the deadline, spending adds.
/// Deterministic, so timing logic can be tested exactly and simulation runs flat out.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(TimeNs start_ns = 0) noexcept : now_ns_(start_ns) {}
  [[nodiscard]] TimeNs NowNs() const noexcept override { return now_ns_; }
  void SleepUntilNs(TimeNs deadline_ns) noexcept override {
    if (deadline_ns > now_ns_) now_ns_ = deadline_ns;
  }
  void SpendNs(TimeNs duration_ns) noexcept override {
    if (duration_ns > 0) now_ns_ += duration_ns;
  }
  [[nodiscard]] bool IsVirtual() const noexcept override { return true; }
  /// Moves time forward by `delta_ns` (negative values are ignored: time never runs back).
  void AdvanceNs(TimeNs delta_ns) noexcept { SpendNs(delta_ns); }

 private:
  TimeNs now_ns_;
};

/// Converts a rate in hertz to a whole-nanosecond period (rounded to nearest).
[[nodiscard]] constexpr TimeNs PeriodNsFromRateHz(double rate_hz) noexcept {
  return static_cast<TimeNs>(static_cast<double>(kNsPerS) / rate_hz + 0.5);
}

}  // namespace hiltwin::kernel_glue
