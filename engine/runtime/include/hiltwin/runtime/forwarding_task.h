#pragma once
/// A run task that wraps another and passes every call on to it: the base of the wrappers that
/// change one thing about a task (its board's faults, its telemetry) and keep the rest.

#include <span>
#include <string>
#include <vector>

#include "hiltwin/runtime/run_task.h"

namespace hiltwin::runtime {

/// Everything is the wrapped task's until a subclass overrides it. The task must outlive the
/// wrapper.
class ForwardingTask : public RunTask {
 public:
  explicit ForwardingTask(RunTask& task) noexcept : task_(task) {}

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override {
    return task_.Exchange(live_outputs);
  }
  StepStatus Step(const scheduler::CycleContext& context) noexcept override {
    return task_.Step(context);
  }
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return task_.LogColumns(); }
  [[nodiscard]] double LogTimeS() const noexcept override { return task_.LogTimeS(); }
  void FillLogRow(std::span<double> values) const noexcept override { task_.FillLogRow(values); }
  [[nodiscard]] TelemetryShape TelemetryShapeOf() const override {
    return task_.TelemetryShapeOf();
  }
  void FillTelemetry(TaskTelemetry& out) const noexcept override { task_.FillTelemetry(out); }

 protected:
  [[nodiscard]] RunTask& wrapped() const noexcept { return task_; }

 private:
  RunTask& task_;
};

}  // namespace hiltwin::runtime
