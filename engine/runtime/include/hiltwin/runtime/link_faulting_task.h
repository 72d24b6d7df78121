#pragma once
/// A run task whose board is damaged on schedule: --inject-link-fault's SPECs
/// (io/link_fault_injection.h) armed on the emulated board before each exchange.

#include <cstdint>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/link_fault_injection.h"
#include "hiltwin/runtime/forwarding_task.h"

namespace hiltwin::runtime {

/// Wraps a task so that its board's faults are armed before each exchange. Everything else
/// is the wrapped task's. The board must outlive the wrapper.
class LinkFaultingTask final : public ForwardingTask {
 public:
  LinkFaultingTask(RunTask& task, io::EmulatedFpga& board, io::LinkFaultSchedule schedule) noexcept
      : ForwardingTask(task), board_(board), schedule_(schedule) {}

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  /// Exchanges made so far.
  [[nodiscard]] std::uint64_t exchanges() const noexcept { return exchanges_; }

 private:
  io::EmulatedFpga& board_;
  io::LinkFaultSchedule schedule_;
  std::uint64_t exchanges_ = 0;
};

}  // namespace hiltwin::runtime
