// The RELbot as a plant (relbot_plant.h).
#include "hiltwin/relbot/relbot_plant.h"

#include <mutex>

#include "hiltwin/plant/plant_registry.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {
namespace {

void WriteOutputs(const RelbotOutputs& out, std::span<double> y) noexcept {
  y[relbot_port::kWheelLeftM] = out.wheel_left_m;
  y[relbot_port::kWheelRightM] = out.wheel_right_m;
  y[relbot_port::kXM] = out.x_m;
  y[relbot_port::kYM] = out.y_m;
  y[relbot_port::kThetaRad] = out.theta_rad;
}

plant::EncoderRoute WheelEncoder(std::size_t channel_index, const char* output, const char* column,
                                 const char* joint, const RelbotParams& params) {
  plant::EncoderRoute route;
  route.channel = static_cast<int>(channel_index) + 1;
  route.output = output;
  route.unit = "m";
  route.counts_per_unit = EncoderCountsPerMetre(params);
  route.column = column;
  route.joint = joint;
  route.wheel_radius_m = params.wheel_radius_m;
  return route;
}

}  // namespace

RelbotPlant::RelbotPlant(const RelbotParams& params, Integrator integrator)
    : params_(params), integrator_(integrator) {
  // Port names are the log's column names, unchanged from before plants were pluggable.
  info_.name = kRelbotPlantName;
  info_.kind = "built-in";
  info_.inputs = {{"duty_left", "1"}, {"duty_right", "1"}};
  info_.outputs = {{"wheel_left_m", "m"}, {"wheel_right_m", "m"}, {"x_m", "m"},
                   {"y_m", "m"},          {"theta_rad", "rad"}};
  info_.details = {{"integrator", std::string(IntegratorName(integrator))}};
}

void RelbotPlant::Start(double step_s, std::span<double> y0) {
  try {
    model_.emplace(params_, integrator_, step_s);
  } catch (const ConfigError& e) {  // the step is out of range or not stable
    throw plant::PlantStepError(e.what());
  }
  WriteOutputs(model_->Outputs(), y0);
}

plant::PlantStatus RelbotPlant::Step(std::span<const double> u, std::span<double> y) noexcept {
  model_->Step(u[relbot_port::kDutyLeft], u[relbot_port::kDutyRight]);
  if (!model_->StateIsFinite()) {
    return plant::PlantStatus::Fault("the model state became non-finite (NaN or Inf)");
  }
  WriteOutputs(model_->Outputs(), y);
  return plant::PlantStatus::Ok();
}

void RelbotPlant::Reset(std::span<double> y0) {
  model_.value().Reset();
  WriteOutputs(model_->Outputs(), y0);
}

plant::PlantMap RelbotDefaultMap(const RelbotParams& params) {
  plant::PlantMap map;
  map.source = "the built-in map of relbot";
  // Appendix G: u[0] = channel2 // Left, u[1] = channel1 // Right; enc1 = right, enc2 = left.
  map.pwm = {{static_cast<int>(kLeftChannel) + 1, "duty_left", 1.0, false, 0, 0},
             {static_cast<int>(kRightChannel) + 1, "duty_right", 1.0, false, 0, 0}};
  map.encoders = {
      WheelEncoder(kLeftChannel, "wheel_left_m", "enc_left", "wheel_left_joint", params),
      WheelEncoder(kRightChannel, "wheel_right_m", "enc_right", "wheel_right_joint", params)};
  map.pose = std::array<std::string, 3>{"x_m", "y_m", "theta_rad"};
  return map;
}

void RegisterRelbotPlant() {
  static std::once_flag once;
  std::call_once(once, [] {
    plant::RegisterPlant(
        {kRelbotPlantName,
         "the RELbot differential-drive robot (built in; --config, --integrator)",
         [](const plant::PlantOptions& o) -> std::unique_ptr<plant::Plant> {
           try {
             const RelbotParams params =
                 o.config_path.empty() ? DefaultRelbotParams() : LoadRelbotParams(o.config_path);
             const Integrator integrator =
                 ParseIntegrator(o.integrator.empty() ? "rk4" : o.integrator);
             return std::make_unique<RelbotPlant>(params, integrator);
           } catch (const ConfigError& e) {
             throw plant::PlantError(e.what());
           }
         },
         [](const plant::Plant& p) {
           return RelbotDefaultMap(static_cast<const RelbotPlant&>(p).params());
         }});
  });
}

}  // namespace hiltwin::app
