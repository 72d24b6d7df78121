#pragma once
/// The RELbot plant and its twin task owned together: the RELbot started at a step, behind a
/// board driver, wired by its default plant map. What `hiltwin run` builds for `--plant
/// relbot` (twin_build.h), in one object for the in-process rigs of tests and benchmarks, with
/// the plant's ports read back as RELbot quantities.

#include <array>
#include <cstdint>

#include "hiltwin/plant/plant_twin_task.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_plant.h"

namespace hiltwin::app {

/// RELbot outputs from the plant's output ports.
[[nodiscard]] RelbotOutputs RelbotOutputsOf(std::span<const double> y) noexcept;

class RelbotTwin {
 public:
  /// `board` is not owned and must outlive the twin. Throws plant::PlantError for a step the
  /// integrator cannot keep stable.
  RelbotTwin(io::IcoBoardInverse& board, const RelbotParams& params, Integrator integrator,
             double step_s);
  RelbotTwin(const RelbotTwin&) = delete;
  RelbotTwin& operator=(const RelbotTwin&) = delete;

  [[nodiscard]] plant::PlantTwinTask& task() noexcept { return task_; }
  [[nodiscard]] const plant::PlantTwinTask& task() const noexcept { return task_; }
  [[nodiscard]] const RelbotModel& model() const { return plant_.model(); }
  /// Outputs after the last step.
  [[nodiscard]] RelbotOutputs outputs() const noexcept { return RelbotOutputsOf(task_.outputs()); }
  /// Duty the last step used, as read from the board.
  [[nodiscard]] Duty duty() const noexcept;

 private:
  RelbotPlant plant_;
  plant::PlantTwinTask task_;
};

}  // namespace hiltwin::app
