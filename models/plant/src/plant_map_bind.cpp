// A plant map checked against one plant's ports (plant_map.h, BindPlantMap).
#include <optional>
#include <set>

#include "hiltwin/plant/map_toml.h"
#include "hiltwin/plant/plant_map.h"

namespace hiltwin::plant {
namespace {

using map_toml::PortIndex;
using map_toml::PortNames;

/// A line and column in the map.
struct Place {
  int line = 0;
  int column = 0;
};

/// Says where in the map and which plant, then what.
class Binder {
 public:
  Binder(const PlantMap& map, const Plant& plant) : map_(map), plant_(plant) {}

  /// `at` is where the map names what is at fault (line 0: nowhere, the map as a whole).
  [[noreturn]] void Fail(Place at, const std::string& what) const {
    std::string where = map_.source;
    if (at.line > 0) where += ":" + std::to_string(at.line);
    if (at.line > 0 && at.column > 0) where += ":" + std::to_string(at.column);
    throw PlantMapError(where + ": " + what + " (plant " + plant_.Info().name + ")");
  }

  /// An input by name; a name that is an output or something else gets its own message.
  std::size_t Input(const std::string& name, Place at, const char* what) const {
    const PlantInfo& info = plant_.Info();
    if (const auto i = PortIndex(info.inputs, name)) return *i;
    if (PortIndex(info.outputs, name)) {
      Fail(at, what + std::string(" '") + name +
                   "' is an output of the plant; only inputs can be driven (inputs: " +
                   PortNames(info.inputs) + ")");
    }
    Unknown(name, at, what, "inputs", info.inputs);
  }

  std::size_t Output(const std::string& name, Place at, const char* what) const {
    const PlantInfo& info = plant_.Info();
    if (const auto i = PortIndex(info.outputs, name)) return *i;
    if (PortIndex(info.inputs, name)) {
      Fail(at, what + std::string(" '") + name +
                   "' is an input of the plant; only outputs can be followed (outputs: " +
                   PortNames(info.outputs) + ")");
    }
    Unknown(name, at, what, "outputs", info.outputs);
  }

 private:
  [[noreturn]] void Unknown(const std::string& name, Place at, const char* what,
                            const char* kind, const std::vector<Port>& ports) const {
    const std::string known = plant_.ExplainNonPort(name);
    Fail(at, what + std::string(" '") + name + "' " +
                 (known.empty() ? "is not a port of the plant" : known) + " (" + kind + ": " +
                 PortNames(ports) + ")");
  }

  const PlantMap& map_;
  const Plant& plant_;
};

void BindPwm(const Binder& b, const PlantMap& map, BoundPlantMap& out, std::vector<bool>& driven) {
  for (const PwmRoute& route : map.pwm) {
    const Place at{route.line, route.col};
    const std::size_t input = b.Input(route.input, at, "PWM channel input");
    if (driven[input]) b.Fail(at, "input '" + route.input + "' is driven by two PWM channels");
    driven[input] = true;
    out.pwm.push_back({static_cast<std::size_t>(route.channel - 1), input,
                       route.reverse ? -route.gain : route.gain});
  }
}

void BindEncoder(const Binder& b, const Plant& plant, const EncoderRoute& route,
                 BoundPlantMap& out) {
  const Place at{route.line, route.col};
  const std::size_t output = b.Output(route.output, at, "encoder output");
  const std::string& unit = plant.Info().outputs[output].unit;
  if (!unit.empty() && unit != route.unit) {
    b.Fail(at, "encoder output '" + route.output + "' is in " + unit +
                           " but the map says unit = \"" + route.unit +
                           "\": an encoder counts metres of travel or radians of rotation");
  }
  out.encoders.push_back({static_cast<std::size_t>(route.channel - 1), output,
                          route.reverse ? -route.counts_per_unit : route.counts_per_unit});
  out.encoder_columns.push_back(route.column);
  if (route.joint.empty()) return;
  const double r = route.wheel_radius_m;
  BoundPlantMap::Joint joint{output, 0.0, 0.0};
  if (route.unit == "rad") {
    joint.to_rad = 1.0;
    joint.to_m = r;  // 0 without a radius: travel unknown
  } else {
    joint.to_m = 1.0;
    joint.to_rad = r > 0.0 ? 1.0 / r : 0.0;
  }
  out.joints.push_back(joint);
  out.joint_names.push_back(route.joint);
}

void BindConstants(const Binder& b, const PlantMap& map, BoundPlantMap& out,
                   std::vector<bool>& driven) {
  for (const ConstantInput& constant : map.constant_inputs) {
    const Place at{constant.line, constant.col};
    const std::size_t input = b.Input(constant.name, at, "[inputs]");
    if (driven[input]) {
      b.Fail(at, "[inputs] gives '" + constant.name +
                     "' a value but a PWM channel drives it: keep one");
    }
    driven[input] = true;
    out.initial_inputs[input] = constant.value;
  }
}

void CheckEveryInputSet(const Binder& b, const Plant& plant, const std::vector<bool>& driven) {
  const std::vector<Port>& inputs = plant.Info().inputs;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (driven[i]) continue;
    b.Fail({}, "plant input '" + inputs[i].name +
                  "' is driven by no PWM channel and has no value: add a [[pwm]] entry for it, "
                  "or hold it constant with '" + inputs[i].name + " = 0.0' under [inputs]");
  }
}

void CheckColumnsUnique(const Binder& b, const Plant& plant, const BoundPlantMap& out) {
  std::set<std::string> columns;
  for (const Port& port : plant.Info().inputs) columns.insert(port.name);
  for (const Port& port : plant.Info().outputs) columns.insert(port.name);
  for (const std::string& column : out.encoder_columns) {
    if (!columns.insert(column).second) {
      b.Fail({}, "log column '" + column + "' appears twice: give the encoder another column");
    }
  }
}

}  // namespace

BoundPlantMap BindPlantMap(const PlantMap& map, const Plant& plant) {
  const Binder b(map, plant);
  const PlantInfo& info = plant.Info();
  BoundPlantMap out;
  out.initial_inputs.assign(info.inputs.size(), 0.0);
  std::vector<bool> driven(info.inputs.size(), false);
  BindPwm(b, map, out, driven);
  BindConstants(b, map, out, driven);
  CheckEveryInputSet(b, plant, driven);
  for (const EncoderRoute& route : map.encoders) BindEncoder(b, plant, route, out);
  if (map.pose) {
    std::array<std::size_t, 3> pose{};
    for (std::size_t i = 0; i < 3; ++i) pose[i] = b.Output((*map.pose)[i], {}, "[telemetry] pose");
    out.pose = pose;
  }
  CheckColumnsUnique(b, plant, out);
  return out;
}

}  // namespace hiltwin::plant
