// The TOML configuration files: RELbot parameters (relbot.toml, relbot/relbot_params.h)
// and ECS gains (ecs_gains.toml, ecs_gains.h), both documenting ConfigError, and plant maps
// (relbot/relbot_map.toml and --plant-map files, plant/plant_map.h), documenting
// PlantMapError. What a reader accepts must pass its own validator (a value the parser let in
// but the validator refuses would reach the model unchecked elsewhere).
//
// Input: byte 0 chooses the reader (0: RELbot parameters, 1: ECS gains, 2 and 3: plant map);
// the rest is the TOML text. A map that parses is then bound to a plant with the RELbot's and
// msd20sim's ports (BindPlantMap, also documenting PlantMapError).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

#include "fuzz_util.h"
#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_map.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/relbot_params.h"

namespace {

using namespace hiltwin;

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FINDING: %s\n", what);
    std::abort();
  }
}

/// The ports of the RELbot and msd20sim plants, so maps written for either bind (BindPlantMap
/// is the second half of reading a map: names, causality and units against a plant).
class PortsOnlyPlant final : public plant::Plant {
 public:
  PortsOnlyPlant() {
    info_.name = "fuzz";
    info_.kind = "ports only";
    info_.inputs = {{"duty_left", "1"}, {"duty_right", "1"}, {"force_n", "N"}};
    info_.outputs = {{"wheel_left_m", "m"}, {"wheel_right_m", "m"}, {"x_m", "m"}, {"y_m", "m"},
                     {"theta_rad", "rad"}, {"position_m", "m"}, {"angle", ""}};
  }
  [[nodiscard]] const plant::PlantInfo& Info() const noexcept override { return info_; }
  void Start(double, std::span<double>) override {}
  [[nodiscard]] plant::PlantStatus Step(std::span<const double>,
                                        std::span<double>) noexcept override {
    return plant::PlantStatus::Ok();
  }
  void Reset(std::span<double>) override {}

 private:
  plant::PlantInfo info_;
};

void CheckPlantMap(const plant::PlantMap& map) {
  for (const auto& route : map.pwm) {
    Require(route.channel >= 1 && route.channel <= 4 && std::isfinite(route.gain),
            "a plant map accepts a PWM route outside its documented rules");
  }
  for (const auto& route : map.encoders) {
    Require(route.channel >= 1 && route.channel <= 4 && std::isfinite(route.counts_per_unit) &&
                route.counts_per_unit != 0.0,
            "a plant map accepts an encoder route outside its documented rules");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const unsigned mode = data[0] & 3U;
  const auto text = fuzz::AsText(data + 1, size - 1);
  if (mode == 0) {
    try {
      const app::RelbotParams params = app::ParseRelbotParams(text, "fuzz.toml");
      try {
        app::ValidateRelbotParams(params, "fuzz.toml");
      } catch (const app::ConfigError&) {
        Require(false, "ParseRelbotParams accepts what ValidateRelbotParams refuses");
      }
    } catch (const app::ConfigError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ParseRelbotParams")
  } else if (mode == 1) {
    try {
      const app::PidGains gains = app::ParseEcsGains(text, "fuzz.toml");
      try {
        app::ValidateEcsGains(gains, "fuzz.toml");
      } catch (const app::ConfigError&) {
        Require(false, "ParseEcsGains accepts what ValidateEcsGains refuses");
      }
    } catch (const app::ConfigError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ParseEcsGains")
  } else {
    try {
      const plant::PlantMap map = plant::ParsePlantMap(text, "fuzz.toml");
      CheckPlantMap(map);
      static const PortsOnlyPlant ports;
      (void)plant::BindPlantMap(map, ports);
    } catch (const plant::PlantMapError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ParsePlantMap")
  }
  return 0;
}
