// The RELbot plant and its twin task owned together (relbot_twin.h).
#include "hiltwin/relbot/relbot_twin.h"

#include <vector>

namespace hiltwin::app {
namespace {

/// Starts `plant` and returns its initial outputs: the member initialiser of the task needs
/// them before the constructor's body could run.
std::vector<double> Started(RelbotPlant& plant, double step_s) {
  std::vector<double> y0(plant.Info().outputs.size(), 0.0);
  plant.Start(step_s, y0);
  return y0;
}

}  // namespace

RelbotOutputs RelbotOutputsOf(std::span<const double> y) noexcept {
  return {y[relbot_port::kWheelLeftM], y[relbot_port::kWheelRightM], y[relbot_port::kXM],
          y[relbot_port::kYM], y[relbot_port::kThetaRad]};
}

RelbotTwin::RelbotTwin(io::IcoBoardInverse& board, const RelbotParams& params,
                       Integrator integrator, double step_s)
    : plant_(params, integrator),
      task_(board, plant_, plant::BindPlantMap(RelbotDefaultMap(params), plant_), step_s,
            Started(plant_, step_s)) {}

Duty RelbotTwin::duty() const noexcept {
  const std::span<const double> u = task_.inputs();
  return {u[relbot_port::kDutyLeft], u[relbot_port::kDutyRight]};
}

}  // namespace hiltwin::app
