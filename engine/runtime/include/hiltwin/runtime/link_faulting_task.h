#pragma once
/// A run task whose board is damaged on schedule: --inject-link-fault's SPECs
/// (io/link_fault_injection.h) armed on the emulated board before each exchange.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::runtime {

/// Wraps a task so that its board's faults are armed before each exchange. Everything else
/// is the wrapped task's. The board must outlive the wrapper.
class LinkFaultingTask final : public RunTask {
 public:
  LinkFaultingTask(RunTask& task, io::EmulatedFpga& board, io::LinkFaultSchedule schedule) noexcept
      : task_(task), board_(board), schedule_(schedule) {}

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
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
  /// Exchanges made so far.
  [[nodiscard]] std::uint64_t exchanges() const noexcept { return exchanges_; }

 private:
  RunTask& task_;
  io::EmulatedFpga& board_;
  io::LinkFaultSchedule schedule_;
  std::uint64_t exchanges_ = 0;
};

}  // namespace hiltwin::runtime
