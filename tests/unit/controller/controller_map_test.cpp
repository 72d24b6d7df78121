// Controller maps: every refusal ParseControllerMap and BindControllerMap list, with its
// file:line:column and what to do, and a good map bound to indices.
#include "hiltwin/controller/controller_map.h"

#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "fakes/fake_controller.h"

namespace hiltwin::controller {
namespace {

using test::FakeController;

/// The RELbot's wiring, as a file would give it: the base the refusal tests change one line of.
constexpr const char* kGood = R"(
[[encoder]]
channel = 2
input = "wheel_left_m"
unit = "m"
counts_per_rev = 64
gear_ratio = 50
wheel_radius_m = 0.04

[[encoder]]
channel = 1
input = "wheel_right_m"
unit = "m"
counts_per_unit = 12732.4
reverse = true

[[setpoint]]
column = "left_m"
input = "setpoint_left_m"
tracks = "wheel_left_m"
on_encoder_grid = true

[[setpoint]]
column = "right_m"
input = "setpoint_right_m"

[[pwm]]
channel = 2
output = "duty_left"

[[pwm]]
channel = 1
output = "duty_right"
gain = 0.5
reverse = true
duty_limit = 0.8
)";

/// The message ParseControllerMap throws for `text` ("" when it parses).
std::string ParseError(const std::string& text) {
  try {
    static_cast<void>(ParseControllerMap(text, "c.toml"));
  } catch (const ControllerMapError& e) {
    return e.what();
  }
  return "";
}

/// `kGood` with its first `from` replaced by `to`.
std::string Good(const std::string& from, const std::string& to) {
  std::string text = kGood;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

FakeController Relbot() {
  return {FakeController::RelbotInputs(), FakeController::RelbotOutputs()};
}

std::string BindError(const std::string& text, const FakeController& controller) {
  try {
    static_cast<void>(BindControllerMap(ParseControllerMap(text, "c.toml"), controller));
  } catch (const ControllerMapError& e) {
    return e.what();
  }
  return "";
}

TEST(ControllerMap, AGoodMapBindsToPortIndicesWithTheSignsFoldedIn) {
  const FakeController controller = Relbot();
  const BoundControllerMap bound = BindControllerMap(ParseControllerMap(kGood, "c.toml"),
                                                     controller);
  ASSERT_EQ(bound.encoders.size(), 2U);
  EXPECT_EQ(bound.encoders[0].channel_index, 1U);
  EXPECT_EQ(bound.encoders[0].input_index, 2U);
  // counts_per_rev · gear_ratio / (2π r): the same double as io::CountsPerMetre's.
  EXPECT_EQ(bound.encoders[0].counts_per_unit, 50.0 * 64.0 / (2.0 * std::numbers::pi * 0.04));
  EXPECT_EQ(bound.encoders[1].counts_per_unit, -12732.4);
  ASSERT_EQ(bound.setpoints.size(), 2U);
  EXPECT_EQ(bound.setpoints[0].column_index, 0U);
  EXPECT_EQ(bound.setpoints[0].input_index, 0U);
  EXPECT_EQ(bound.setpoints[0].tracked_encoder, 0U);
  EXPECT_TRUE(bound.setpoints[0].on_encoder_grid);
  EXPECT_EQ(bound.setpoints[1].column_index, 1U);
  EXPECT_FALSE(bound.setpoints[1].tracked_encoder.has_value());
  ASSERT_EQ(bound.pwm.size(), 2U);
  EXPECT_EQ(bound.pwm[1].channel_index, 0U);
  EXPECT_EQ(bound.pwm[1].output_index, 1U);
  EXPECT_EQ(bound.pwm[1].gain, -0.5);
  EXPECT_EQ(bound.pwm[1].duty_limit, 0.8);
  EXPECT_EQ(bound.pwm[0].duty_limit, 1.0);  // the default
  EXPECT_EQ(bound.initial_inputs, std::vector<double>(4, 0.0));
}

TEST(ControllerMap, AnUnknownTableIsRefusedAtItsKey) {
  EXPECT_EQ(ParseError("[[motor]]\nchannel = 1\n"),
            "c.toml:1:3: unknown key 'motor' in the controller map (known: encoder, setpoint, "
            "pwm, inputs)");
}

TEST(ControllerMap, AnUnknownKeyIsRefusedAtItsPlaceWithTheKnownOnes) {
  EXPECT_EQ(ParseError(Good("gain = 0.5", "gian = 0.5")),
            "c.toml:34:1: unknown key 'gian' in [[pwm]] (known: channel, output, gain, reverse, "
            "duty_limit)");
}

TEST(ControllerMap, AChannelOutsideOneToFourIsRefused) {
  EXPECT_EQ(ParseError(Good("channel = 2\ninput", "channel = 5\ninput")),
            "c.toml:3:11: [[encoder]] #1: channel must be an integer 1..4 (board channel n, as "
            "in thesis appendix G's channel1..channel4)");
}

TEST(ControllerMap, AChannelUsedTwicePerDirectionIsRefusedAtTheSecond) {
  EXPECT_EQ(ParseError(Good("channel = 1\noutput", "channel = 2\noutput")),
            "c.toml:32:11: PWM channel 2 is mapped twice: a channel carries one signal");
  // An encoder and a PWM route on one channel are two directions: allowed.
  EXPECT_EQ(ParseError(kGood), "");
}

TEST(ControllerMap, AnInputFedTwiceIsRefusedNamingBothSources) {
  EXPECT_EQ(ParseError(Good("input = \"setpoint_right_m\"", "input = \"wheel_left_m\"")),
            "c.toml:25:9: input 'wheel_left_m' is fed by encoder channel 2 and by setpoint "
            "column right_m: an input has one source, keep one");
  EXPECT_EQ(ParseError(std::string(kGood) + "\n[inputs]\nsetpoint_left_m = 0.1\n"),
            "c.toml:39:19: input 'setpoint_left_m' is fed by setpoint column left_m and by "
            "[inputs]: an input has one source, keep one");
}

TEST(ControllerMap, BadScalesGainsAndDutyLimitsAreRefused) {
  EXPECT_EQ(ParseError(Good("counts_per_unit = 12732.4", "counts_per_unit = -12732.4")),
            "c.toml:14:19: [[encoder]] #2: counts_per_unit -12732.4 is negative: give its size "
            "and reverse = true (the direction pin then means the other way)");
  EXPECT_EQ(ParseError(Good("counts_per_unit = 12732.4", "counts_per_unit = nan")),
            "c.toml:14:19: [[encoder]] #2: 'counts_per_unit' must be a finite number");
  EXPECT_EQ(ParseError(Good("gain = 0.5", "gain = 0")),
            "c.toml:34:8: [[pwm]] #2: gain 0 would leave the motor off whatever the controller "
            "says: give the duty per unit of the output (default 1)");
  EXPECT_EQ(ParseError(Good("duty_limit = 0.8", "duty_limit = 1.5")),
            "c.toml:36:14: [[pwm]] #2: duty_limit 1.5 is outside (0, 1]: a duty is a fraction "
            "of the supply voltage");
  EXPECT_EQ(ParseError(Good("duty_limit = 0.8", "duty_limit = 0")),
            "c.toml:36:14: [[pwm]] #2: duty_limit 0 is outside (0, 1]: a duty is a fraction "
            "of the supply voltage");
}

TEST(ControllerMap, AnEncoderWithoutAScaleOrUnitIsRefused) {
  EXPECT_EQ(ParseError(Good("counts_per_unit = 12732.4\n", "")),
            "c.toml:10:1: [[encoder]] #2 has no scale: give counts_per_unit, or counts_per_rev "
            "(with gear_ratio, and wheel_radius_m when unit = \"m\")");
  EXPECT_EQ(ParseError(Good("unit = \"m\"", "unit = \"deg\"")),
            "c.toml:5:8: [[encoder]] #1: unit \"deg\" is not one an encoder measures: \"m\" or "
            "\"rad\"");
}

TEST(ControllerMap, AnUnknownSetpointColumnIsRefusedWithTheProfileColumns) {
  EXPECT_EQ(ParseError(Good("column = \"right_m\"", "column = \"middle_m\"")),
            "c.toml:24:10: [[setpoint]] #2: column \"middle_m\" is not a column of the setpoint "
            "profile (time,left_m,right_m): \"left_m\" or \"right_m\"");
}

TEST(ControllerMap, TracksMustNameAnEncoderFedInput) {
  EXPECT_EQ(ParseError(Good("tracks = \"wheel_left_m\"", "tracks = \"wheel_middle_m\"")),
            "c.toml:19:9: setpoint column left_m tracks 'wheel_middle_m', which no [[encoder]] "
            "feeds (encoder inputs: wheel_left_m, wheel_right_m): name the input the setpoint "
            "is for, or remove tracks");
}

TEST(ControllerMap, OnEncoderGridNeedsTracks) {
  EXPECT_EQ(ParseError(Good("tracks = \"wheel_left_m\"\n", "")),
            "c.toml:20:19: [[setpoint]] #1: on_encoder_grid = true rounds the setpoint to the "
            "counts of the encoder it tracks: add tracks = \"<the encoder-fed input>\", or "
            "remove on_encoder_grid");
}

TEST(ControllerMap, AnUnreadableFileIsRefusedNamingIt) {
  try {
    static_cast<void>(LoadControllerMap("/nonexistent/c.toml"));
    FAIL() << "no error";
  } catch (const ControllerMapError& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot read the controller map /nonexistent/c.toml: No such file or directory; "
              "give an existing TOML file to --controller-map (docs/controllers.md)");
  }
}

TEST(ControllerMap, AMissingPortIsRefusedWithThePortsThatExist) {
  const FakeController controller({{"setpoint_left_m", "m"}, {"wheel_left_m", "m"}},
                                  {{"duty_left", "1"}, {"duty_right", "1"}});
  EXPECT_EQ(BindError(kGood, controller),
            "c.toml:12:9: encoder input 'wheel_right_m' is not a port of the controller "
            "(inputs: setpoint_left_m, wheel_left_m) (controller fake)");
}

TEST(ControllerMap, AnOutputNamedAsAnInputIsRefused) {
  EXPECT_EQ(BindError(Good("output = \"duty_left\"", "output = \"wheel_left_m\""), Relbot()),
            "c.toml:29:10: PWM output 'wheel_left_m' is an input of the controller; only "
            "outputs can drive a motor (outputs: duty_left, duty_right) (controller fake)");
}

TEST(ControllerMap, AnInputFedByNothingIsRefusedWithWhatToAdd) {
  const FakeController controller(
      {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"}, {"wheel_left_m", "m"},
       {"wheel_right_m", "m"}, {"mass_kg", "kg"}},
      FakeController::RelbotOutputs());
  EXPECT_EQ(BindError(kGood, controller),
            "c.toml: controller input 'mass_kg' is fed by nothing: add an [[encoder]] or "
            "[[setpoint]] entry with input = \"mass_kg\", or hold it constant with 'mass_kg = "
            "0.0' under [inputs] (controller fake)");
  // [inputs] holds it.
  const BoundControllerMap bound = BindControllerMap(
      ParseControllerMap(std::string(kGood) + "\n[inputs]\nmass_kg = 1.5\n", "c.toml"),
      controller);
  EXPECT_EQ(bound.initial_inputs[4], 1.5);
}

TEST(ControllerMap, AnOutputThatDrivesNothingIsRefused) {
  const FakeController controller(FakeController::RelbotInputs(),
                                  {{"duty_left", "1"}, {"duty_right", "1"}, {"brake", "1"}});
  EXPECT_EQ(BindError(kGood, controller),
            "c.toml: controller output 'brake' drives no PWM channel: add a [[pwm]] entry with "
            "output = \"brake\" (a controller's every output must reach a motor, or a result "
            "would silently lack it) (controller fake)");
}

TEST(ControllerMap, UnitMismatchesAreRefused) {
  const FakeController radians({{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                {"wheel_left_m", "rad"}, {"wheel_right_m", "m"}},
                               FakeController::RelbotOutputs());
  EXPECT_EQ(BindError(kGood, radians),
            "c.toml:4:9: encoder input 'wheel_left_m' is in rad but the map gives it m: make "
            "the units agree (the map's unit, or the controller's) (controller fake)");
  const FakeController volts(FakeController::RelbotInputs(),
                             {{"duty_left", "V"}, {"duty_right", "1"}});
  EXPECT_EQ(BindError(kGood, volts),
            "c.toml:29:10: PWM output 'duty_left' is in V but the map gives it 1: make the "
            "units agree (the map's unit, or the controller's) (controller fake)");
  // A setpoint column is metres, and so must be what it tracks.
  EXPECT_EQ(ParseError(Good("unit = \"m\"\ncounts_per_rev", "unit = \"rad\"\ncounts_per_rev")),
            "c.toml:19:9: setpoint column left_m is in metres but tracks 'wheel_left_m', an "
            "encoder in rad: track an encoder with unit = \"m\"");
}

}  // namespace
}  // namespace hiltwin::controller
