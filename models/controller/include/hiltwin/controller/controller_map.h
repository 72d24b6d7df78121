#pragma once
/// The I/O processing between the IcoBoard (ECS image) and a controller, as data: which
/// controller input each encoder channel feeds and how many counts a unit of it is, which
/// setpoint column feeds which input, which output drives which PWM channel with what gain,
/// direction and duty limit. Written in TOML (docs/controllers.md "Controller maps"); the ECS's
/// controller task applies it every cycle, so no controller has hand-written I/O code. The
/// mirror of the plant map (plant_map.h), with the same keys where the meaning is the same.
///
///   [[encoder]]                  # board encoder channel -> controller input
///   channel = 2                  # 1..4 (appendix G's channel2: the left wheel)
///   input = "wheel_left_m"       # the controller's input port
///   unit = "m"                   # "m" or "rad"; must agree with the controller's own unit
///   counts_per_unit = 12732.4    # or counts_per_rev + gear_ratio (+ wheel_radius_m for "m")
///   reverse = false              # true: the encoder counts the other way
///
///   [[setpoint]]                 # setpoint profile column -> controller input
///   column = "left_m"            # a column of --setpoint (time,left_m,right_m): left_m, right_m
///   input = "setpoint_left_m"
///   tracks = "wheel_left_m"      # optional: the encoder-fed input it is a setpoint for; the
///                                # report gives the tracking error of the pair
///   on_encoder_grid = true       # optional (needs tracks): rounded to that encoder's whole
///                                # counts, so error zero is reachable (the built-in PID's rule)
///
///   [[pwm]]                      # controller output -> board PWM channel
///   channel = 2
///   output = "duty_left"         # the controller's output port
///   gain = 1.0                   # duty per unit of the output; default 1
///   reverse = false              # true: the direction pin means the other way
///   duty_limit = 1.0             # |duty| beyond it stops the controller (safe outputs);
///                                # (0, 1], default 1
///
///   [inputs]                     # controller inputs nothing feeds, held constant
///   mass_kg = 1.2

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/controller/controller.h"

namespace hiltwin::controller {

/// A bad controller map, or one that does not fit its controller; the message says
/// file:line:column, what is wrong and what to write instead.
class ControllerMapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An encoder channel feeding a controller input: input = counts / counts_per_unit (negated
/// when reversed), counts since the first reading (the robot's encoders power up anywhere).
struct EncoderInput {
  int channel = 0;  ///< board channel, 1..4
  std::string input;
  std::string unit;  ///< "m" or "rad"
  double counts_per_unit = 0.0;
  bool reverse = false;
  int line = 0;  ///< where the map names the input (its `input` key); 0: nowhere
  int col = 0;
};

/// A setpoint column feeding a controller input (unit "m": the profile's columns are wheel
/// travel in metres).
struct SetpointInput {
  std::string column;  ///< "left_m" or "right_m"
  std::string input;
  std::string tracks;  ///< an EncoderInput's input, or ""
  bool on_encoder_grid = false;
  int line = 0;
  int col = 0;
};

/// A controller output driving a PWM channel: duty = gain * output (negated when reversed).
struct PwmOutput {
  int channel = 0;  ///< board channel, 1..4
  std::string output;
  double gain = 1.0;  ///< > 0; the direction is `reverse`
  bool reverse = false;
  double duty_limit = 1.0;  ///< in (0, 1]
  int line = 0;
  int col = 0;
};

/// A controller input nothing feeds, held at a constant ([inputs] name = value).
struct ConstantControllerInput {
  std::string name;
  double value = 0.0;
  int line = 0;
  int col = 0;
};

/// A parsed map, not yet checked against a controller.
struct ControllerMap {
  std::string source;  ///< the file, or "the built-in map of <controller>"
  std::vector<EncoderInput> encoders;
  std::vector<SetpointInput> setpoints;
  std::vector<PwmOutput> pwm;
  std::vector<ConstantControllerInput> constant_inputs;  ///< [inputs]
};

/// Parses a map. `source_name` names it in messages. Unknown tables and keys, a channel outside
/// 1..4, a channel used twice (per direction), an input fed twice, a non-finite, zero or
/// negative scale or gain, a duty limit outside (0, 1], an unknown unit or column are refused
/// with file:line:column of the key at fault (of the table when a key is missing).
[[nodiscard]] ControllerMap ParseControllerMap(std::string_view toml_text,
                                               std::string_view source_name);
/// Reads and parses a map file; an unreadable file is a ControllerMapError naming it.
[[nodiscard]] ControllerMap LoadControllerMap(const std::filesystem::path& path);

/// A map checked against one controller: names resolved to port indices, signs folded in.
struct BoundControllerMap {
  struct Encoder {
    std::size_t channel_index = 0;  ///< channel - 1
    std::size_t input_index = 0;
    double counts_per_unit = 0.0;  ///< reverse folded in
  };
  struct Setpoint {
    std::size_t column_index = 0;  ///< 0 left_m, 1 right_m
    std::size_t input_index = 0;
    std::optional<std::size_t> tracked_encoder;  ///< index into `encoders`
    bool on_encoder_grid = false;
  };
  struct Pwm {
    std::size_t channel_index = 0;
    std::size_t output_index = 0;
    double gain = 1.0;  ///< reverse folded in
    double duty_limit = 1.0;
  };
  std::vector<Encoder> encoders;
  std::vector<Setpoint> setpoints;
  std::vector<Pwm> pwm;
  /// Every controller input's value before the routes write theirs: the [inputs] constants,
  /// 0 for routed inputs.
  std::vector<double> initial_inputs;
};

/// Checks `map` against `controller`'s ports: every name exists with the right direction,
/// units agree, every controller input is fed (encoder, setpoint or [inputs]) and every output
/// drives a PWM channel. Throws ControllerMapError saying which entry, where, and what exists
/// instead.
[[nodiscard]] BoundControllerMap BindControllerMap(const ControllerMap& map,
                                                   const Controller& controller);

}  // namespace hiltwin::controller
