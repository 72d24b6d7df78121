#include "hiltwin/app_relbot/ecs_gains.h"

#include <toml++/toml.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>

namespace hiltwin::app {
namespace {

// File order of app_relbot/ecs_gains.toml. Ranges reject negative gains (a sign error turns
// negative feedback into positive) and values no RELbot-sized loop can use (a unit slip, e.g.
// a gain per millimetre written as per metre); they do not judge the tuning.
constexpr std::array<EcsGainSpec, 5> kSpecs{{
    {"pid", "kp_duty_per_m", &PidGains::kp_duty_per_m, 0.0, false, 1.0e5},
    {"pid", "ki_duty_per_m_s", &PidGains::ki_duty_per_m_s, 0.0, false, 1.0e7},
    {"pid", "kd_duty_s_per_m", &PidGains::kd_duty_s_per_m, 0.0, false, 1.0e3},
    {"pid", "derivative_filter_s", &PidGains::derivative_filter_s, 0.0, false, 1.0},
    {"output", "duty_limit", &PidGains::duty_limit, 0.0, true, 1.0},
}};

constexpr const char* kWhatToDo =
    "fix it in the file (app_relbot/ecs_gains.toml lists every key with its unit and the tuned "
    "value), or run without a gains file to use the built-in gains";

std::string FullKey(const EcsGainSpec& spec) {
  return std::string(spec.table) + "." + std::string(spec.key);
}

std::string Where(std::string_view source_name, const toml::source_region& region) {
  std::ostringstream out;
  out << source_name;
  if (region.begin.line != 0) out << ':' << region.begin.line << ':' << region.begin.column;
  return out.str();
}

std::string RangeText(const EcsGainSpec& spec) {
  std::ostringstream out;
  out << (spec.min_exclusive ? "> " : ">= ") << spec.min << " and <= " << spec.max;
  return out.str();
}

// Empty when the value is acceptable, otherwise why it is not.
std::string CheckValue(const EcsGainSpec& spec, double value) {
  if (!std::isfinite(value)) return "is not a finite number";
  const bool low = spec.min_exclusive ? !(value > spec.min) : !(value >= spec.min);
  if (low || value > spec.max) {
    std::ostringstream out;
    out << "= " << value << " is out of range: it must be " << RangeText(spec);
    return out.str();
  }
  return {};
}

const EcsGainSpec* FindSpec(std::string_view table, std::string_view key) {
  for (const EcsGainSpec& spec : kSpecs) {
    if (spec.table == table && spec.key == key) return &spec;
  }
  return nullptr;
}

bool IsKnownTable(std::string_view table) {
  for (const EcsGainSpec& spec : kSpecs) {
    if (spec.table == table) return true;
  }
  return false;
}

// Unknown tables and keys are almost always typos (or a unit suffix changed by hand):
// ignoring them would run the robot with the built-in gain the user meant to change.
void RejectUnknownKeys(const toml::table& root, std::string_view source_name) {
  for (const auto& [table_name, table_node] : root) {
    const toml::table* table = table_node.as_table();
    if (table == nullptr || !IsKnownTable(table_name.str())) {
      throw ConfigError(Where(source_name, table_node.source()) + ": unknown " +
                        (table == nullptr ? "top-level key '" : "table [") +
                        std::string(table_name.str()) + (table == nullptr ? "'" : "]") +
                        "; expected the tables pid and output; " + kWhatToDo);
    }
    for (const auto& [key, node] : *table) {
      if (FindSpec(table_name.str(), key.str()) == nullptr) {
        throw ConfigError(Where(source_name, node.source()) + ": unknown key " +
                          std::string(table_name.str()) + "." + std::string(key.str()) +
                          " (check the spelling and the unit suffix); " + kWhatToDo);
      }
    }
  }
}

double ReadValue(const toml::table& root, const EcsGainSpec& spec, std::string_view source_name) {
  const toml::node* node = root[spec.table][spec.key].node();
  if (node == nullptr) {
    throw ConfigError(std::string(source_name) + ": missing ECS gain " + FullKey(spec) +
                      " (a number " + RangeText(spec) + "); add it under [" +
                      std::string(spec.table) + "]; " + kWhatToDo);
  }
  const std::optional<double> value = node->value<double>();
  if (!node->is_number() || !value) {
    std::ostringstream type;
    type << node->type();
    throw ConfigError(Where(source_name, node->source()) + ": ECS gain " + FullKey(spec) +
                      " must be a number, not a " + type.str() + "; " + kWhatToDo);
  }
  const std::string why = CheckValue(spec, *value);
  if (!why.empty()) {
    throw ConfigError(Where(source_name, node->source()) + ": ECS gain " + FullKey(spec) + " " +
                      why + "; " + kWhatToDo);
  }
  return *value;
}

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
  for (const EcsGainSpec& spec : kSpecs) {
    const std::string why = CheckValue(spec, gains.*spec.member);
    if (!why.empty()) {
      throw ConfigError(std::string(source_name) + ": ECS gain " + FullKey(spec) + " " + why +
                        "; " + kWhatToDo);
    }
  }
}

PidGains ParseEcsGains(std::string_view toml_text, std::string_view source_name) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    throw ConfigError(Where(source_name, error.source()) +
                      ": not valid TOML: " + std::string(error.description()) + "; " + kWhatToDo);
  }
  RejectUnknownKeys(root, source_name);
  PidGains gains;
  for (const EcsGainSpec& spec : kSpecs) gains.*spec.member = ReadValue(root, spec, source_name);
  return gains;
}

PidGains LoadEcsGains(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    // generic_category().message, not strerror: the command may already run other threads.
    throw ConfigError(path.string() + ": cannot read the ECS gains file (" +
                      std::generic_category().message(errno) +
                      "); check the path, or run without a gains file to use the built-in "
                      "gains");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParseEcsGains(text.str(), path.string());
}

}  // namespace hiltwin::app
