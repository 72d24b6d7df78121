#include "hiltwin/scheduler/executive.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hiltwin::scheduler {

void ValidateRateHz(double rate_hz) {
  if (!std::isfinite(rate_hz) || rate_hz < kMinRateHz || rate_hz > kMaxRateHz) {
    throw std::invalid_argument("update rate " + std::to_string(rate_hz) +
                                " Hz is outside the supported range 1 Hz to 50000 Hz; "
                                "choose a rate in that range (the RELbot twin runs at 4000 Hz)");
  }
}

void Validate(const ExecutiveConfig& config) {
  const TimeNs min_period_ns = kernel_glue::PeriodNsFromRateHz(kMaxRateHz);
  const TimeNs max_period_ns = kernel_glue::PeriodNsFromRateHz(kMinRateHz);
  if (config.period_ns < min_period_ns || config.period_ns > max_period_ns) {
    throw std::invalid_argument("period " + std::to_string(config.period_ns) +
                                " ns is outside 20000 ns (50 kHz) to 1 s (1 Hz)");
  }
  if (config.deadline_ns < 0 || config.deadline_ns > config.period_ns) {
    throw std::invalid_argument("deadline " + std::to_string(config.deadline_ns) +
                                " ns must be between 1 ns and the period (" +
                                std::to_string(config.period_ns) + " ns); 0 means the period");
  }
  if (config.start_delay_ns < 0) {
    throw std::invalid_argument("start delay must not be negative");
  }
  if (config.recent_samples_capacity == 0) {
    throw std::invalid_argument("recent_samples_capacity must be at least 1");
  }
}

const char* ToString(StopCause cause) noexcept {
  switch (cause) {
    case StopCause::kCycleLimit: return "cycle_limit";
    case StopCause::kStopRequested: return "stop_requested";
    case StopCause::kTaskStopped: return "task_stopped";
    case StopCause::kObserverStopped: return "observer_stopped";
  }
  return "unknown";
}

Executive::Executive(kernel_glue::Clock& clock, const ExecutiveConfig& config)
    : clock_(clock),
      config_(config),
      deadline_ns_(config.deadline_ns == 0 ? config.period_ns : config.deadline_ns) {
  Validate(config);
  recent_.resize(config.recent_samples_capacity);
}

void Executive::AddObserver(CycleObserver& observer) {
  if (observer_count_ == kMaxObservers) {
    throw std::length_error("at most " + std::to_string(kMaxObservers) + " cycle observers");
  }
  observers_[observer_count_++] = &observer;
}

// Inline in Run: the work of every cycle, so no call and no copy of the sample.
[[gnu::always_inline]] inline void Executive::Account(const TimingSample& sample,
                                                      bool has_previous_start,
                                                      TimeNs previous_start_ns,
                                                      bool loop_was_idle) noexcept {
  const TimeNs latency_ns = sample.wake_ns - sample.release_ns;
  const TimeNs response_ns = sample.end_ns - sample.release_ns;
  // Wake-up latency is the OS's share only when the loop was asleep at the release; a cycle
  // that starts behind (catch-up after an overrun) is late because of the model, and that
  // lateness shows in its response time instead.
  if (loop_was_idle) stats_.wake_latency.Record(latency_ns);
  stats_.compute.Record(sample.end_ns - sample.start_ns - sample.io_ns);
  stats_.io.Record(sample.io_ns);
  stats_.response.Record(response_ns);
  if (has_previous_start) {
    stats_.period_jitter.Record(sample.start_ns - previous_start_ns - config_.period_ns);
  }
  ++stats_.cycles_run;
  stats_.releases += 1 + sample.releases_skipped;
  stats_.releases_skipped += sample.releases_skipped;

  // The sample was written in place in the ring (Run): only the ring's indices move here.
  recent_next_ = recent_next_ + 1 == recent_.size() ? 0 : recent_next_ + 1;
  ++recent_count_;

  live_.cycles_run.store(stats_.cycles_run, std::memory_order_relaxed);
  if (loop_was_idle && latency_ns > live_.max_latency_ns.load(std::memory_order_relaxed)) {
    live_.max_latency_ns.store(latency_ns, std::memory_order_relaxed);
  }
  if (response_ns > live_.max_response_ns.load(std::memory_order_relaxed)) {
    live_.max_response_ns.store(response_ns, std::memory_order_relaxed);
  }
}

StopCause Executive::Run(CyclicTask& task) noexcept {
  const TimeNs period_ns = config_.period_ns;
  t0_ns_ = clock_.NowNs() + (config_.start_delay_ns > 0 ? config_.start_delay_ns : period_ns);
  std::uint64_t k = 0;
  bool has_previous_start = false;
  TimeNs previous_start_ns = 0;
  TimeNs previous_end_ns = clock_.NowNs();

  for (;;) {
    if (config_.max_cycles != 0 && k >= config_.max_cycles) return StopCause::kCycleLimit;
    if (stop_requested_ != nullptr && stop_requested_()) return StopCause::kStopRequested;

    // Written in place in the ring of recent samples; Account moves the ring on.
    TimingSample& sample = recent_[recent_next_];
    sample.cycle = k;
    sample.release_ns = t0_ns_ + static_cast<TimeNs>(k) * period_ns;
    const bool loop_was_idle = previous_end_ns <= sample.release_ns;
    // A release the previous step ended after has passed: the catch-up cycle starts at once,
    // without a system call to be told so (clock_nanosleep costs microseconds under a trace).
    if (loop_was_idle) clock_.SleepUntilNs(sample.release_ns);
    sample.wake_ns = clock_.NowNs();
    sample.start_ns = sample.wake_ns;  // nothing runs between the wake-up and the step
    const CycleContext context{k, sample.release_ns, period_ns,
                               static_cast<TimeNs>(k) * period_ns, sample.start_ns};
    const CycleAction task_action = task.Step(context);
    sample.end_ns = clock_.NowNs();
    sample.io_ns = task.IoNsOfLastStep();
    sample.missed = sample.end_ns > sample.release_ns + deadline_ns_;

    std::uint64_t next = NextReleaseIndex(config_.overrun_policy, k, sample.end_ns, t0_ns_, period_ns);
    if (config_.max_cycles != 0) next = std::min(next, std::max(config_.max_cycles, k + 1));
    sample.releases_skipped = static_cast<std::uint32_t>(next - k - 1);

    Account(sample, has_previous_start, previous_start_ns, loop_was_idle);
    has_previous_start = sample.releases_skipped == 0;  // jitter only between neighbours
    previous_start_ns = sample.start_ns;
    previous_end_ns = sample.end_ns;

    bool observer_stop = false;
    for (std::size_t i = 0; i < observer_count_; ++i) {
      observer_stop |= observers_[i]->OnCycle(sample) == CycleAction::kStop;
    }
    if (task_action == CycleAction::kStop) return StopCause::kTaskStopped;
    if (observer_stop) return StopCause::kObserverStopped;
    k = next;
  }
}

std::vector<TimingSample> Executive::RecentSamples() const {
  const std::size_t n =
      static_cast<std::size_t>(std::min<std::uint64_t>(recent_count_, recent_.size()));
  std::vector<TimingSample> out;
  out.reserve(n);
  const std::size_t first = (recent_next_ + recent_.size() - n) % recent_.size();
  for (std::size_t i = 0; i < n; ++i) out.push_back(recent_[(first + i) % recent_.size()]);
  return out;
}

}  // namespace hiltwin::scheduler
