// A controller map checked against one controller's ports (controller_map.h,
// BindControllerMap).
#include <optional>
#include <string>

#include "hiltwin/controller/controller_map.h"
#include "hiltwin/plant/map_toml.h"

namespace hiltwin::controller {
namespace {

using plant::map_toml::PortIndex;
using plant::map_toml::PortNames;

/// Says where in the map and which controller, then what.
class ControllerBinder {
 public:
  ControllerBinder(const ControllerMap& map, const Controller& controller)
      : map_(map), info_(controller.Info()) {}

  /// `line` 0: nowhere in particular (the map as a whole).
  [[noreturn]] void Fail(int line, int col, const std::string& what) const {
    std::string where = map_.source;
    if (line > 0) where += ":" + std::to_string(line);
    if (line > 0 && col > 0) where += ":" + std::to_string(col);
    // The spec says which file (two libraries may share a descriptor name); the name, which
    // code.
    const std::string which =
        info_.spec.empty() || info_.spec == info_.name ? info_.name
                                                       : info_.spec + " '" + info_.name + "'";
    throw ControllerMapError(where + ": " + what + " (controller " + which + ")");
  }

  /// An input by name, in `unit` when `unit` is not empty and the port says its unit.
  std::size_t Input(const std::string& name, const std::string& unit, int line, int col,
                    const std::string& what) const {
    const auto i = PortIndex(info_.inputs, name);
    if (!i && PortIndex(info_.outputs, name)) {
      Fail(line, col, what + " '" + name + "' is an output of the controller; only inputs can "
                                           "be fed (inputs: " + PortNames(info_.inputs) + ")");
    }
    if (!i) {
      Fail(line, col, what + " '" + name + "' is not a port of the controller (inputs: " +
                          PortNames(info_.inputs) + ")");
    }
    CheckUnit(info_.inputs[*i], unit, line, col, what);
    return *i;
  }

  std::size_t Output(const std::string& name, int line, int col) const {
    const auto i = PortIndex(info_.outputs, name);
    if (!i && PortIndex(info_.inputs, name)) {
      Fail(line, col, "PWM output '" + name + "' is an input of the controller; only outputs "
                      "can drive a motor (outputs: " + PortNames(info_.outputs) + ")");
    }
    if (!i) {
      Fail(line, col, "PWM output '" + name + "' is not a port of the controller (outputs: " +
                          PortNames(info_.outputs) + ")");
    }
    CheckUnit(info_.outputs[*i], "1", line, col, "PWM output");
    return *i;
  }

  [[nodiscard]] const ControllerInfo& info() const { return info_; }

 private:
  /// A port without a unit takes the map's; one with a unit must agree.
  void CheckUnit(const Port& port, const std::string& unit, int line, int col,
                 const std::string& what) const {
    if (unit.empty() || port.unit.empty() || port.unit == unit) return;
    Fail(line, col, what + " '" + port.name + "' is in " + port.unit + " but the map gives it " +
                        unit + ": make the units agree (the map's unit, or the controller's)");
  }

  const ControllerMap& map_;
  const ControllerInfo& info_;
};

void BindEncoders(const ControllerBinder& b, const ControllerMap& map, BoundControllerMap& out,
                  std::vector<bool>& fed) {
  for (const EncoderInput& r : map.encoders) {
    const std::size_t input = b.Input(r.input, r.unit, r.line, r.col, "encoder input");
    fed[input] = true;
    out.encoders.push_back({static_cast<std::size_t>(r.channel - 1), input,
                            r.reverse ? -r.counts_per_unit : r.counts_per_unit});
  }
}

void BindSetpoints(const ControllerBinder& b, const ControllerMap& map, BoundControllerMap& out,
                   std::vector<bool>& fed) {
  for (const SetpointInput& r : map.setpoints) {
    const std::size_t input = b.Input(r.input, "m", r.line, r.col, "setpoint input");
    fed[input] = true;
    BoundControllerMap::Setpoint s;
    s.column_index = r.column == "left_m" ? 0 : 1;
    s.input_index = input;
    s.on_encoder_grid = r.on_encoder_grid;
    for (std::size_t e = 0; e < map.encoders.size(); ++e) {
      if (!r.tracks.empty() && map.encoders[e].input == r.tracks) s.tracked_encoder = e;
    }
    out.setpoints.push_back(s);
  }
}

void BindConstants(const ControllerBinder& b, const ControllerMap& map, BoundControllerMap& out,
                   std::vector<bool>& fed) {
  for (const ConstantControllerInput& c : map.constant_inputs) {
    const std::size_t input = b.Input(c.name, "", c.line, c.col, "[inputs]");
    fed[input] = true;
    out.initial_inputs[input] = c.value;
  }
}

void BindPwm(const ControllerBinder& b, const ControllerMap& map, BoundControllerMap& out) {
  std::vector<bool> drives(b.info().outputs.size(), false);
  for (const PwmOutput& r : map.pwm) {
    const std::size_t output = b.Output(r.output, r.line, r.col);
    drives[output] = true;
    out.pwm.push_back({static_cast<std::size_t>(r.channel - 1), output,
                       r.reverse ? -r.gain : r.gain, r.duty_limit});
  }
  for (std::size_t i = 0; i < drives.size(); ++i) {
    if (drives[i]) continue;
    const std::string& name = b.info().outputs[i].name;
    b.Fail(0, 0, "controller output '" + name + "' drives no PWM channel: add a [[pwm]] entry "
                 "with output = \"" + name + "\" (a controller's every output must reach a "
                 "motor, or a result would silently lack it)");
  }
}

}  // namespace

BoundControllerMap BindControllerMap(const ControllerMap& map, const Controller& controller) {
  const ControllerBinder b(map, controller);
  const ControllerInfo& info = controller.Info();
  BoundControllerMap out;
  out.initial_inputs.assign(info.inputs.size(), 0.0);
  std::vector<bool> fed(info.inputs.size(), false);
  BindEncoders(b, map, out, fed);
  BindSetpoints(b, map, out, fed);
  BindConstants(b, map, out, fed);
  for (std::size_t i = 0; i < fed.size(); ++i) {
    if (fed[i]) continue;
    const std::string& name = info.inputs[i].name;
    b.Fail(0, 0, "controller input '" + name + "' is fed by nothing: add an [[encoder]] or "
                 "[[setpoint]] entry with input = \"" + name + "\", or hold it constant with '" +
                 name + " = 0.0' under [inputs]");
  }
  BindPwm(b, map, out);
  return out;
}

}  // namespace hiltwin::controller
