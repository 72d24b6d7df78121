#pragma once
/// The RELbot twin's cycle (DESIGN.md "One cycle, as data flows"): one full-duplex exchange
/// with the board (PWM duty in, the encoder positions computed last cycle out), the model
/// step, and the positions for the next exchange. Plus the observers that turn each cycle's
/// timing into a QoS record, a trace event and a log row. Everything on the loop's path is
/// noexcept and allocation-free.

#include <array>
#include <cstdint>

#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/overrun_injection.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/scheduler/cycle.h"
#include "hiltwin/statemachine/lifecycle.h"
#include "hiltwin/tracing/csv_logger.h"

namespace hiltwin::app {

/// Board channels the RELbot uses (thesis appendix G: motor/encoder 1 left, 2 right).
constexpr std::size_t kLeftChannel = 0;
constexpr std::size_t kRightChannel = 1;

/// What one cycle read, computed and sent: the log row's source.
struct TwinCycleRecord {
  std::uint64_t cycle = 0;
  double model_time_s = 0.0;  ///< model time after the step
  Duty duty;                  ///< duty read from the board (held on a bad frame)
  RelbotOutputs outputs;      ///< model outputs after the step
  std::array<std::int32_t, io::kChannels> encoder_counts{};  ///< absolute counts sent next
  io::ExchangeStatus::Code io_status = io::ExchangeStatus::Code::kOk;
};

/// Plays an input profile into the emulated board's PWM reader the way a controller would:
/// sampled and held at the controller's rate (thesis fig. 5.1 was played by a 1 kHz ECS).
class ProfilePwmSource final : public io::PwmSignalSource {
 public:
  ProfilePwmSource(const InputProfile& profile, double controller_rate_hz) noexcept;
  void DutyAt(std::int64_t t_ns, std::array<double, io::kChannels>& duty_out) noexcept override;

 private:
  const InputProfile& profile_;
  std::int64_t controller_period_ns_;
};

/// The twin's cyclic step.
class TwinTask final : public scheduler::CyclicTask {
 public:
  /// None of the references is owned; all must outlive the task.
  TwinTask(io::IcoBoardInverse& board, RelbotModel& model, const io::WheelGeometry& geometry,
           kernel_glue::Clock& clock, const OverrunInjector& injector,
           statemachine::Lifecycle& lifecycle) noexcept;

  scheduler::CycleAction Step(const scheduler::CycleContext& context) noexcept override;

  /// Safe outputs after the loop: one more exchange that repeats the positions last sent, so
  /// the encoder emulator emits no further pulses (a robot at rest). Returns the status.
  io::ExchangeStatus HoldOutputs() noexcept;

  [[nodiscard]] const TwinCycleRecord& last() const noexcept { return last_; }
  /// Frames that were corrupted or missed (inputs held) over the run.
  [[nodiscard]] std::uint64_t io_errors() const noexcept { return io_errors_; }
  /// Cycles in which no controller was attached to the wire (the twin saw idle PWM).
  [[nodiscard]] std::uint64_t controller_absent_cycles() const noexcept {
    return controller_absent_cycles_;
  }
  /// Why the link failed, when the task stopped on an I/O fault (static text).
  [[nodiscard]] const char* fault_reason() const noexcept { return fault_reason_; }
  /// Cycle at which a fault stopped the task.
  [[nodiscard]] std::uint64_t fault_cycle() const noexcept { return fault_cycle_; }

 private:
  io::IcoBoardInverse& board_;
  RelbotModel& model_;
  io::WheelGeometry geometry_;
  kernel_glue::Clock& clock_;
  const OverrunInjector& injector_;
  statemachine::Lifecycle& lifecycle_;
  io::TwinInputs inputs_{};
  std::array<std::int32_t, io::kChannels> encoder_out_{};
  TwinCycleRecord last_{};
  std::uint64_t io_errors_ = 0;
  std::uint64_t controller_absent_cycles_ = 0;
  const char* fault_reason_ = "";
  std::uint64_t fault_cycle_ = 0;
};

/// Feeds every release to the QoS monitor (skipped releases as misses) and asks the executive
/// to stop when the monitor says so (policy abort). Emits the `cycle` and `qos` tracepoints.
class QosObserver final : public scheduler::CycleObserver {
 public:
  explicit QosObserver(qos::QosMonitor& monitor) noexcept : monitor_(monitor) {}
  scheduler::CycleAction OnCycle(const scheduler::TimingSample& sample) noexcept override;

 private:
  qos::QosMonitor& monitor_;
};

/// Offers one CSV row per cycle to the logger (which decimates and counts drops).
class LogObserver final : public scheduler::CycleObserver {
 public:
  /// The columns this observer writes, after the logger's own time_s.
  static const std::vector<std::string>& Columns();
  LogObserver(tracing::CsvLogger& logger, const TwinTask& task) noexcept
      : logger_(logger), task_(task) {}
  scheduler::CycleAction OnCycle(const scheduler::TimingSample& sample) noexcept override;

 private:
  tracing::CsvLogger& logger_;
  const TwinTask& task_;
};

}  // namespace hiltwin::app
