#include "hiltwin/app_relbot/relbot_params.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <toml++/toml.h>

namespace hiltwin::app {
namespace {

constexpr double kMax = 1.0e300;

// File order of app_relbot/relbot.toml. Ranges reject what is not physical (negative masses,
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

constexpr const char* kWhatToDo =
    "fix it in the file (app_relbot/relbot.toml lists every key with its unit and a documented "
    "value), or run without a parameter file to use the built-in set";

std::string FullKey(const ParamSpec& spec) {
  return std::string(spec.table) + "." + std::string(spec.key);
}

std::string Where(std::string_view source_name, const toml::source_region& region) {
  std::ostringstream out;
  out << source_name;
  if (region.begin.line != 0) out << ':' << region.begin.line << ':' << region.begin.column;
  return out.str();
}

std::string RangeText(const ParamSpec& spec) {
  std::ostringstream out;
  out << (spec.min_exclusive ? "> " : ">= ") << spec.min;
  if (spec.max < kMax) out << " and <= " << spec.max;
  return out.str();
}

// Returns an empty string when the value is acceptable, otherwise why it is not.
std::string CheckValue(const ParamSpec& spec, double value) {
  if (!std::isfinite(value)) return "is not a finite number";
  const bool low = spec.min_exclusive ? !(value > spec.min) : !(value >= spec.min);
  if (low || value > spec.max) {
    std::ostringstream out;
    out << "= " << value << " is out of range: it must be " << RangeText(spec);
    return out.str();
  }
  return {};
}

const ParamSpec* FindSpec(std::string_view table, std::string_view key) {
  for (const ParamSpec& spec : kSpecs) {
    if (spec.table == table && spec.key == key) return &spec;
  }
  return nullptr;
}

bool IsKnownTable(std::string_view table) {
  for (const ParamSpec& spec : kSpecs) {
    if (spec.table == table) return true;
  }
  return false;
}

}  // namespace

std::span<const ParamSpec> RelbotParamSpecs() noexcept { return kSpecs; }

void ValidateRelbotParams(const RelbotParams& params, std::string_view source_name) {
  for (const ParamSpec& spec : kSpecs) {
    const std::string why = CheckValue(spec, params.*spec.member);
    if (!why.empty()) {
      throw ConfigError(std::string(source_name) + ": RELbot parameter " + FullKey(spec) + " " +
                        why + "; " + kWhatToDo);
    }
  }
}

RelbotParams ParseRelbotParams(std::string_view toml_text, std::string_view source_name) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    throw ConfigError(Where(source_name, error.source()) + ": not valid TOML: " +
                      std::string(error.description()) + "; " + kWhatToDo);
  }

  // Unknown tables and keys are almost always typos of a known one; silently ignoring them
  // would run the model with the built-in value the user meant to change.
  for (const auto& [table_name, table_node] : root) {
    const toml::table* table = table_node.as_table();
    if (table == nullptr || !IsKnownTable(table_name.str())) {
      throw ConfigError(Where(source_name, table_node.source()) + ": unknown " +
                        (table == nullptr ? "top-level key '" : "table [") +
                        std::string(table_name.str()) + (table == nullptr ? "'" : "]") +
                        "; expected the tables supply, motor, gear, encoder, wheel, body, "
                        "contact, castor; " + kWhatToDo);
    }
    for (const auto& [key, node] : *table) {
      if (FindSpec(table_name.str(), key.str()) == nullptr) {
        throw ConfigError(Where(source_name, node.source()) + ": unknown key " +
                          std::string(table_name.str()) + "." + std::string(key.str()) +
                          " (check the spelling and the unit suffix); " + kWhatToDo);
      }
    }
  }

  RelbotParams params;
  for (const ParamSpec& spec : kSpecs) {
    const toml::node* node = root[spec.table][spec.key].node();
    if (node == nullptr) {
      throw ConfigError(std::string(source_name) + ": missing RELbot parameter " +
                        FullKey(spec) + " (a number " + RangeText(spec) +
                        "); add it under [" + std::string(spec.table) + "]; " + kWhatToDo);
    }
    const std::optional<double> value = node->value<double>();
    if (!node->is_number() || !value) {
      std::ostringstream type;
      type << node->type();
      throw ConfigError(Where(source_name, node->source()) + ": RELbot parameter " +
                        FullKey(spec) + " must be a number, not a " + type.str() + "; " +
                        kWhatToDo);
    }
    const std::string why = CheckValue(spec, *value);
    if (!why.empty()) {
      throw ConfigError(Where(source_name, node->source()) + ": RELbot parameter " +
                        FullKey(spec) + " " + why + "; " + kWhatToDo);
    }
    params.*spec.member = *value;
  }
  return params;
}

RelbotParams LoadRelbotParams(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw ConfigError(path.string() + ": cannot read the RELbot parameter file (" +
                      std::string(std::strerror(errno)) +
                      "); check the path, or run without a parameter file to use the built-in "
                      "set");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParseRelbotParams(text.str(), path.string());
}

io::WheelGeometry WheelGeometryOf(const RelbotParams& params) noexcept {
  return io::WheelGeometry{params.wheel_radius_m, params.gear_ratio_motor_rev_per_wheel_rev,
                           params.encoder_counts_per_motor_rev};
}

double EncoderCountsPerMetre(const RelbotParams& params) noexcept {
  return io::CountsPerMetre(WheelGeometryOf(params));
}

}  // namespace hiltwin::app
