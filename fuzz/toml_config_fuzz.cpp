// The TOML configuration files: RELbot parameters (relbot.toml, app_relbot/relbot_params.h)
// and ECS gains (ecs_gains.toml, ecs_gains.h), both documenting ConfigError, and plant maps
// (app_relbot/relbot_map.toml and --plant-map files, plant/plant_map.h), documenting
// PlantMapError. What a reader accepts must pass its own validator (a value the parser let in
// but the validator refuses would reach the model unchecked elsewhere).
//
// Input: byte 0 chooses the reader (0: RELbot parameters, 1: ECS gains, 2 and 3: plant map);
// the rest is the TOML text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_util.h"
#include "hiltwin/app_relbot/ecs_gains.h"
#include "hiltwin/app_relbot/relbot_params.h"
#include "hiltwin/plant/plant_map.h"

namespace {

using namespace hiltwin;

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FINDING: %s\n", what);
    std::abort();
  }
}

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
      CheckPlantMap(plant::ParsePlantMap(text, "fuzz.toml"));
    } catch (const plant::PlantMapError&) {
    }
    HILTWIN_FUZZ_UNDOCUMENTED("ParsePlantMap")
  }
  return 0;
}
