#pragma once
/// The RELbot's embedded control system (ECS) as a run task: the same code drives the twin (mock or
/// wire backend) or the real robot (spidev), through the ECS image of the IcoBoard. Per cycle
/// (docs/architecture.md, "One cycle, as data flows"): one full-duplex exchange (the duty the last
/// step computed goes out, the encoder counts come in), then one step that computes the duty for
/// the next exchange. Two modes:
///
/// - closed loop (default): wheel position setpoints from a SetpointProfile into any controller
///   (controller/controller.h) through a controller map, run by a controller::ControllerTask;
///   the built-in one is one PositionPid per wheel (PidController, thesis §7.2, appendix E) on
///   the RELbot's map, whose setpoints are rounded to a whole encoder count: the encoder reads
///   only whole counts, so a setpoint between two of them could never be met and the integral
///   would make the wheel hunt across the count edge at rest. Logs and statistics use the
///   profile's own setpoint and the RELbot's wheels (channels per relbot_channels.h);
/// - open loop (`--mode openloop`): plays a duty InputProfile and logs the duty on the wire
///   and the measured wheel positions every cycle (thesis §5.2, fig. 5.2), so the log can be
///   replayed into a reference run (LoadInputProfile reads its duty_left,duty_right columns).
///
/// Time is the task's own: (cycle − paused cycles) × period_ns, exact multiples, never
/// accumulated, so a pause stops the profile rather than skipping part of it. The cycle
/// of the exchange is the sampling moment: the counts read in cycle k are the wheels at
/// t_k = k·period, and the duty computed in step k is on the wire from t_{k+1}. Everything on
/// the loop's path is noexcept and allocation-free.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/controller/controller.h"
#include "hiltwin/controller/controller_map.h"
#include "hiltwin/controller/controller_task.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/pid_controller.h"
#include "hiltwin/relbot/position_pid.h"
#include "hiltwin/relbot/relbot_channels.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::app {

enum class EcsMode : std::uint8_t { kClosedLoop, kOpenLoop };

/// Closed-loop tracking error (setpoint - measured, both in metres of wheel travel) over every
/// step since the start. Constant memory; kept on the loop thread, read after the run.
struct TrackingStats {
  std::uint64_t samples = 0;  ///< steps counted
  double max_abs_error_left_m = 0.0;
  double max_abs_error_right_m = 0.0;
  double rms_error_left_m = 0.0;
  double rms_error_right_m = 0.0;
  double rms_error_m = 0.0;         ///< over both wheels together
  double final_error_left_m = 0.0;  ///< at the last step
  double final_error_right_m = 0.0;
  /// Steps in which either wheel's output hit its limit: the built-in PID's own (--gains),
  /// another controller's duty at its route's duty_limit.
  std::uint64_t saturated_cycles = 0;
  double max_abs_duty = 0.0;           ///< largest |duty| commanded, either wheel
};

/// What the last step read, computed and sent: the log row's source.
struct EcsCycleRecord {
  std::uint64_t cycle = 0;
  double time_s = 0.0;      ///< cycle · period: when the counts were read
  Duty duty_sent;           ///< on the wire from time_s (this cycle's exchange), as quantised
  Duty duty_next;           ///< this step's output, on the wire from the next exchange
  WheelPositions measured;  ///< wheel travel since the first step, from the encoder counts
  WheelPositions setpoint;  ///< closed loop; zero in open loop
  std::array<std::int64_t, 2> counts{};  ///< encoder counts since the first step: left, right
};

/// The ECS's cyclic work.
class EcsTask final : public runtime::RunTask {
 public:
  /// Closed loop with the built-in PID (PidController) on the RELbot's controller map.
  /// `geometry` converts counts to metres (WheelGeometryOf(params) of the robot or twin being
  /// driven); `period_ns` is the ECS cycle and must equal the session's period. Throws
  /// ConfigError for invalid gains and std::invalid_argument for period_ns <= 0. `board` and
  /// `setpoints` are not owned and must outlive the task.
  EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints, const PidGains& gains,
          const io::WheelGeometry& geometry, std::int64_t period_ns);
  /// Closed loop with any controller, bound to `map`; starts it at period_ns (ControllerError
  /// when it cannot run at it). `controller` is not owned and must outlive the task; the log
  /// and statistics are the RELbot wheels' (`geometry`) and the left_m / right_m `tracks`
  /// pairs'.
  EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints, controller::Controller& controller,
          controller::BoundControllerMap map, const io::WheelGeometry& geometry,
          std::int64_t period_ns);
  /// Open loop: plays `duty_profile` (repeating with its period), sampled at the ECS's cycle.
  EcsTask(io::IcoBoard& board, const InputProfile& duty_profile, const io::WheelGeometry& geometry,
          std::int64_t period_ns);

  /// Live: sends the duty of the last step. Safe: sends zero duty (motors off).
  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  /// Never finishes on its own: after the setpoint profile's end the last setpoint holds (the
  /// robot is kept in place) and a duty profile repeats, so the command's duration decides.
  /// A session period other than the task's is a fault (the gains were discretised for it).
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  /// Closed loop: setpoint_left_m, setpoint_right_m, wheel_left_m, wheel_right_m,
  /// error_left_m, error_right_m, duty_left, duty_right, enc_left, enc_right.
  /// Open loop: duty_left, duty_right, wheel_left_m, wheel_right_m, enc_left, enc_right.
  /// duty_* is the duty on the wire from time_s on, so a log replays as a duty profile.
  [[nodiscard]] std::vector<std::string> LogColumns() const override;
  [[nodiscard]] double LogTimeS() const noexcept override { return last_.time_s; }
  void FillLogRow(std::span<double> values) const noexcept override;
  /// Both wheels as the encoders measured them at the last exchange (no pose: the controller
  /// does not know it) and, in closed loop, their setpoints (the log's setpoint_*_m).
  [[nodiscard]] runtime::TelemetryShape TelemetryShapeOf() const override;
  void FillTelemetry(runtime::TaskTelemetry& out) const noexcept override;

  [[nodiscard]] EcsMode mode() const noexcept { return mode_; }
  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_; }
  /// The profile's length in seconds: the setpoint profile's last time, or one period of the
  /// duty profile. The command's default duration.
  [[nodiscard]] double length_s() const noexcept;
  [[nodiscard]] const EcsCycleRecord& last() const noexcept { return last_; }
  /// Closed-loop statistics so far (all zero in open loop). Not synchronised: read it when
  /// the loop is not running (after RunSession::Run returns).
  [[nodiscard]] TrackingStats tracking() const noexcept;
  /// What the board reported at the last exchange.
  [[nodiscard]] const io::EcsInputs& inputs() const noexcept;
  /// The controller's task (closed loop; nullptr in open loop): its controller, per-pair
  /// tracking and fault, for the report.
  [[nodiscard]] const controller::ControllerTask* controller_task() const noexcept {
    return loop_ ? &*loop_ : nullptr;
  }

 private:
  /// The setpoint profile as the controller task's columns (left_m, right_m).
  class ProfileColumns final : public controller::SetpointColumns {
   public:
    explicit ProfileColumns(const SetpointProfile& profile) : profile_(profile) {}
    [[nodiscard]] std::array<double, 2> At(double time_s) const noexcept override;

   private:
    const SetpointProfile& profile_;
  };

  EcsTask(io::IcoBoard& board, const SetpointProfile& setpoints,
          std::unique_ptr<controller::Controller> owned, const io::WheelGeometry& geometry,
          std::int64_t period_ns);
  void ReadWheels() noexcept;
  /// The log's record of a closed-loop step, from the controller task's.
  void RecordClosedLoop() noexcept;
  void SetNextDuty(const Duty& duty) noexcept;

  io::IcoBoard& board_;
  EcsMode mode_;
  const SetpointProfile* setpoints_;  ///< closed loop
  const InputProfile* duty_profile_;  ///< open loop
  io::WheelGeometry geometry_;
  std::int64_t period_ns_;
  std::unique_ptr<controller::Controller> owned_controller_;  ///< the built-in PID's
  /// The controller when it is the built-in PID: its own saturation flag counts saturated
  /// cycles, as before controllers were pluggable (its --gains limit may be below the map's).
  const PidController* pid_ = nullptr;
  std::uint64_t pid_saturated_cycles_ = 0;
  std::optional<ProfileColumns> columns_;                     ///< closed loop
  std::optional<controller::ControllerTask> loop_;            ///< closed loop
  io::EcsInputs inputs_{};  ///< open loop
  std::array<std::int32_t, io::kChannels> pwm_next_{};  ///< computed by the last step
  std::array<std::int32_t, io::kChannels> pwm_sent_{};  ///< on the wire since the last exchange
  std::array<std::int64_t, 2> origin_counts_{};  ///< open loop: left, right at the first step
  bool have_inputs_ = false;       ///< an exchange has succeeded: the counts are a reading
  bool started_ = false;           ///< the origin is taken
  std::uint64_t held_cycles_ = 0;  ///< exchanges with safe outputs (paused): not profile time
  EcsCycleRecord last_{};
};

}  // namespace hiltwin::app
