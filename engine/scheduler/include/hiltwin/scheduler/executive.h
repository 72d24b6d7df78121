#pragma once
/// The cyclic executive: runs a CyclicTask at a fixed period on absolute release times
/// t0 + k·period, captures {k, release, wake, start, end} for every cycle, keeps streaming
/// statistics, detects deadline misses and applies the overrun policy. The same loop runs on
/// the monotonic clock (real time) or the virtual clock (tests, as-fast-as-possible runs).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/scheduler/cycle.h"
#include "hiltwin/scheduler/overrun_policy.h"
#include "hiltwin/scheduler/timing_stats.h"

namespace hiltwin::scheduler {

/// Accepted update rates (docs/architecture.md, "Commands": 1 Hz – 50 kHz).
constexpr double kMinRateHz = 1.0;
constexpr double kMaxRateHz = 50'000.0;

/// Plain configuration, unit-suffixed (cactus-rt style). Validate() says what is wrong.
struct ExecutiveConfig {
  TimeNs period_ns = 250'000;  ///< 4 kHz
  TimeNs deadline_ns = 0;      ///< 0 = the period; may be shorter, never longer
  OverrunPolicy overrun_policy = OverrunPolicy::kCatchUp;
  std::uint64_t max_cycles = 0;  ///< releases to run (0 = until stopped)
  TimeNs start_delay_ns = 0;     ///< t0 = now + this (0 = one period), time to settle
  std::size_t recent_samples_capacity = 4096;  ///< ring of the latest samples, preallocated
};

/// Throws std::invalid_argument naming the offending value when the rate is outside
/// [kMinRateHz, kMaxRateHz] or not finite.
void ValidateRateHz(double rate_hz);
/// Throws std::invalid_argument when the configuration is inconsistent.
void Validate(const ExecutiveConfig& config);

/// Why Run() returned.
enum class StopCause {
  kCycleLimit,     ///< max_cycles releases done
  kStopRequested,  ///< the stop flag was raised (SIGINT/SIGTERM or a command)
  kTaskStopped,    ///< the task returned kStop
  kObserverStopped ///< an observer returned kStop (e.g. the QoS monitor under policy abort)
};
[[nodiscard]] const char* ToString(StopCause cause) noexcept;

/// Counters written by the loop and readable from any thread (progress display, telemetry).
/// Misses are not here: the QoS monitor is the one miss ledger.
struct LiveCounters {
  std::atomic<std::uint64_t> cycles_run{0};
  std::atomic<std::int64_t> max_latency_ns{0};
  std::atomic<std::int64_t> max_response_ns{0};
};

/// Timing statistics of a run; read them after Run() returns. Whether a cycle missed is
/// decided here (TimingSample::missed), but misses are counted by the QoS monitor alone.
struct ExecutiveStats {
  std::uint64_t cycles_run = 0;        ///< steps executed
  std::uint64_t releases = 0;          ///< releases consumed (run + skipped)
  std::uint64_t releases_skipped = 0;  ///< by the kSkip policy
  TimingStats wake_latency;   ///< wake - release of cycles whose release found the loop
                              ///< asleep: the OS's share (catch-up cycles are not in it)
  TimingStats compute;        ///< end - start - io: the step's own computation
  TimingStats io;             ///< the step's I/O time (CyclicTask::IoNsOfLastStep)
  TimingStats response;       ///< end - release
  TimingStats period_jitter;  ///< (start_k - start_{k-1}) - period, consecutive cycles only
};

class Executive {
 public:
  static constexpr std::size_t kMaxObservers = 8;

  /// Allocates everything the loop needs; throws std::invalid_argument on a bad config.
  Executive(kernel_glue::Clock& clock, const ExecutiveConfig& config);

  /// Adds an observer (not owned). Throws std::length_error past kMaxObservers. Not while running.
  void AddObserver(CycleObserver& observer);
  /// A flag polled once per cycle, e.g. kernel_glue::StopRequested. May be null.
  void SetStopCheck(bool (*stop_requested)() noexcept) noexcept { stop_requested_ = stop_requested; }

  /// Runs until max_cycles, a stop request, or a kStop from the task or an observer.
  /// Real-time safe: no allocation, no locks, no I/O, no exceptions.
  StopCause Run(CyclicTask& task) noexcept;

  [[nodiscard]] const ExecutiveStats& stats() const noexcept { return stats_; }
  [[nodiscard]] const LiveCounters& live() const noexcept { return live_; }
  [[nodiscard]] const ExecutiveConfig& config() const noexcept { return config_; }
  [[nodiscard]] TimeNs deadline_ns() const noexcept { return deadline_ns_; }
  [[nodiscard]] TimeNs t0_ns() const noexcept { return t0_ns_; }
  /// The latest samples, oldest first, up to recent_samples_capacity.
  [[nodiscard]] std::vector<TimingSample> RecentSamples() const;

 private:
  void Account(const TimingSample& sample, bool has_previous_start, TimeNs previous_start_ns,
               bool loop_was_idle) noexcept;

  kernel_glue::Clock& clock_;
  ExecutiveConfig config_;
  TimeNs deadline_ns_;
  TimeNs t0_ns_ = 0;
  std::array<CycleObserver*, kMaxObservers> observers_{};
  std::size_t observer_count_ = 0;
  bool (*stop_requested_)() noexcept = nullptr;
  ExecutiveStats stats_;
  LiveCounters live_;
  std::vector<TimingSample> recent_;  // ring buffer, preallocated
  std::size_t recent_next_ = 0;
  std::uint64_t recent_count_ = 0;
};

}  // namespace hiltwin::scheduler
