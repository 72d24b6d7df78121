#include "hiltwin/runs/trajectory_recorder.h"

#include "hiltwin/relbot/relbot_plant.h"

namespace hiltwin::app {

TrajectoryRecorder::TrajectoryRecorder(plant::PlantTwinTask& twin, kernel_glue::TimeNs period_ns,
                                       std::size_t capacity_cycles)
    : twin_(twin), capacity_(capacity_cycles) {
  record_.period_s = static_cast<double>(period_ns) * 1e-9;
  record_.exchange_time_s.reserve(capacity_);
  record_.wheel_left_m.reserve(capacity_);
  record_.wheel_right_m.reserve(capacity_);
}

runtime::StepStatus TrajectoryRecorder::Step(const scheduler::CycleContext& context) noexcept {
  const runtime::StepStatus status = twin_.Step(context);
  if (record_.exchange_time_s.size() == capacity_) {
    ++not_recorded_;
    return status;
  }
  // The exchange opens the step (runtime::CycleRunner), so it happened at start_ns. Times are
  // kept since release 0, the origin of the controller's sample instants.
  const kernel_glue::TimeNs release0_ns =
      context.release_ns - static_cast<kernel_glue::TimeNs>(context.cycle) * context.period_ns;
  record_.exchange_time_s.push_back(static_cast<double>(context.start_ns - release0_ns) * 1e-9);
  record_.wheel_left_m.push_back(twin_.outputs()[relbot_port::kWheelLeftM]);
  record_.wheel_right_m.push_back(twin_.outputs()[relbot_port::kWheelRightM]);
  return status;
}

}  // namespace hiltwin::app
