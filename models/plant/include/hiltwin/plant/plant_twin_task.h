#pragma once
/// Any plant as a twin run task (docs/architecture.md, "One cycle, as data flows"): one full-duplex
/// exchange with the board (PWM duty in, the encoder counts computed last cycle out), the
/// plant map's input processing, the plant's step, and the map's output processing into the
/// counts for the next exchange. Timing, QoS, tracing, logging and the lifecycle are the run
/// assembly's (runtime::RunSession). Everything on the loop's path is noexcept and
/// allocation-free: the port vectors are sized once, in the constructor.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/io/icoboard.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"
#include "hiltwin/runtime/run_task.h"

namespace hiltwin::plant {

class PlantTwinTask final : public runtime::RunTask {
 public:
  /// None of the references is owned; all must outlive the task. `plant` must be started
  /// (Plant::Start) at `step_s`, and `initial_outputs` are what Start wrote: the encoders
  /// count from there, as an incremental encoder counts from wherever it was switched on.
  PlantTwinTask(io::IcoBoardInverse& board, Plant& plant, BoundPlantMap map, double step_s,
                std::span<const double> initial_outputs);

  /// Live: sends the counts of the last step. Safe: repeats the counts last sent, so the
  /// encoder emulator emits no further pulses (a plant at rest, not a jump to zero).
  io::ExchangeStatus Exchange(bool live_outputs) noexcept override;
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  /// The plant's input names, its output names, then one column per encoder route.
  [[nodiscard]] std::vector<std::string> LogColumns() const override;
  [[nodiscard]] double LogTimeS() const noexcept override { return model_time_s_; }
  void FillLogRow(std::span<double> values) const noexcept override;
  /// Role "twin"; a pose when the map names one, a joint per encoder route with `joint`.
  [[nodiscard]] runtime::TelemetryShape TelemetryShapeOf() const override;
  void FillTelemetry(runtime::TaskTelemetry& out) const noexcept override;

  /// The plant inputs and outputs of the last step (for recorders and tests).
  [[nodiscard]] std::span<const double> inputs() const noexcept { return u_; }
  [[nodiscard]] std::span<const double> outputs() const noexcept { return y_; }
  [[nodiscard]] std::uint64_t steps() const noexcept { return steps_; }
  /// The counts the last step computed, to go out with the next live exchange.
  [[nodiscard]] const std::array<std::int32_t, io::kChannels>& encoder_next() const noexcept {
    return encoder_out_;
  }
  /// The counts of the last exchange (live or safe).
  [[nodiscard]] const std::array<std::int32_t, io::kChannels>& encoder_sent() const noexcept {
    return encoder_sent_;
  }
  [[nodiscard]] const Plant& plant() const noexcept { return plant_; }
  [[nodiscard]] const BoundPlantMap& map() const noexcept { return map_; }

 private:
  /// The counts of the last step's outputs into encoder_out_; a model fault when they cannot
  /// be represented (beyond kMaxAbsCounts, or half an encoder turn since the last step).
  runtime::StepStatus CountsFromOutputs() noexcept;

  io::IcoBoardInverse& board_;
  Plant& plant_;
  BoundPlantMap map_;
  double step_s_;
  io::TwinInputs inputs_{};
  std::vector<double> u_;
  std::vector<double> y_;
  std::array<std::int64_t, io::kChannels> counts_origin_{};  ///< counts of the initial outputs
  std::array<std::int64_t, io::kChannels> counts_{};  ///< of the last step, from the origin
  std::array<std::int32_t, io::kChannels> encoder_out_{};   ///< computed by the last step
  std::array<std::int32_t, io::kChannels> encoder_sent_{};  ///< on the wire last
  std::uint64_t steps_ = 0;
  double model_time_s_ = 0.0;
};

}  // namespace hiltwin::plant
