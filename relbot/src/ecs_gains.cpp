#include "hiltwin/relbot/ecs_gains.h"

#include <array>

namespace hiltwin::app {
namespace {

// File order of relbot/ecs_gains.toml. Ranges reject negative gains (a sign error turns
// negative feedback into positive) and values no RELbot-sized loop can use (a unit slip, e.g.
// a gain per millimetre written as per metre); they do not judge the tuning.
constexpr std::array<EcsGainSpec, 5> kSpecs{{
    {"pid", "kp_duty_per_m", &PidGains::kp_duty_per_m, 0.0, false, 1.0e5},
    {"pid", "ki_duty_per_m_s", &PidGains::ki_duty_per_m_s, 0.0, false, 1.0e7},
    {"pid", "kd_duty_s_per_m", &PidGains::kd_duty_s_per_m, 0.0, false, 1.0e3},
    {"pid", "derivative_filter_s", &PidGains::derivative_filter_s, 0.0, false, 1.0},
    {"output", "duty_limit", &PidGains::duty_limit, 0.0, true, 1.0},
}};

constexpr TomlNumbersWording kWording{
    .value_name = "ECS gain",
    .file_name = "ECS gains file",
    .expected_tables = "pid and output",
    .file_hint = "relbot/ecs_gains.toml lists every key with its unit and the tuned value",
    .fallback = "run without a gains file to use the built-in gains",
};

}  // namespace

std::span<const EcsGainSpec> EcsGainSpecs() noexcept { return kSpecs; }

PidGains DefaultEcsGains() noexcept {
  PidGains gains;
  gains.kp_duty_per_m = 100.0;
  gains.ki_duty_per_m_s = 1000.0;
  gains.kd_duty_s_per_m = 3.0;
  gains.derivative_filter_s = 0.005;
  gains.duty_limit = 1.0;
  return gains;
}

void ValidateEcsGains(const PidGains& gains, std::string_view source_name) {
  ValidateTomlNumbers(gains, source_name, kSpecs, kWording);
}

PidGains ParseEcsGains(std::string_view toml_text, std::string_view source_name) {
  return ParseTomlNumbers(toml_text, source_name, kSpecs, kWording);
}

PidGains LoadEcsGains(const std::filesystem::path& path) {
  return LoadTomlNumbers(path, kSpecs, kWording);
}

}  // namespace hiltwin::app
