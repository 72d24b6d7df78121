#pragma once
// The whole HiL loop in one process, on one virtual timeline: the RELbot twin (the RELbot plant behind a PlantTwinTask on an
// emulated icoboard_inverse board, IcoBoardInverse driver, RelbotModel RK4) and the ECS
// (EcsTask on an emulated icoboard board, IcoBoard driver), joined by the encoder lines
// (EmulatorToReaderLink: the ECS board's quadrature readers decode the twin's A/B edges) and the
// PWM lines (GeneratorToReaderLink: the twin's PWM reader measures the ECS's generator).
//
// InProcessHil is itself a RunTask whose cycle is one ECS cycle: Exchange is the ECS's exchange
// k (at t_k), Step is the ECS's step k followed by the twin's cycles j = r·k .. r·k + r - 1
// (r = twin rate / ECS rate), each an exchange at t_j then a model step. So the ECS at t_k reads
// the edges the twin emitted up to t_k, and the twin integrates over [t_k, t_k+1) with the duty
// the ECS put on the wire at t_k, as on two boards running in real time. It can be stepped by
// hand (RunInProcess) or run by a real runtime::RunSession on the virtual clock.
//
// The boards have no clock: each counts its time as data frames × step. After every cycle the
// rig checks that both boards' times are the ECS's and the twin's cycle × period.
//
// The boards are pluggable (HilBoards): by default the emulated pair (io::EmulatedFpga joined by
// the line links above); tests/unit/fpga_sim plugs in the verilated RTL pair wired pin to pin.

#include <cstdint>
#include <memory>
#include <optional>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/relbot/profile_pwm_source.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/relbot_twin.h"

namespace hiltwin::app::test {

/// The rig's two boards, each behind its own bus, already joined by their wires.
class HilBoards {
 public:
  virtual ~HilBoards() = default;
  [[nodiscard]] virtual io::SpiBus& twin_bus() noexcept = 0;
  [[nodiscard]] virtual io::SpiBus& ecs_bus() noexcept = 0;
  /// Board time (ns since INIT) of each board's latest ALL; ALLs the ECS board has served.
  [[nodiscard]] virtual std::int64_t twin_time_ns() const noexcept = 0;
  [[nodiscard]] virtual std::int64_t ecs_time_ns() const noexcept = 0;
  [[nodiscard]] virtual std::uint64_t ecs_data_frames() const noexcept = 0;
  /// A/B edges a real quadrature reader would miscount (illegal, too fast) and resyncs.
  [[nodiscard]] virtual std::uint64_t line_errors() const noexcept = 0;
};

/// The emulated pair: io::EmulatedFpga boards joined by EmulatorToReaderLink and
/// GeneratorToReaderLink.
[[nodiscard]] std::unique_ptr<HilBoards> MakeEmulatedBoards();

struct HilConfig {
  double ecs_rate_hz = 1000.0;
  double twin_rate_hz = 4000.0;
  PidGains gains;                              ///< closed loop, without `controller`
  /// Closed loop: another controller than the built-in PID, on the RELbot's controller map
  /// (not owned; outlives the rig). Null: the PID with `gains`.
  controller::Controller* controller = nullptr;
  const SetpointProfile* setpoints = nullptr;  ///< closed loop (null: open loop)
  const InputProfile* duty_profile = nullptr;  ///< open loop
  double duration_s = 0.0;                     ///< 0: the profile's length
  double rest_window_s = 1.0;  ///< the end of the run over which rest behaviour is measured
};

/// What the rig observed besides the ECS's own TrackingStats.
struct HilObservations {
  std::uint64_t ecs_cycles = 0;
  std::uint64_t twin_cycles = 0;
  std::uint64_t board_time_mismatches = 0;  ///< a board's frames × step != cycle × period
  std::uint64_t link_errors = 0;            ///< exchanges that did not return kOk, both sides
  std::uint64_t line_errors = 0;            ///< quadrature readers: illegal, too fast, resyncs
  /// Setpoint minus the twin's true wheel position at each ECS sampling moment (not quantised,
  /// not delayed: what the robot really did).
  double max_abs_true_error_left_m = 0.0;
  double max_abs_true_error_right_m = 0.0;
  /// Over the rest window at the end of the run.
  double rest_min_duty = 0.0;
  double rest_max_duty = 0.0;
  std::int64_t rest_min_counts = 0;  ///< either wheel, since the start
  std::int64_t rest_max_counts = 0;
  std::uint64_t rest_duty_sign_changes = 0;  ///< per wheel, summed: hunting shows up here
  double final_true_error_left_m = 0.0;
  double final_true_error_right_m = 0.0;
  /// The last ECS sampling time at which either wheel's error exceeded one encoder count
  /// (closed loop): from then on the loop has settled to within one count.
  double last_error_above_one_count_s = 0.0;
};

class InProcessHil final : public runtime::RunTask {
 public:
  explicit InProcessHil(const HilConfig& config,
                        std::unique_ptr<HilBoards> boards = MakeEmulatedBoards());

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return ecs_.LogColumns(); }
  [[nodiscard]] double LogTimeS() const noexcept override { return ecs_.LogTimeS(); }
  void FillLogRow(std::span<double> values) const noexcept override { ecs_.FillLogRow(values); }

  [[nodiscard]] std::int64_t ecs_period_ns() const noexcept { return ecs_period_ns_; }
  /// ECS cycles of the configured duration.
  [[nodiscard]] std::uint64_t planned_cycles() const noexcept { return planned_cycles_; }
  [[nodiscard]] const EcsTask& ecs() const noexcept { return ecs_; }
  [[nodiscard]] const io::IcoBoard& ecs_driver() const noexcept { return ecs_driver_; }
  [[nodiscard]] const RelbotTwin& twin() const noexcept { return twin_; }
  [[nodiscard]] const RelbotModel& model() const noexcept { return twin_.model(); }
  [[nodiscard]] HilObservations observations() const noexcept;

 private:
  void Observe(std::uint64_t ecs_cycle) noexcept;

  HilConfig config_;
  std::int64_t ecs_period_ns_;
  std::int64_t twin_period_ns_;
  std::uint64_t twin_per_ecs_;
  std::uint64_t planned_cycles_;
  double rest_from_s_;
  RelbotParams params_;
  io::WheelGeometry geometry_;
  double count_m_;  ///< one encoder count in metres
  std::unique_ptr<HilBoards> boards_;
  io::IcoBoardInverse twin_driver_;
  io::IcoBoard ecs_driver_;
  RelbotTwin twin_;
  EcsTask ecs_;
  std::uint64_t twin_cycle_ = 0;
  HilObservations seen_{};
  bool rest_seen_ = false;
  double last_rest_duty_left_ = 0.0;
  double last_rest_duty_right_ = 0.0;
};

/// Runs the loop by hand for the configured duration: the ECS's cycle k is released at k·period.
/// Fails the current test (ADD_FAILURE) when a step reports a fault.
void RunInProcess(InProcessHil& rig);

}  // namespace hiltwin::app::test
