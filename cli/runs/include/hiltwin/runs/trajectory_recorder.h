#pragma once
/// The RELbot twin as its controller sees it: a RunTask that forwards every call to the twin
/// task (a PlantTwinTask running the RELbot plant) and
/// records, for each stepped cycle, when its board exchange happened and the wheel positions
/// its step computed. `hiltwin tune` turns the record into the RMS error the controller sees
/// (analysis::ControllerViewRmsError). The storage is reserved up front: on the loop thread
/// the recorder only writes into it, and stops recording (never allocates) once it is full.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "hiltwin/plant/plant_twin_task.h"
#include "hiltwin/runtime/run_task.h"
#include "hiltwin/tuning/tuning.h"

namespace hiltwin::app {

class TrajectoryRecorder final : public runtime::RunTask {
 public:
  /// `twin` runs the RELbot plant; it is not owned and must outlive the recorder; room for
  /// `capacity_cycles` cycles.
  TrajectoryRecorder(plant::PlantTwinTask& twin, kernel_glue::TimeNs period_ns, std::size_t capacity_cycles);

  io::ExchangeStatus Exchange(bool live_outputs) noexcept override {
    return twin_.Exchange(live_outputs);
  }
  runtime::StepStatus Step(const scheduler::CycleContext& context) noexcept override;
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return twin_.LogColumns(); }
  [[nodiscard]] double LogTimeS() const noexcept override { return twin_.LogTimeS(); }
  void FillLogRow(std::span<double> values) const noexcept override { twin_.FillLogRow(values); }

  /// The record so far (read after the run).
  [[nodiscard]] const analysis::TwinTrajectory& trajectory() const noexcept { return record_; }
  /// Cycles that did not fit (0 unless the run outlasted the capacity).
  [[nodiscard]] std::size_t cycles_not_recorded() const noexcept { return not_recorded_; }

 private:
  plant::PlantTwinTask& twin_;
  analysis::TwinTrajectory record_;
  std::size_t capacity_;
  std::size_t not_recorded_ = 0;
};

}  // namespace hiltwin::app
