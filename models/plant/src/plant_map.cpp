// Plant maps (plant_map.h): parsed from TOML, then bound to one plant's ports.
#include "hiltwin/plant/plant_map.h"

#include <string>
#include <tuple>

#include "hiltwin/plant/map_toml.h"

namespace hiltwin::plant {
namespace {

using map_toml::CheckKeys;
using map_toml::Entry;
using map_toml::Fail;

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

EncoderRoute ParseEncoder(std::string_view source, const toml::table& table, std::size_t index) {
  CheckKeys(source, table, "[[encoder]]",
            {"channel", "output", "unit", "counts_per_unit", "counts_per_rev", "gear_ratio",
             "wheel_radius_m", "reverse", "column", "joint"});
  const Entry e(source, table, "[[encoder]] #" + std::to_string(index + 1));
  EncoderRoute route;
  route.channel = e.Channel();
  route.output = e.String("output", true);
  route.unit = e.EncoderUnit();
  route.counts_per_unit = e.EncoderScale(route.unit);
  route.reverse = e.Flag("reverse");
  route.column = e.String("column", false);
  if (route.column.empty()) route.column = "enc" + std::to_string(route.channel);
  route.joint = e.String("joint", false);
  route.wheel_radius_m = e.Positive("wheel_radius_m");
  std::tie(route.line, route.col) = e.Place("output");
  return route;
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

PlantMap ParseMap(std::string_view toml_text, std::string_view source_name) {
  const toml::table root = map_toml::ParseRoot(toml_text, source_name);
  CheckKeys(source_name, root, "the plant map", {"pwm", "encoder", "inputs", "telemetry"});
  PlantMap map;
  map.source = std::string(source_name);
  const toml::array* pwm = map_toml::ArrayOfTables(source_name, root, "pwm");
  for (std::size_t i = 0; pwm != nullptr && i < pwm->size(); ++i) {
    map.pwm.push_back(ParsePwm(source_name, *(*pwm)[i].as_table(), i));
  }
  const toml::array* encoders = map_toml::ArrayOfTables(source_name, root, "encoder");
  for (std::size_t i = 0; encoders != nullptr && i < encoders->size(); ++i) {
    map.encoders.push_back(ParseEncoder(source_name, *(*encoders)[i].as_table(), i));
  }
  map_toml::CheckChannelsOnce(source_name, pwm, map.pwm, "PWM");
  map_toml::CheckChannelsOnce(source_name, encoders, map.encoders, "encoder");
  map.constant_inputs = map_toml::ParseConstants(source_name, root);
  ParseTelemetry(source_name, root, map);
  return map;
}

}  // namespace

PlantMap ParsePlantMap(std::string_view toml_text, std::string_view source_name) {
  return map_toml::Rethrown<PlantMapError>([&] { return ParseMap(toml_text, source_name); });
}

PlantMap LoadPlantMap(const std::filesystem::path& path) {
  const std::string text = map_toml::Rethrown<PlantMapError>([&] {
    return map_toml::ReadMapFile(path, "plant map",
                                 "give an existing TOML file to --plant-map (docs/plants.md)");
  });
  return ParsePlantMap(text, path.string());
}

}  // namespace hiltwin::plant
