#pragma once
/// What an application (a plant twin, a controller) gives the run assembly: one exchange with
/// the board and one computation step per cycle, plus its log columns. Both calls run on the
/// real-time loop thread, so they must not allocate, block, print or throw; they report how
/// the cycle went with status values, and RunSession alone turns those into lifecycle events.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/io/exchange_status.h"
#include "hiltwin/runtime/telemetry.h"
#include "hiltwin/scheduler/cycle.h"

namespace hiltwin::runtime {

/// How a computation step ended.
struct StepStatus {
  enum class Code : std::uint8_t {
    kOk,
    kModelFault,  ///< the state became non-finite (a diverged model, a broken controller)
    kFinished,    ///< the task has nothing more to do (e.g. its setpoint profile ended)
  };
  Code code = Code::kOk;
  const char* reason = "";  ///< static text: why, for kModelFault

  [[nodiscard]] static StepStatus Ok() noexcept { return {}; }
  [[nodiscard]] static StepStatus ModelFault(const char* why) noexcept {
    return {Code::kModelFault, why};
  }
};

/// The application's cyclic work. Per cycle the session calls Exchange, then (only while the
/// lifecycle lets the model step) Step: the outputs computed in cycle k go out in cycle k+1,
/// one full-duplex frame per cycle (the one-period delay of thesis §3.7).
class RunTask {
 public:
  virtual ~RunTask() = default;

  /// One full-duplex frame with the board: sends the outputs of the last step, or the safe
  /// outputs when `live_outputs` is false (paused, stopping, after a fault), and receives the
  /// inputs for the next step. On an error the inputs must stay as they were (held).
  virtual io::ExchangeStatus Exchange(bool live_outputs) noexcept = 0;

  /// The model or controller step on the inputs of the last exchange.
  virtual StepStatus Step(const scheduler::CycleContext& context) noexcept = 0;

  /// Names of the task's log columns (after time_s; the session appends its timing columns).
  [[nodiscard]] virtual std::vector<std::string> LogColumns() const = 0;
  /// The task's time in seconds (model time) and values for the last completed step, one per
  /// LogColumns() entry. Real-time path.
  [[nodiscard]] virtual double LogTimeS() const noexcept = 0;
  virtual void FillLogRow(std::span<double> values) const noexcept = 0;

  /// What the task publishes as telemetry (telemetry.h); called once, before the run.
  [[nodiscard]] virtual TelemetryShape TelemetryShapeOf() const { return {}; }
  /// The task's telemetry values for the last completed step, matching TelemetryShapeOf().
  /// Real-time path: called every cycle while telemetry is on.
  virtual void FillTelemetry(TaskTelemetry& out) const noexcept { static_cast<void>(out); }
};

}  // namespace hiltwin::runtime
