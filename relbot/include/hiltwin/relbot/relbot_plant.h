#pragma once
/// The RELbot as a plant (plant/plant.h): inputs the two duties, outputs both wheels' travel
/// and the pose. Its board I/O (which channel is which wheel, metres -> encoder counts,
/// thesis appendix G) is a plant map like any other plant's: RelbotDefaultMap, the same as the
/// shipped relbot/relbot_map.toml for the default parameters.

#include <optional>
#include <span>

#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"
#include "hiltwin/relbot/integrator.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {

/// Port positions of the RELbot plant (inputs and outputs are separate lists).
namespace relbot_port {
inline constexpr std::size_t kDutyLeft = 0;   ///< input, duty in [-1, 1]
inline constexpr std::size_t kDutyRight = 1;  ///< input
inline constexpr std::size_t kWheelLeftM = 0;   ///< output: left wheel travel
inline constexpr std::size_t kWheelRightM = 1;  ///< output
inline constexpr std::size_t kXM = 2;           ///< output: centre of mass, world frame
inline constexpr std::size_t kYM = 3;           ///< output
inline constexpr std::size_t kThetaRad = 4;     ///< output: heading, unwrapped
}  // namespace relbot_port

/// The plant name `--plant` knows the RELbot by (the default).
inline constexpr const char* kRelbotPlantName = "relbot";

class RelbotPlant final : public plant::Plant {
 public:
  /// params must be valid (LoadRelbotParams and DefaultRelbotParams give valid ones).
  RelbotPlant(const RelbotParams& params, Integrator integrator);

  [[nodiscard]] const plant::PlantInfo& Info() const noexcept override { return info_; }
  /// Builds the model at `step_s`; a step the integrator cannot keep stable is a PlantError
  /// with the reason (RelbotModel's check).
  void Start(double step_s, std::span<double> y0) override;
  [[nodiscard]] plant::PlantStatus Step(std::span<const double> u,
                                        std::span<double> y) noexcept override;
  void Reset(std::span<double> y0) override;

  [[nodiscard]] const RelbotParams& params() const noexcept { return params_; }
  [[nodiscard]] Integrator integrator() const noexcept { return integrator_; }
  /// The model, once started.
  [[nodiscard]] const RelbotModel& model() const { return model_.value(); }

 private:
  RelbotParams params_;
  Integrator integrator_;
  plant::PlantInfo info_;
  std::optional<RelbotModel> model_;
};

/// The RELbot's board wiring as a plant map (thesis appendix G): channel 2 drives duty_left
/// and follows wheel_left_m, channel 1 the right wheel; counts per metre from the params'
/// wheel radius, gear ratio and encoder; the pose and both wheels as telemetry.
[[nodiscard]] plant::PlantMap RelbotDefaultMap(const RelbotParams& params);

/// Adds "relbot" to the plant registry (plant_registry.h); idempotent.
void RegisterRelbotPlant();

}  // namespace hiltwin::app
