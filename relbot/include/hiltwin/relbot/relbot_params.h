#pragma once
/// Physical parameters of the RELbot plant model and their TOML file (relbot/relbot.toml).
/// The thesis publishes no parameter values; the defaults are plausible for a ~2 kg two-wheel
/// robot with 12 V geared DC motors and quadrature encoders (see docs/relbot-model.md and the
/// comment on every key in relbot.toml). The defaults below and relbot.toml must agree; a unit
/// test checks it.

#include <filesystem>
#include <span>
#include <string_view>

#include "hiltwin/io/conversions.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/toml_numbers.h"

namespace hiltwin::app {

/// RELbot parameters in SI units; the member name carries the unit.
struct RelbotParams {
  double supply_voltage_v = 12.0;                        ///< motor driver supply (duty 1 = this)
  double motor_resistance_ohm = 4.0;                     ///< armature resistance
  double motor_torque_constant_n_m_per_a = 0.01;         ///< k_t
  double motor_back_emf_constant_v_s_per_rad = 0.01;     ///< k_e (= k_t in SI for an ideal motor)
  double motor_rotor_inertia_kg_m2 = 1.0e-6;             ///< rotor (and encoder disc)
  double motor_viscous_friction_n_m_s_per_rad = 2.0e-6;  ///< motor + gearbox, at the motor shaft
  double gear_ratio_motor_rev_per_wheel_rev = 50.0;  ///< reduction N (motor turns per wheel turn)
  double encoder_counts_per_motor_rev = 64.0;        ///< quadrature counts (4 x lines)
  double wheel_radius_m = 0.04;
  double wheel_mass_kg = 0.1;                        ///< one wheel with hub
  double wheel_inertia_kg_m2 = 8.0e-5;               ///< one wheel about its axle
  double body_mass_kg = 1.8;                         ///< everything except the two wheels
  double body_yaw_inertia_kg_m2 = 0.01;              ///< body about the vertical axis at the CoM
  double track_width_m = 0.17;                       ///< distance between the wheel contacts
  double contact_stiffness_n_per_m = 2.0e4;          ///< wheel-to-body spring (X)
  double contact_damping_n_s_per_m = 150.0;          ///< wheel-to-body damper (X)
  double contact_lateral_damping_n_s_per_m = 200.0;  ///< both wheels' resistance to side slip (Y)
  double castor_offset_m = 0.10;                     ///< castor behind the CoM along -X
  double castor_viscous_friction_n_s_per_m = 0.2;
  double castor_coulomb_friction_n = 0.12;       ///< rolling resistance
  double castor_smoothing_speed_m_per_s = 0.01;  ///< below this the Coulomb term fades out
};

/// How one parameter appears in the TOML file and which values it accepts.
using ParamSpec = TomlNumberSpec<RelbotParams>;

/// Every parameter, in file order. The loader, the validator and the tests iterate this.
[[nodiscard]] std::span<const ParamSpec> RelbotParamSpecs() noexcept;

/// The built-in parameter set (identical to relbot/relbot.toml).
[[nodiscard]] inline RelbotParams DefaultRelbotParams() noexcept { return RelbotParams{}; }

/// Checks every value is finite and within its range; throws ConfigError naming
/// `source_name` and the key ("table.key").
void ValidateRelbotParams(const RelbotParams& params, std::string_view source_name);

/// Parses TOML text. Every key of RelbotParamSpecs() is required, unknown keys are rejected
/// (they are usually typos). Throws ConfigError with source_name:line:column where known.
[[nodiscard]] RelbotParams ParseRelbotParams(std::string_view toml_text,
                                             std::string_view source_name);

/// Reads and parses a TOML parameter file. Throws ConfigError (also when it cannot be read).
[[nodiscard]] RelbotParams LoadRelbotParams(const std::filesystem::path& path);

/// The wheel geometry the FPGA conversions need (radius, gearbox, encoder), from `params`.
[[nodiscard]] io::WheelGeometry WheelGeometryOf(const RelbotParams& params) noexcept;

/// Encoder counts per metre of wheel travel (m / (2π radius) · N · counts per motor turn).
[[nodiscard]] double EncoderCountsPerMetre(const RelbotParams& params) noexcept;

}  // namespace hiltwin::app
