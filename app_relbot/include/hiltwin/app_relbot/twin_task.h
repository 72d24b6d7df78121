#pragma once
/// The RELbot twin as a run task (DESIGN.md "One cycle, as data flows"): one full-duplex
/// exchange with the board (PWM duty in, the encoder positions computed last cycle out), the
/// model step, and the positions for the next exchange. Timing, QoS, tracing, logging and the
/// lifecycle are the run assembly's (runtime::RunSession). Everything on the loop's path is
/// noexcept and allocation-free.

#include <array>
#include <cstdint>

#include "hiltwin/app_relbot/input_profile.h"
#include "hiltwin/app_relbot/relbot_channels.h"
#include "hiltwin/app_relbot/relbot_model.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::app {

/// What the last step read, computed and will send: the log row's source.
struct TwinCycleRecord {
  std::uint64_t cycle = 0;
  double model_time_s = 0.0;  ///< model time after the step
  Duty duty;                  ///< duty read from the board (held on a bad frame)
  RelbotOutputs outputs;      ///< model outputs after the step
  std::array<std::int32_t, io::kChannels> encoder_counts{};  ///< absolute counts sent next
};

/// Plays an input profile into the emulated board's PWM reader the way a controller would:
/// sampled and held at the controller's rate (thesis fig. 5.1 was played by a 1 kHz ECS).
/// The mock board's time is its frame count times the twin's whole-nanosecond period, so the
/// source counts in frames: frame k holds the controller's sample floor(k * controller rate /
/// twin rate), taken at that sample's exact time. A frame that coincides with a controller
/// sample therefore reads it whatever the period's rounding (7 kHz is 142857 ns, and 7 of them
/// end 1 ns before the millisecond: counted in nanoseconds, every such frame would read the
/// previous sample, a whole period of extra delay at some rates and none at others).
class ProfilePwmSource final : public io::PwmSignalSource {
 public:
  ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                   double twin_rate_hz) noexcept;
  void DutyAt(std::int64_t t_ns, std::array<double, io::kChannels>& duty_out) noexcept override;

 private:
  const InputProfile& profile_;
  double controller_rate_hz_;
  double twin_rate_hz_;
  double twin_period_ns_;  ///< whole nanoseconds, as the board counts them
};

/// The twin's cyclic work.
class TwinTask final : public runtime::RunTask {
 public:
  /// Neither reference is owned; both must outlive the task.
  TwinTask(io::IcoBoardInverse& board, RelbotModel& model,
           const io::WheelGeometry& geometry) noexcept;

  /// Live: sends the positions of the last step. Safe: repeats the positions last sent, so
  /// the encoder emulator emits no further pulses (a robot at rest, not a jump to zero).
  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  [[nodiscard]] std::vector<std::string> LogColumns() const override;
  [[nodiscard]] double LogTimeS() const noexcept override { return last_.model_time_s; }
  void FillLogRow(std::span<double> values) const noexcept override;
  /// The pose (x, y, heading) and both wheels as the model moved them in the last step.
  [[nodiscard]] runtime::TelemetryShape TelemetryShapeOf() const override;
  void FillTelemetry(runtime::TaskTelemetry& out) const noexcept override;

  [[nodiscard]] const TwinCycleRecord& last() const noexcept { return last_; }
  /// The absolute counts of the last exchange (live or safe).
  [[nodiscard]] const std::array<std::int32_t, io::kChannels>& encoder_sent() const noexcept {
    return encoder_sent_;
  }

 private:
  io::IcoBoardInverse& board_;
  RelbotModel& model_;
  io::WheelGeometry geometry_;
  io::TwinInputs inputs_{};
  std::array<std::int32_t, io::kChannels> encoder_out_{};   ///< computed by the last step
  std::array<std::int32_t, io::kChannels> encoder_sent_{};  ///< on the wire last
  TwinCycleRecord last_{};
};

}  // namespace hiltwin::app
