// Plant maps (plant_map.h): parsed from TOML, then bound to one plant's ports.
#include "hiltwin/plant/plant_map.h"

#include <toml++/toml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>
#include <tuple>

namespace hiltwin::plant {
namespace {

constexpr int kChannels = 4;

std::string Where(std::string_view source, const toml::source_region& region) {
  std::ostringstream out;
  out << source;
  if (region.begin.line != 0) out << ':' << region.begin.line;
  if (region.begin.line != 0 && region.begin.column != 0) out << ':' << region.begin.column;
  return out.str();
}

[[noreturn]] void Fail(std::string_view source, const toml::node& at, const std::string& what) {
  throw PlantMapError(Where(source, at.source()) + ": " + what);
}

std::string Num(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// Refuses keys a table does not know, so a typo cannot silently fall back to a default.
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
    throw PlantMapError(Where(source, key.source()) + ": unknown key '" + std::string(key.str()) +
                        "' in " + std::string(table_name) + " (known: " + list + ")");
  }
}

/// Reads a table's entries one key at a time, with the entry's name in every message.
class Entry {
 public:
  Entry(std::string_view source, const toml::table& table, std::string name)
      : source_(source), table_(table), name_(std::move(name)) {}

  [[nodiscard]] int Channel() const {
    const toml::node* node = table_.get("channel");
    if (node == nullptr) Fail(source_, table_, name_ + " has no 'channel' (a board channel 1..4)");
    // value_exact: toml++'s value<int64_t>() converts a float by a cast that is undefined for
    // one outside int64_t (channel = 3e75, found by fuzz/toml_config); a channel is an integer.
    const std::optional<std::int64_t> value = node->value_exact<std::int64_t>();
    if (!value || *value < 1 || *value > kChannels) {
      Fail(source_, *node, name_ + ": channel must be an integer 1..4 (board channel n, as in "
                                    "thesis appendix G's channel1..channel4)");
    }
    return static_cast<int>(*value);
  }
  [[nodiscard]] std::string String(std::string_view key, bool required) const {
    const toml::node* node = table_.get(key);
    if (node == nullptr) {
      if (required) Fail(source_, table_, name_ + " has no '" + std::string(key) + "'");
      return {};
    }
    const std::optional<std::string> value = node->value<std::string>();
    if (!value || value->empty()) {
      Fail(source_, *node, name_ + ": '" + std::string(key) + "' must be a non-empty string");
    }
    return *value;
  }
  [[nodiscard]] std::optional<double> Number(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (node == nullptr) return std::nullopt;
    const std::optional<double> value = node->value<double>();  // integers convert too
    if (!value || !std::isfinite(*value)) {
      Fail(source_, *node, name_ + ": '" + std::string(key) + "' must be a finite number");
    }
    return value;
  }
  /// A scale that must be > 0: the direction is `reverse`'s, so a negative one is refused.
  [[nodiscard]] std::optional<double> Scale(std::string_view key) const {
    const std::optional<double> value = Number(key);
    if (value && *value < 0.0) {
      Fail(source_, *table_.get(key), name_ + ": " + std::string(key) + " " + Num(*value) +
                                          " is negative: give its size and reverse = true (the "
                                          "direction pin then means the other way)");
    }
    return value;
  }
  [[nodiscard]] double Positive(std::string_view key) const {
    const std::optional<double> value = Number(key);
    if (value && *value <= 0.0) {
      Fail(source_, *table_.get(key), name_ + ": '" + std::string(key) + "' = " + Num(*value) +
                                          " must be > 0");
    }
    return value.value_or(0.0);
  }
  [[nodiscard]] bool Flag(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (node == nullptr) return false;
    const std::optional<bool> value = node->value<bool>();
    if (!value) Fail(source_, *node, name_ + ": '" + std::string(key) + "' must be true or false");
    return *value;
  }
  /// Line and column of `key`'s value (the table's when it is missing), for later messages.
  [[nodiscard]] std::pair<int, int> Place(std::string_view key) const {
    const toml::node* node = table_.get(key);
    const toml::source_position at = (node != nullptr ? node->source() : table_.source()).begin;
    return {static_cast<int>(at.line), static_cast<int>(at.column)};
  }
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::string_view source_;
  const toml::table& table_;
  std::string name_;
};

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

PwmRoute ParsePwm(std::string_view source, const toml::table& table, std::size_t index) {
  CheckKeys(source, table, "[[pwm]]", {"channel", "input", "gain", "reverse"});
  const Entry e(source, table, "[[pwm]] #" + std::to_string(index + 1));
  PwmRoute route;
  route.channel = e.Channel();
  route.input = e.String("input", true);
  route.gain = e.Scale("gain").value_or(1.0);
  if (route.gain == 0.0) {
    Fail(source, *table.get("gain"), e.name() + ": gain 0 would disconnect the input; remove "
                                                "the entry and give the input a value in [inputs]");
  }
  route.reverse = e.Flag("reverse");
  std::tie(route.line, route.col) = e.Place("input");
  return route;
}

/// A scale the board can follow: at most kMaxCountsPerUnit. `at` is the key that set it last.
double CheckRepresentable(std::string_view source, const toml::node& at, const Entry& e,
                          const std::string& unit, double counts_per_unit) {
  if (!(counts_per_unit > 0.0)) {  // keys far below 1 multiplied to nothing
    Fail(source, at, e.name() + ": the scale comes to 0 counts per " + unit +
                         ": check the scale's keys and their units");
  }
  if (counts_per_unit <= kMaxCountsPerUnit) return counts_per_unit;
  Fail(source, at,
       e.name() + ": " + Num(counts_per_unit) + " counts per " + unit + " is more than " +
           Num(kMaxCountsPerUnit) + ", the most counts the board emits in a second (" +
           Num(static_cast<double>(io::kFpgaClockHz) / 1e6) + " MHz over its smallest clock "
           "divider, " + std::to_string(io::kMinClockDivider) +
           "): it could not follow the output moving one " + unit +
           " per second; check the scale's keys and their units");
}

/// counts per unit of the output: given directly, or from the encoder on a geared shaft.
double EncoderScale(std::string_view source, const toml::table& table, const Entry& e,
                    const std::string& unit) {
  const std::optional<double> direct = e.Scale("counts_per_unit");
  const double per_rev = e.Positive("counts_per_rev");
  if (direct && per_rev > 0.0) {
    Fail(source, *table.get("counts_per_rev"),
         e.name() + " gives both counts_per_unit and counts_per_rev: keep one");
  }
  if (direct) {
    const toml::node& at = *table.get("counts_per_unit");
    if (*direct == 0.0) Fail(source, at, e.name() + ": 0 counts per unit");
    return CheckRepresentable(source, at, e, unit, *direct);
  }
  if (per_rev == 0.0) {
    Fail(source, table, e.name() + " has no scale: give counts_per_unit, or counts_per_rev "
                                   "(with gear_ratio, and wheel_radius_m when unit = \"m\")");
  }
  const double ratio = table.contains("gear_ratio") ? e.Positive("gear_ratio") : 1.0;
  // Output radians turn the encoder's shaft `ratio` times as far; metres are radians times r.
  const double per_rad = per_rev * ratio / (2.0 * std::numbers::pi);
  const toml::node& shaft =
      *table.get(table.contains("gear_ratio") ? "gear_ratio" : "counts_per_rev");
  if (unit == "rad") return CheckRepresentable(source, shaft, e, unit, per_rad);
  const double radius_m = e.Positive("wheel_radius_m");
  if (radius_m == 0.0) {
    Fail(source, table, e.name() + ": unit \"m\" with counts_per_rev needs wheel_radius_m");
  }
  return CheckRepresentable(source, *table.get("wheel_radius_m"), e, unit, per_rad / radius_m);
}

EncoderRoute ParseEncoder(std::string_view source, const toml::table& table, std::size_t index) {
  CheckKeys(source, table, "[[encoder]]",
            {"channel", "output", "unit", "counts_per_unit", "counts_per_rev", "gear_ratio",
             "wheel_radius_m", "reverse", "column", "joint"});
  const Entry e(source, table, "[[encoder]] #" + std::to_string(index + 1));
  EncoderRoute route;
  route.channel = e.Channel();
  route.output = e.String("output", true);
  route.unit = e.String("unit", true);
  if (route.unit != "m" && route.unit != "rad") {
    Fail(source, *table.get("unit"), e.name() + ": unit \"" + route.unit +
                                         "\" is not one an encoder measures: \"m\" or \"rad\"");
  }
  route.counts_per_unit = EncoderScale(source, table, e, route.unit);
  route.reverse = e.Flag("reverse");
  route.column = e.String("column", false);
  if (route.column.empty()) route.column = "enc" + std::to_string(route.channel);
  route.joint = e.String("joint", false);
  route.wheel_radius_m = e.Positive("wheel_radius_m");
  std::tie(route.line, route.col) = e.Place("output");
  return route;
}

void ParseInputs(std::string_view source, const toml::table& root, PlantMap& map) {
  const toml::node* node = root.get("inputs");
  if (node == nullptr) return;
  const toml::table* table = node->as_table();
  if (table == nullptr) Fail(source, *node, "[inputs] must be a table of name = value");
  for (const auto& [key, value] : *table) {
    const std::optional<double> number = value.value<double>();
    if (!number || !std::isfinite(*number)) {
      Fail(source, value, "[inputs] " + std::string(key.str()) + " must be a finite number");
    }
    const toml::source_position at = value.source().begin;
    map.constant_inputs.push_back({std::string(key.str()), *number, static_cast<int>(at.line),
                                   static_cast<int>(at.column)});
  }
}

void ParseTelemetry(std::string_view source, const toml::table& root, PlantMap& map) {
  const toml::node* node = root.get("telemetry");
  if (node == nullptr) return;
  const toml::table* table = node->as_table();
  if (table == nullptr) Fail(source, *node, "[telemetry] must be a table");
  CheckKeys(source, *table, "[telemetry]", {"pose"});
  const toml::node* pose = table->get("pose");
  if (pose == nullptr) return;
  const toml::array* names = pose->as_array();
  if (names == nullptr || names->size() != 3) {
    Fail(source, *pose, "[telemetry] pose must name three outputs: [\"x\", \"y\", \"heading\"]");
  }
  std::array<std::string, 3> outputs;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::optional<std::string> name = (*names)[i].value<std::string>();
    if (!name) Fail(source, *pose, "[telemetry] pose entries must be output names (strings)");
    outputs[i] = *name;
  }
  map.pose = outputs;
}

/// One PWM channel drives one input; one encoder channel follows one output. `tables` are the
/// routes' own, for the place of the second `channel`.
template <class Route>
void CheckChannelsOnce(std::string_view source, const toml::array* tables,
                       const std::vector<Route>& routes, std::string_view what) {
  std::set<int> seen;
  for (std::size_t i = 0; i < routes.size(); ++i) {
    if (seen.insert(routes[i].channel).second) continue;
    Fail(source, *(*tables)[i].as_table()->get("channel"),
         std::string(what) + " channel " + std::to_string(routes[i].channel) +
             " is mapped twice: a channel carries one signal");
  }
}

}  // namespace

PlantMap ParsePlantMap(std::string_view toml_text, std::string_view source_name) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& e) {
    throw PlantMapError(Where(source_name, e.source()) + ": not valid TOML: " +
                        std::string(e.description()));
  }
  CheckKeys(source_name, root, "the plant map", {"pwm", "encoder", "inputs", "telemetry"});
  PlantMap map;
  map.source = std::string(source_name);
  const toml::array* pwm = ArrayOfTables(source_name, root, "pwm");
  for (std::size_t i = 0; pwm != nullptr && i < pwm->size(); ++i) {
    map.pwm.push_back(ParsePwm(source_name, *(*pwm)[i].as_table(), i));
  }
  const toml::array* encoders = ArrayOfTables(source_name, root, "encoder");
  for (std::size_t i = 0; encoders != nullptr && i < encoders->size(); ++i) {
    map.encoders.push_back(ParseEncoder(source_name, *(*encoders)[i].as_table(), i));
  }
  CheckChannelsOnce(source_name, pwm, map.pwm, "PWM");
  CheckChannelsOnce(source_name, encoders, map.encoders, "encoder");
  ParseInputs(source_name, root, map);
  ParseTelemetry(source_name, root, map);
  return map;
}

PlantMap LoadPlantMap(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    char buffer[256];
    const std::string why = strerror_r(errno, buffer, sizeof buffer);
    throw PlantMapError("cannot read the plant map " + path.string() + ": " + why +
                        "; give an existing TOML file to --plant-map (docs/plants.md)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParsePlantMap(text.str(), path.string());
}

}  // namespace hiltwin::plant
