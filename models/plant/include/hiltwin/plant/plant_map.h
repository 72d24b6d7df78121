#pragma once
/// The I/O processing between the IcoBoard and a plant, as data (thesis appendix B §4 and
/// appendix G): which plant input each PWM channel drives and with what gain and direction,
/// which plant output each encoder channel follows and how many counts a unit of it is.
/// Written in TOML (docs/plants.md "Plant maps"); the twin task applies it every cycle, so no
/// plant has hand-written I/O code.
///
///   [[pwm]]                      # board PWM channel -> plant input
///   channel = 2                  # 1..4 (appendix G's channel2)
///   input = "duty_left"          # the plant's input port
///   gain = 1.0                   # input per unit of duty (PWM value / 2048); default 1
///   reverse = false              # true: the direction pin means the other way
///
///   [[encoder]]                  # plant output -> board encoder channel
///   channel = 2
///   output = "wheel_left_m"
///   unit = "m"                   # "m" or "rad"; must agree with the plant's own unit
///   counts_per_unit = 12732.4    # or counts_per_rev + gear_ratio (+ wheel_radius_m for "m")
///   column = "enc_left"          # log column of the counts; default "enc<channel>"
///   joint = "wheel_left_joint"   # optional: published as this telemetry joint
///
///   [inputs]                     # plant inputs no PWM channel drives, held constant
///   load_n = 0.0
///
///   [telemetry]
///   pose = ["x_m", "y_m", "theta_rad"]   # optional: outputs published as the planar pose

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/plant/plant.h"

namespace hiltwin::plant {

/// A bad plant map; the message says file:line, what is wrong and what to write instead.
class PlantMapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The largest encoder scale a map may give, in counts per unit of the output (m or rad): the
/// most counts the board's encoder emulator emits in a second, 100 MHz over its smallest clock
/// divider (4), 25 M (docs/spi-protocol.md, "Pulse-rate limit"). At a larger scale the board
/// could not follow the output moving even one unit per second.
constexpr double kMaxCountsPerUnit =
    static_cast<double>(io::kFpgaClockHz) / static_cast<double>(io::kMinClockDivider);

/// A PWM channel driving a plant input: u[input] = gain * duty (negated when reversed).
struct PwmRoute {
  int channel = 0;  ///< board channel, 1..4
  std::string input;
  double gain = 1.0;  ///< > 0; the direction is `reverse`
  bool reverse = false;
  int line = 0;  ///< where the map names the input (its `input` key), for messages; 0: nowhere
  int col = 0;
};

/// An encoder channel following a plant output: counts = floor(y * counts_per_unit) (negated
/// when reversed).
struct EncoderRoute {
  int channel = 0;  ///< board channel, 1..4
  std::string output;
  std::string unit;  ///< "m" or "rad"
  double counts_per_unit = 0.0;
  bool reverse = false;
  std::string column;  ///< log column of the counts
  std::string joint;   ///< telemetry joint name; "" = not published
  /// Radius that turns the output into a wheel angle or travel for telemetry (0: unknown).
  double wheel_radius_m = 0.0;
  int line = 0;  ///< where the map names the output (its `output` key); 0: nowhere
  int col = 0;
};

/// A plant input no PWM channel drives, held at a constant ([inputs] name = value).
struct ConstantInput {
  std::string name;
  double value = 0.0;
  int line = 0;  ///< where in the map, for messages
  int col = 0;
};

/// A parsed map, not yet checked against a plant.
struct PlantMap {
  std::string source;  ///< the file, or "the built-in map of <plant>"
  std::vector<PwmRoute> pwm;
  std::vector<EncoderRoute> encoders;
  std::vector<ConstantInput> constant_inputs;                   ///< [inputs]
  std::optional<std::array<std::string, 3>> pose;               ///< [telemetry] pose: x, y, theta
};

/// Parses a map. `source_name` names it in messages. Unknown keys, a channel outside 1..4, a
/// channel used twice, a non-finite, zero or negative scale, an encoder scale above
/// kMaxCountsPerUnit, an encoder without a scale or with two, an unknown unit are refused with
/// file:line:column of the key at fault (of the table when a key is missing).
[[nodiscard]] PlantMap ParsePlantMap(std::string_view toml_text, std::string_view source_name);
/// Reads and parses a map file; an unreadable file is a PlantMapError naming it.
[[nodiscard]] PlantMap LoadPlantMap(const std::filesystem::path& path);

/// A map checked against one plant: names resolved to port indices, signs folded into gains.
struct BoundPlantMap {
  struct Pwm {
    std::size_t channel_index = 0;  ///< channel - 1
    std::size_t input_index = 0;
    double gain = 1.0;  ///< reverse folded in
  };
  struct Encoder {
    std::size_t channel_index = 0;
    std::size_t output_index = 0;
    double counts_per_unit = 0.0;  ///< reverse folded in
  };
  struct Joint {
    std::size_t output_index = 0;
    double to_rad = 0.0;  ///< output -> joint angle (1 for "rad"; 1/r for "m" with a radius)
    double to_m = 0.0;    ///< output -> wheel travel (1 for "m"; r for "rad" with a radius)
  };
  std::vector<Pwm> pwm;
  std::vector<Encoder> encoders;
  std::vector<std::string> encoder_columns;  ///< one per encoder route
  /// Every plant input's value before the PWM routes write theirs: the [inputs] constants,
  /// 0 for PWM-driven inputs.
  std::vector<double> initial_inputs;
  std::optional<std::array<std::size_t, 3>> pose;  ///< output indices of x, y, theta
  std::vector<Joint> joints;
  std::vector<std::string> joint_names;
};

/// Checks `map` against `plant`'s ports: every name exists with the right causality (an
/// output cannot be driven, an input cannot be followed), units agree, every plant input is
/// driven by a PWM channel or given a constant in [inputs], log columns are unique. Throws
/// PlantMapError saying which entry, where (the line and column of the name at fault), and
/// what exists instead.
[[nodiscard]] BoundPlantMap BindPlantMap(const PlantMap& map, const Plant& plant);

}  // namespace hiltwin::plant
