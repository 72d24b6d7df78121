// The TOML reading plant and controller maps share (map_toml.h).
#include "hiltwin/plant/map_toml.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

namespace hiltwin::plant::map_toml {
namespace {

constexpr int kChannels = 4;

}  // namespace

std::string Where(std::string_view source, const toml::source_region& region) {
  return Where(source, static_cast<int>(region.begin.line), static_cast<int>(region.begin.column));
}

std::string Where(std::string_view source, int line, int column) {
  std::string out(source);
  if (line > 0) out += ":" + std::to_string(line);
  if (line > 0 && column > 0) out += ":" + std::to_string(column);
  return out;
}

void Fail(std::string_view source, const toml::node& at, const std::string& what) {
  throw MapTomlError(Where(source, at.source()) + ": " + what);
}

std::string Num(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

toml::table ParseRoot(std::string_view toml_text, std::string_view source) {
  try {
    return toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    throw MapTomlError(Where(source, e.source()) + ": not valid TOML: " +
                       std::string(e.description()));
  }
}

std::string ReadMapFile(const std::filesystem::path& path, std::string_view map_name,
                        std::string_view what_to_do) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    char buffer[256];
    const std::string why = strerror_r(errno, buffer, sizeof buffer);
    throw MapTomlError("cannot read the " + std::string(map_name) + " " + path.string() + ": " +
                       why + "; " + std::string(what_to_do));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void CheckKeys(std::string_view source, const toml::table& table, std::string_view table_name,
               std::initializer_list<std::string_view> known) {
  for (const auto& entry : table) {
    const toml::key& key = entry.first;
    bool found = false;
    for (const std::string_view k : known) found = found || k == key.str();
    if (found) continue;
    std::string list;
    for (const std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    // The key's own place: its value is not what is wrong.
    throw MapTomlError(Where(source, key.source()) + ": unknown key '" + std::string(key.str()) +
                       "' in " + std::string(table_name) + " (known: " + list + ")");
  }
}

const toml::array* ArrayOfTables(std::string_view source, const toml::table& root,
                                 std::string_view key) {
  const toml::node* node = root.get(key);
  if (node == nullptr) return nullptr;
  const toml::array* array = node->as_array();
  if (array == nullptr || !array->is_array_of_tables()) {
    Fail(source, *node, "'" + std::string(key) + "' must be written as [[" + std::string(key) +
                            "]] tables, one per channel");
  }
  return array;
}

void Entry::Fail(std::string_view key, const std::string& what) const {
  const toml::node* node = table_.get(key);
  map_toml::Fail(source_, node != nullptr ? *node : table_, what);
}

int Entry::Channel() const {
  const toml::node* node = table_.get("channel");
  if (node == nullptr) Fail("channel", name_ + " has no 'channel' (a board channel 1..4)");
  // value_exact: toml++'s value<int64_t>() converts a float by a cast that is undefined for
  // one outside int64_t (channel = 3e75, found by fuzz/toml_config); a channel is an integer.
  const std::optional<std::int64_t> value = node->value_exact<std::int64_t>();
  if (!value || *value < 1 || *value > kChannels) {
    Fail("channel", name_ + ": channel must be an integer 1..4 (board channel n, as in "
                            "thesis appendix G's channel1..channel4)");
  }
  return static_cast<int>(*value);
}

std::string Entry::String(std::string_view key, bool required) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) {
    if (required) Fail(key, name_ + " has no '" + std::string(key) + "'");
    return {};
  }
  const std::optional<std::string> value = node->value<std::string>();
  if (!value || value->empty()) {
    Fail(key, name_ + ": '" + std::string(key) + "' must be a non-empty string");
  }
  return *value;
}

std::optional<double> Entry::Number(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const std::optional<double> value = node->value<double>();  // integers convert too
  if (!value || !std::isfinite(*value)) {
    Fail(key, name_ + ": '" + std::string(key) + "' must be a finite number");
  }
  return value;
}

std::optional<double> Entry::Scale(std::string_view key) const {
  const std::optional<double> value = Number(key);
  if (value && *value < 0.0) {
    Fail(key, name_ + ": " + std::string(key) + " " + Num(*value) +
                  " is negative: give its size and reverse = true (the direction pin then means "
                  "the other way)");
  }
  return value;
}

double Entry::Positive(std::string_view key) const {
  const std::optional<double> value = Number(key);
  if (value && *value <= 0.0) {
    Fail(key, name_ + ": '" + std::string(key) + "' = " + Num(*value) + " must be > 0");
  }
  return value.value_or(0.0);
}

bool Entry::Flag(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return false;
  const std::optional<bool> value = node->value<bool>();
  if (!value) Fail(key, name_ + ": '" + std::string(key) + "' must be true or false");
  return *value;
}

std::pair<int, int> Entry::Place(std::string_view key) const {
  const toml::node* node = table_.get(key);
  const toml::source_position at = (node != nullptr ? node->source() : table_.source()).begin;
  return {static_cast<int>(at.line), static_cast<int>(at.column)};
}

std::string Entry::EncoderUnit() const {
  std::string unit = String("unit", true);
  if (unit != "m" && unit != "rad") {
    Fail("unit",
         name_ + ": unit \"" + unit + "\" is not one an encoder measures: \"m\" or \"rad\"");
  }
  return unit;
}

/// A scale the board can follow: at most kMaxCountsPerUnit. `at` is the key that set it last.
double Entry::Representable(const toml::node& at, const std::string& unit,
                            double counts_per_unit) const {
  if (!(counts_per_unit > 0.0)) {  // keys far below 1 multiplied to nothing
    map_toml::Fail(source_, at, name_ + ": the scale comes to 0 counts per " + unit +
                                    ": check the scale's keys and their units");
  }
  if (counts_per_unit <= kMaxCountsPerUnit) return counts_per_unit;
  map_toml::Fail(
      source_, at,
      name_ + ": " + Num(counts_per_unit) + " counts per " + unit + " is more than " +
          Num(kMaxCountsPerUnit) + ", the most counts the board emits in a second (" +
          Num(static_cast<double>(io::kFpgaClockHz) / 1e6) + " MHz over its smallest clock "
          "divider, " + std::to_string(io::kMinClockDivider) +
          "): it could not follow the output moving one " + unit +
          " per second; check the scale's keys and their units");
}

double Entry::EncoderScale(const std::string& unit) const {
  const std::optional<double> direct = Scale("counts_per_unit");
  const double per_rev = Positive("counts_per_rev");
  if (direct && per_rev > 0.0) {
    Fail("counts_per_rev", name_ + " gives both counts_per_unit and counts_per_rev: keep one");
  }
  if (direct) {
    const toml::node& at = *table_.get("counts_per_unit");
    if (*direct == 0.0) map_toml::Fail(source_, at, name_ + ": 0 counts per unit");
    return Representable(at, unit, *direct);
  }
  if (per_rev == 0.0) {
    map_toml::Fail(source_, table_,
                   name_ + " has no scale: give counts_per_unit, or counts_per_rev (with "
                           "gear_ratio, and wheel_radius_m when unit = \"m\")");
  }
  const bool geared = table_.contains("gear_ratio");
  const double ratio = geared ? Positive("gear_ratio") : 1.0;
  // Output radians turn the encoder's shaft `ratio` times as far; metres are radians times r.
  const double per_rad = per_rev * ratio / (2.0 * std::numbers::pi);
  const toml::node& shaft = *table_.get(geared ? "gear_ratio" : "counts_per_rev");
  if (unit == "rad") return Representable(shaft, unit, per_rad);
  const double radius_m = Positive("wheel_radius_m");
  if (radius_m == 0.0) {
    map_toml::Fail(source_, table_,
                   name_ + ": unit \"m\" with counts_per_rev needs wheel_radius_m");
  }
  return Representable(*table_.get("wheel_radius_m"), unit, per_rad / radius_m);
}

std::vector<ConstantInput> ParseConstants(std::string_view source, const toml::table& root) {
  std::vector<ConstantInput> out;
  const toml::node* node = root.get("inputs");
  if (node == nullptr) return out;
  const toml::table* table = node->as_table();
  if (table == nullptr) Fail(source, *node, "[inputs] must be a table of name = value");
  for (const auto& [key, value] : *table) {
    const std::optional<double> number = value.value<double>();
    if (!number || !std::isfinite(*number)) {
      Fail(source, value, "[inputs] " + std::string(key.str()) + " must be a finite number");
    }
    const toml::source_position at = value.source().begin;
    out.push_back({std::string(key.str()), *number, static_cast<int>(at.line),
                   static_cast<int>(at.column)});
  }
  return out;
}

std::optional<std::size_t> PortIndex(const std::vector<Port>& ports, const std::string& name) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  return std::nullopt;
}

std::string PortNames(const std::vector<Port>& ports) {
  if (ports.empty()) return "none";
  std::string out;
  for (const Port& port : ports) out += (out.empty() ? "" : ", ") + port.name;
  return out;
}

}  // namespace hiltwin::plant::map_toml
