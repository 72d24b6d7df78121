#include "hiltwin/relbot/relbot_params.h"

#include <array>

namespace hiltwin::app {
namespace {

// File order of relbot/relbot.toml. Ranges reject what is not physical (negative masses,
// zero resistance) and what is certainly a unit slip (a 1 km wheel); they do not judge taste.
constexpr std::array<ParamSpec, 21> kSpecs{{
    {"supply", "voltage_v", &RelbotParams::supply_voltage_v, 0.0, true, 1000.0},
    {"motor", "resistance_ohm", &RelbotParams::motor_resistance_ohm, 0.0, true, 1.0e4},
    {"motor", "torque_constant_n_m_per_a", &RelbotParams::motor_torque_constant_n_m_per_a, 0.0,
     true, 100.0},
    {"motor", "back_emf_constant_v_s_per_rad",
     &RelbotParams::motor_back_emf_constant_v_s_per_rad, 0.0, true, 100.0},
    {"motor", "rotor_inertia_kg_m2", &RelbotParams::motor_rotor_inertia_kg_m2, 0.0, true, 10.0},
    {"motor", "viscous_friction_n_m_s_per_rad",
     &RelbotParams::motor_viscous_friction_n_m_s_per_rad, 0.0, false, 10.0},
    {"gear", "ratio_motor_rev_per_wheel_rev", &RelbotParams::gear_ratio_motor_rev_per_wheel_rev,
     0.0, true, 1.0e5},
    {"encoder", "counts_per_motor_rev", &RelbotParams::encoder_counts_per_motor_rev, 1.0, false,
     1.0e7},
    {"wheel", "radius_m", &RelbotParams::wheel_radius_m, 0.0, true, 10.0},
    {"wheel", "mass_kg", &RelbotParams::wheel_mass_kg, 0.0, false, 1.0e4},
    {"wheel", "inertia_kg_m2", &RelbotParams::wheel_inertia_kg_m2, 0.0, false, 1.0e4},
    {"body", "mass_kg", &RelbotParams::body_mass_kg, 0.0, true, 1.0e5},
    {"body", "yaw_inertia_kg_m2", &RelbotParams::body_yaw_inertia_kg_m2, 0.0, true, 1.0e5},
    {"body", "track_width_m", &RelbotParams::track_width_m, 0.0, true, 100.0},
    {"contact", "stiffness_n_per_m", &RelbotParams::contact_stiffness_n_per_m, 0.0, true, 1.0e9},
    {"contact", "damping_n_s_per_m", &RelbotParams::contact_damping_n_s_per_m, 0.0, true, 1.0e7},
    {"contact", "lateral_damping_n_s_per_m", &RelbotParams::contact_lateral_damping_n_s_per_m,
     0.0, true, 1.0e7},
    {"castor", "offset_m", &RelbotParams::castor_offset_m, 0.0, false, 100.0},
    {"castor", "viscous_friction_n_s_per_m", &RelbotParams::castor_viscous_friction_n_s_per_m,
     0.0, false, 1.0e5},
    {"castor", "coulomb_friction_n", &RelbotParams::castor_coulomb_friction_n, 0.0, false, 1.0e5},
    {"castor", "smoothing_speed_m_per_s", &RelbotParams::castor_smoothing_speed_m_per_s, 0.0,
     true, 100.0},
}};

constexpr TomlNumbersWording kWording{
    .value_name = "RELbot parameter",
    .file_name = "RELbot parameter file",
    .expected_tables = "supply, motor, gear, encoder, wheel, body, contact, castor",
    .file_hint = "relbot/relbot.toml lists every key with its unit and a documented value",
    .fallback = "run without a parameter file to use the built-in set",
};

}  // namespace

std::span<const ParamSpec> RelbotParamSpecs() noexcept { return kSpecs; }

void ValidateRelbotParams(const RelbotParams& params, std::string_view source_name) {
  ValidateTomlNumbers(params, source_name, kSpecs, kWording);
}

RelbotParams ParseRelbotParams(std::string_view toml_text, std::string_view source_name) {
  return ParseTomlNumbers(toml_text, source_name, kSpecs, kWording);
}

RelbotParams LoadRelbotParams(const std::filesystem::path& path) {
  return LoadTomlNumbers(path, kSpecs, kWording);
}

io::WheelGeometry WheelGeometryOf(const RelbotParams& params) noexcept {
  return io::WheelGeometry{params.wheel_radius_m, params.gear_ratio_motor_rev_per_wheel_rev,
                           params.encoder_counts_per_motor_rev};
}

double EncoderCountsPerMetre(const RelbotParams& params) noexcept {
  return io::CountsPerMetre(WheelGeometryOf(params));
}

}  // namespace hiltwin::app
