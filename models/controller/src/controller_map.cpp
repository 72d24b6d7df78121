// Controller maps (controller_map.h): parsed from TOML with the plant map's helpers
// (plant/map_toml.h), then checked for what the map alone can tell: channels, names fed twice,
// setpoint columns and what they track.
#include "hiltwin/controller/controller_map.h"

#include <array>
#include <map>
#include <string>
#include <tuple>

#include "hiltwin/plant/map_toml.h"

namespace hiltwin::controller {
namespace {

namespace mt = plant::map_toml;

/// The setpoint profile's columns (SetpointInput::column); BoundControllerMap's column_index.
constexpr std::array<std::string_view, 2> kColumns = {"left_m", "right_m"};

EncoderInput ParseEncoderInput(std::string_view source, const toml::table& table,
                               std::size_t index) {
  mt::CheckKeys(source, table, "[[encoder]]",
                {"channel", "input", "unit", "counts_per_unit", "counts_per_rev", "gear_ratio",
                 "wheel_radius_m", "reverse"});
  const mt::Entry e(source, table, "[[encoder]] #" + std::to_string(index + 1));
  EncoderInput route;
  route.channel = e.Channel();
  route.input = e.String("input", true);
  route.unit = e.EncoderUnit();
  route.counts_per_unit = e.EncoderScale(route.unit);
  route.reverse = e.Flag("reverse");
  std::tie(route.line, route.col) = e.Place("input");
  return route;
}

SetpointInput ParseSetpointInput(std::string_view source, const toml::table& table,
                                 std::size_t index) {
  mt::CheckKeys(source, table, "[[setpoint]]", {"column", "input", "tracks", "on_encoder_grid"});
  const mt::Entry e(source, table, "[[setpoint]] #" + std::to_string(index + 1));
  SetpointInput route;
  route.column = e.String("column", true);
  bool known = false;
  for (const std::string_view column : kColumns) known = known || column == route.column;
  if (!known) {
    e.Fail("column", e.name() + ": column \"" + route.column +
                         "\" is not a column of the setpoint profile (time,left_m,right_m): "
                         "\"left_m\" or \"right_m\"");
  }
  route.input = e.String("input", true);
  route.tracks = e.String("tracks", false);
  route.on_encoder_grid = e.Flag("on_encoder_grid");
  if (route.on_encoder_grid && route.tracks.empty()) {
    e.Fail("on_encoder_grid", e.name() + ": on_encoder_grid = true rounds the setpoint to the "
                                         "counts of the encoder it tracks: add tracks = \"<the "
                                         "encoder-fed input>\", or remove on_encoder_grid");
  }
  std::tie(route.line, route.col) = e.Place("input");
  return route;
}

PwmOutput ParsePwmOutput(std::string_view source, const toml::table& table, std::size_t index) {
  mt::CheckKeys(source, table, "[[pwm]]",
                {"channel", "output", "gain", "reverse", "duty_limit"});
  const mt::Entry e(source, table, "[[pwm]] #" + std::to_string(index + 1));
  PwmOutput route;
  route.channel = e.Channel();
  route.output = e.String("output", true);
  route.gain = e.Scale("gain").value_or(1.0);
  if (route.gain == 0.0) {
    e.Fail("gain", e.name() + ": gain 0 would leave the motor off whatever the controller "
                              "says: give the duty per unit of the output (default 1)");
  }
  route.reverse = e.Flag("reverse");
  route.duty_limit = e.Number("duty_limit").value_or(1.0);
  if (!(route.duty_limit > 0.0 && route.duty_limit <= 1.0)) {
    e.Fail("duty_limit", e.name() + ": duty_limit " + mt::Num(route.duty_limit) +
                             " is outside (0, 1]: a duty is a fraction of the supply voltage");
  }
  std::tie(route.line, route.col) = e.Place("output");
  return route;
}

/// Every input is fed once: by an encoder, a setpoint column or an [inputs] constant.
void CheckFedOnce(std::string_view source, const ControllerMap& map) {
  std::map<std::string, std::string> fed;  // input -> what feeds it
  const auto feed = [&](const std::string& input, int line, int col, const std::string& by) {
    const auto [it, fresh] = fed.emplace(input, by);
    if (fresh) return;
    throw mt::MapTomlError(mt::Where(source, line, col) + ": input '" + input + "' is fed by " +
                           it->second + " and by " + by + ": an input has one source, keep one");
  };
  for (const EncoderInput& r : map.encoders) {
    feed(r.input, r.line, r.col, "encoder channel " + std::to_string(r.channel));
  }
  for (const SetpointInput& r : map.setpoints) {
    feed(r.input, r.line, r.col, "setpoint column " + r.column);
  }
  for (const ConstantControllerInput& c : map.constant_inputs) {
    feed(c.name, c.line, c.col, "[inputs]");
  }
}

/// `tracks` names an input an encoder feeds, in metres as the setpoint columns are.
void CheckTracks(std::string_view source, const ControllerMap& map) {
  for (const SetpointInput& r : map.setpoints) {
    if (r.tracks.empty()) continue;
    const EncoderInput* tracked = nullptr;
    for (const EncoderInput& encoder : map.encoders) {
      if (encoder.input == r.tracks) tracked = &encoder;
    }
    std::string encoder_inputs;
    for (const EncoderInput& encoder : map.encoders) {
      encoder_inputs += (encoder_inputs.empty() ? "" : ", ") + encoder.input;
    }
    if (tracked == nullptr) {
      throw mt::MapTomlError(
          mt::Where(source, r.line, r.col) + ": setpoint column " + r.column + " tracks '" +
          r.tracks + "', which no [[encoder]] feeds (encoder inputs: " +
          (encoder_inputs.empty() ? "none" : encoder_inputs) +
          "): name the input the setpoint is for, or remove tracks");
    }
    if (tracked->unit != "m") {
      throw mt::MapTomlError(mt::Where(source, r.line, r.col) + ": setpoint column " + r.column +
                             " is in metres but tracks '" + r.tracks + "', an encoder in " +
                             tracked->unit + ": track an encoder with unit = \"m\"");
    }
  }
}

template <class Route, class ParseOne>
std::vector<Route> ParseTables(std::string_view source, const toml::array* tables,
                               ParseOne parse_one) {
  std::vector<Route> out;
  for (std::size_t i = 0; tables != nullptr && i < tables->size(); ++i) {
    out.push_back(parse_one(source, *(*tables)[i].as_table(), i));
  }
  return out;
}

ControllerMap ParseMapText(std::string_view toml_text, std::string_view source) {
  const toml::table root = mt::ParseRoot(toml_text, source);
  mt::CheckKeys(source, root, "the controller map", {"encoder", "setpoint", "pwm", "inputs"});
  ControllerMap map;
  map.source = std::string(source);
  const toml::array* encoders = mt::ArrayOfTables(source, root, "encoder");
  const toml::array* setpoints = mt::ArrayOfTables(source, root, "setpoint");
  const toml::array* pwm = mt::ArrayOfTables(source, root, "pwm");
  map.encoders = ParseTables<EncoderInput>(source, encoders, ParseEncoderInput);
  map.setpoints = ParseTables<SetpointInput>(source, setpoints, ParseSetpointInput);
  map.pwm = ParseTables<PwmOutput>(source, pwm, ParsePwmOutput);
  mt::CheckChannelsOnce(source, encoders, map.encoders, "encoder");
  mt::CheckChannelsOnce(source, pwm, map.pwm, "PWM");
  for (const plant::ConstantInput& c : mt::ParseConstants(source, root)) {
    map.constant_inputs.push_back({c.name, c.value, c.line, c.col});
  }
  CheckFedOnce(source, map);
  CheckTracks(source, map);
  return map;
}

}  // namespace

ControllerMap ParseControllerMap(std::string_view toml_text, std::string_view source_name) {
  return mt::Rethrown<ControllerMapError>([&] { return ParseMapText(toml_text, source_name); });
}

ControllerMap LoadControllerMap(const std::filesystem::path& path) {
  const std::string text = mt::Rethrown<ControllerMapError>([&] {
    return mt::ReadMapFile(path, "controller map",
                           "give an existing TOML file to --controller-map (docs/controllers.md)");
  });
  return ParseControllerMap(text, path.string());
}

}  // namespace hiltwin::controller
