#pragma once
/// Fault injection on the FPGA link: corrupted, dropped and delayed SPI frames and a stuck
/// encoder, armed on the emulated board (mock and wire backends) at chosen exchanges, so a
/// user can watch what the run does with a broken link (docs/reliability.md's fault matrix).
/// The board's own hooks (io::FaultInjection) do the damage; this only decides when.
///
/// SPEC forms (comma-separated, repeatable flag):
///   KIND,at=K[,count=N]   KIND: corrupt-request | corrupt-answer | drop-answer |
///                         delay-answer | stuck-encoder
/// Exchange K is the K-th frame exchange of the run (0-based; the exchange of cycle K when no
/// release was skipped). Frame faults hit exchanges K .. K+N-1 (count defaults to 1); a stuck
/// encoder emits (twin) or sees (ECS) nothing from exchange K on, for N exchanges when count
/// is given, else to the end of the run.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::runtime {

struct LinkFaultInjection {
  enum class Kind : std::uint8_t {
    kCorruptRequest,
    kCorruptAnswer,
    kDropAnswer,
    kDelayAnswer,
    kStuckEncoder,
  };
  Kind kind = Kind::kCorruptAnswer;
  std::uint64_t first_exchange = 0;  ///< at=
  std::uint64_t count = 1;           ///< count=; stuck-encoder without count: to the end
  bool until_end = false;            ///< stuck-encoder given no count
};

/// Parses one SPEC; throws std::invalid_argument quoting it, saying what is wrong and the
/// accepted forms (the caller names the flag).
[[nodiscard]] LinkFaultInjection ParseLinkFaultInjection(std::string_view spec);
/// The SPEC form, e.g. "drop-answer,at=4000,count=3".
[[nodiscard]] std::string Describe(const LinkFaultInjection& injection);

/// A fixed set of link faults, applied to a board exchange by exchange without allocating.
class LinkFaultSchedule {
 public:
  static constexpr std::size_t kMaxInjections = 8;
  /// Throws std::length_error past kMaxInjections.
  void Add(const LinkFaultInjection& injection);
  /// Throws std::invalid_argument naming the first injection whose exchange K is not below
  /// `planned_exchanges` (0: the run has no end, every exchange may come).
  void CheckFiresWithin(std::uint64_t planned_exchanges) const;
  /// Arms `faults` for exchange `exchange`: frame faults at their first exchange (the board
  /// consumes one per frame), the stuck encoder on and off at its edges. Real-time path.
  void Arm(std::uint64_t exchange, io::FaultInjection& faults) const noexcept;
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] std::span<const LinkFaultInjection> injections() const noexcept {
    return {injections_.data(), size_};
  }

 private:
  std::array<LinkFaultInjection, kMaxInjections> injections_{};
  std::size_t size_ = 0;
};

/// Wraps a task so that its board's faults are armed before each exchange. Everything else
/// is the wrapped task's. The board must outlive the wrapper.
class LinkFaultingTask final : public RunTask {
 public:
  LinkFaultingTask(RunTask& task, io::EmulatedFpga& board, LinkFaultSchedule schedule) noexcept
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
  LinkFaultSchedule schedule_;
  std::uint64_t exchanges_ = 0;
};

}  // namespace hiltwin::runtime
