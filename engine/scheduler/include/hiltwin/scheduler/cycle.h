#pragma once
/// The vocabulary shared by the executive, the user's step and the observers.

#include <cstdint>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::scheduler {

using kernel_glue::TimeNs;

/// Timing of one executed cycle, all on the executive's clock.
struct TimingSample {
  std::uint64_t cycle = 0;        ///< release index k (release = t0 + k·period)
  TimeNs release_ns = 0;          ///< when the cycle should have started
  TimeNs wake_ns = 0;             ///< when the sleep returned (catch-up: when it was skipped)
  TimeNs start_ns = 0;            ///< when the step began: the same clock reading as wake_ns
  TimeNs end_ns = 0;              ///< when the step (and its I/O) ended
  TimeNs io_ns = 0;               ///< of end - start, the time the step spent in I/O
  std::uint32_t releases_skipped = 0;  ///< releases after this one dropped by kSkip (each a miss)
  bool missed = false;            ///< end_ns > release_ns + deadline
};

/// What the step or an observer asks of the executive after a cycle.
enum class CycleAction { kContinue, kStop };

/// What the step is told about the cycle it runs in.
struct CycleContext {
  std::uint64_t cycle = 0;   ///< release index k
  TimeNs release_ns = 0;     ///< absolute release time
  TimeNs period_ns = 0;
  TimeNs model_time_ns = 0;  ///< k·period: the model time this step integrates to from
  TimeNs start_ns = 0;       ///< when this step began (the board exchange follows at once)
};

/// The user's cyclic work: I/O, model step, I/O. Runs on the real-time thread, so it must
/// not allocate, block, print or throw.
class CyclicTask {
 public:
  virtual ~CyclicTask() = default;
  virtual CycleAction Step(const CycleContext& context) noexcept = 0;
  /// How much of the last Step() was I/O (bus transfers), so that compute time and I/O time
  /// are reported apart. Tasks without I/O leave it 0. Not virtual: the executive reads it
  /// every cycle, and a field costs no call.
  [[nodiscard]] TimeNs IoNsOfLastStep() const noexcept { return io_ns_of_last_step_; }

 protected:
  /// A task with I/O sets its I/O time here during Step().
  void SetIoNsOfLastStep(TimeNs io_ns) noexcept { io_ns_of_last_step_ = io_ns; }

 private:
  TimeNs io_ns_of_last_step_ = 0;
};

/// Receives every cycle's timing right after the cycle (QoS, tracing, logging). One virtual
/// call per cycle and observer; the sample is passed whole, never field by field.
class CycleObserver {
 public:
  virtual ~CycleObserver() = default;
  virtual CycleAction OnCycle(const TimingSample& sample) noexcept = 0;
};

}  // namespace hiltwin::scheduler
