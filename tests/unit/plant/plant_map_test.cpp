// Plant maps: every key parsed, every mistake refused with file:line and a fix, and binding to
// a plant's ports with the causality and unit checks.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

#include "fake_plant.h"
#include "hiltwin/plant/plant_map.h"

namespace hiltwin::plant {
namespace {

using ::testing::HasSubstr;
using test::FakePlant;

constexpr const char* kFullMap = R"(
[[pwm]]
channel = 3
input = "force_n"
gain = 10.0
reverse = true

[[encoder]]
channel = 1
output = "angle_rad"
unit = "rad"
counts_per_rev = 1024
gear_ratio = 4
joint = "shaft_joint"

[[encoder]]
channel = 4
output = "position_m"
unit = "m"
counts_per_unit = 5000
column = "enc_pos"
reverse = true

[inputs]
load_n = 2.5

[telemetry]
pose = ["position_m", "angle_rad", "angle_rad"]
)";

FakePlant ThreePortPlant() {
  return FakePlant({{"force_n", "N"}, {"load_n", "N"}},
                   {{"position_m", "m"}, {"angle_rad", "rad"}, {"speed", ""}});
}

std::string ParseError(const std::string& text) {
  try {
    static_cast<void>(ParsePlantMap(text, "map.toml"));
  } catch (const PlantMapError& e) {
    return e.what();
  }
  return "no error";
}

std::string BindError(const std::string& text, const Plant& plant) {
  try {
    static_cast<void>(BindPlantMap(ParsePlantMap(text, "map.toml"), plant));
  } catch (const PlantMapError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PlantMap, ParsesEveryKey) {
  const PlantMap map = ParsePlantMap(kFullMap, "map.toml");
  ASSERT_EQ(map.pwm.size(), 1U);
  EXPECT_EQ(map.pwm[0].channel, 3);
  EXPECT_EQ(map.pwm[0].input, "force_n");
  EXPECT_EQ(map.pwm[0].gain, 10.0);
  EXPECT_TRUE(map.pwm[0].reverse);
  EXPECT_EQ(map.pwm[0].line, 4);  // where it names its input
  EXPECT_EQ(map.pwm[0].col, 9);
  ASSERT_EQ(map.encoders.size(), 2U);
  // 1024 counts per shaft turn, the shaft turns 4 times per output radian's turn.
  EXPECT_DOUBLE_EQ(map.encoders[0].counts_per_unit, 1024.0 * 4.0 / (2.0 * std::numbers::pi));
  EXPECT_EQ(map.encoders[0].column, "enc1");  // the default column names the channel
  EXPECT_EQ(map.encoders[0].joint, "shaft_joint");
  EXPECT_EQ(map.encoders[1].counts_per_unit, 5000.0);
  EXPECT_EQ(map.encoders[1].column, "enc_pos");
  EXPECT_TRUE(map.encoders[1].reverse);
  ASSERT_EQ(map.constant_inputs.size(), 1U);
  EXPECT_EQ(map.constant_inputs[0].name, "load_n");
  EXPECT_EQ(map.constant_inputs[0].value, 2.5);
  EXPECT_EQ(map.constant_inputs[0].line, 25);
  ASSERT_TRUE(map.pose.has_value());
  EXPECT_EQ((*map.pose)[0], "position_m");
}

TEST(PlantMap, MetresFromAShaftEncoderUseTheWheelRadius) {
  const PlantMap map = ParsePlantMap(
      "[[encoder]]\nchannel = 2\noutput = \"x\"\nunit = \"m\"\ncounts_per_rev = 64\n"
      "gear_ratio = 50\nwheel_radius_m = 0.04\n",
      "m.toml");
  EXPECT_NEAR(map.encoders[0].counts_per_unit, 64.0 * 50.0 / (2.0 * std::numbers::pi * 0.04),
              1e-9);
}

TEST(PlantMap, MistakesAreRefusedWithTheLineAndAFix) {
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\ngian = 2\n"),
              AllOf(HasSubstr("map.toml:4:1"), HasSubstr("unknown key 'gian'"), HasSubstr("gain")));
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 5\ninput = \"u\"\n"),
              AllOf(HasSubstr("map.toml:2"), HasSubstr("1..4")));
  EXPECT_THAT(ParseError("[[pwm]]\ninput = \"u\"\n"), HasSubstr("has no 'channel'"));
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\n[[pwm]]\nchannel = 1\ninput = "
                         "\"v\"\n"),
              AllOf(HasSubstr("map.toml:5:11"), HasSubstr("channel 1 is mapped twice")));
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\ngain = 0\n"),
              HasSubstr("gain 0 would disconnect"));
  EXPECT_THAT(ParseError("[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"deg\"\n"
                         "counts_per_unit = 1\n"),
              AllOf(HasSubstr("map.toml:4"), HasSubstr("\"m\" or \"rad\"")));
  EXPECT_THAT(ParseError("[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"rad\"\n"),
              HasSubstr("has no scale"));
  EXPECT_THAT(ParseError("[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"rad\"\n"
                         "counts_per_unit = 1\ncounts_per_rev = 4\n"),
              HasSubstr("keep one"));
  EXPECT_THAT(ParseError("[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"m\"\n"
                         "counts_per_rev = 4\n"),
              HasSubstr("needs wheel_radius_m"));
  EXPECT_THAT(ParseError("[pwm]\nchannel = 1\n"), HasSubstr("[[pwm]]"));
  EXPECT_THAT(ParseError("[telemetry]\npose = [\"x\"]\n"), HasSubstr("three outputs"));
  EXPECT_THAT(ParseError("[[pwm]\n"), AllOf(HasSubstr("map.toml:1"), HasSubstr("not valid TOML")));
  EXPECT_THAT(ParseError("[inputs]\nload = \"high\"\n"), HasSubstr("finite number"));
}

// Every message names the line and column of the key at fault, not its [[pwm]] or [[encoder]]
// header; binding names the input or output key's own place, and [inputs] the constant's.
TEST(PlantMap, ErrorsNameTheOffendingKeysLineAndColumn) {
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\ngain = 0\n"),
              HasSubstr("map.toml:4:8: [[pwm]] #1: gain 0 would disconnect"));
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\n[[pwm]]\ninput = \"v\"\n"
                         "channel = 1\n"),
              HasSubstr("map.toml:6:11: PWM channel 1 is mapped twice"));
  EXPECT_THAT(ParseError("[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"rad\"\n"
                         "counts_per_unit = 1\ncounts_per_rev = 4\n"),
              HasSubstr("map.toml:6:18: [[encoder]] #1 gives both counts_per_unit and "
                        "counts_per_rev: keep one"));
  const FakePlant plant = ThreePortPlant();
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"position_m\"\n[inputs]\nload_n = 0\n",
                        plant),
              HasSubstr("map.toml:3:9: PWM channel input 'position_m' is an output"));
  EXPECT_THAT(BindError("[[encoder]]\nchannel = 1\nunit = \"m\"\ncounts_per_unit = 1\n"
                        "output = \"force_n\"\n[inputs]\nforce_n = 0\nload_n = 0\n",
                        plant),
              HasSubstr("map.toml:5:10: encoder output 'force_n' is an input"));
  EXPECT_THAT(BindError("[inputs]\nforce_n = 0\n  load_n = 0\nnope = 1\n", plant),
              HasSubstr("map.toml:4:8: [inputs] 'nope' is not a port of the plant"));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"force_n\"\n[inputs]\nforce_n = 1\n"
                        "load_n = 0\n",
                        plant),
              HasSubstr("map.toml:5:11: [inputs] gives 'force_n' a value but a PWM channel "
                        "drives it"));
}

// A negative scale is refused (reverse = true says the direction); so is an encoder scale
// beyond the most counts the board emits in a second (100 MHz over its smallest clock divider,
// 4: 25 M), at which it could not follow the output moving one unit per second: a wheel radius
// of 1e-200 m made the encoder read 0 all run while the wheel moved.
TEST(PlantMap, NegativeScalesAndScalesBeyondTheBoardsCountRateAreRefused) {
  EXPECT_THAT(ParseError("[[pwm]]\nchannel = 1\ninput = \"u\"\ngain = -2\n"),
              HasSubstr("map.toml:4:8: [[pwm]] #1: gain -2 is negative: give its size and "
                        "reverse = true"));
  const std::string encoder = "[[encoder]]\nchannel = 1\noutput = \"y\"\n";
  EXPECT_THAT(ParseError(encoder + "unit = \"rad\"\ncounts_per_unit = -5\n"),
              HasSubstr("map.toml:5:19: [[encoder]] #1: counts_per_unit -5 is negative: give "
                        "its size and reverse = true"));
  EXPECT_THAT(ParseError(encoder + "unit = \"rad\"\ncounts_per_unit = 1e15\n"),
              HasSubstr("map.toml:5:19: [[encoder]] #1: 1e+15 counts per rad is more than "
                        "2.5e+07, the most counts the board emits in a second"));
  EXPECT_THAT(ParseError(encoder + "unit = \"m\"\ncounts_per_rev = 64\ngear_ratio = 50\n"
                                   "wheel_radius_m = 1e-200\n"),
              HasSubstr("map.toml:7:18: [[encoder]] #1: 5.09296e+202 counts per m is more than "
                        "2.5e+07"));
  EXPECT_THAT(ParseError(encoder + "unit = \"rad\"\ncounts_per_rev = 1e300\ngear_ratio = 1e300\n"),
              HasSubstr("map.toml:6:14: [[encoder]] #1: inf counts per rad"));
  EXPECT_EQ(ParsePlantMap(encoder + "unit = \"rad\"\ncounts_per_unit = 2.5e7\n", "m.toml")
                .encoders[0]
                .counts_per_unit,
            kMaxCountsPerUnit);
}

// Found by fuzz/toml_config (fuzz/corpus/toml_config/regression_float_channel.toml): a float
// channel far outside int64_t reached toml++'s float-to-integer cast, undefined behaviour.
// A channel is an integer; a float one, big or not, is refused with the line.
TEST(PlantMap, AFloatChannelIsRefusedAsNotAnInteger) {
  for (const char* channel : {"3.3333333333333333333333333e75", "1e300", "-1e300", "2.0", "nan"}) {
    EXPECT_THAT(ParseError(std::string("[[pwm]]\nchannel = ") + channel + "\ninput = \"u\"\n"),
                AllOf(HasSubstr("map.toml:2"), HasSubstr("channel must be an integer 1..4")))
        << channel;
  }
}

TEST(PlantMap, AMissingFileSaysWhichAndWhy) {
  try {
    static_cast<void>(LoadPlantMap("/nonexistent/map.toml"));
    FAIL() << "no error";
  } catch (const PlantMapError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("/nonexistent/map.toml"),
                                HasSubstr("No such file or directory")));
  }
}

TEST(PlantMap, BindsNamesToPortIndicesWithTheSignsFoldedIn) {
  const FakePlant plant = ThreePortPlant();
  const BoundPlantMap bound = BindPlantMap(ParsePlantMap(kFullMap, "map.toml"), plant);
  ASSERT_EQ(bound.pwm.size(), 1U);
  EXPECT_EQ(bound.pwm[0].channel_index, 2U);
  EXPECT_EQ(bound.pwm[0].input_index, 0U);
  EXPECT_EQ(bound.pwm[0].gain, -10.0);
  ASSERT_EQ(bound.encoders.size(), 2U);
  EXPECT_EQ(bound.encoders[0].output_index, 1U);
  EXPECT_EQ(bound.encoders[1].channel_index, 3U);
  EXPECT_EQ(bound.encoders[1].counts_per_unit, -5000.0);
  EXPECT_EQ(bound.encoder_columns, (std::vector<std::string>{"enc1", "enc_pos"}));
  EXPECT_EQ(bound.initial_inputs, (std::vector<double>{0.0, 2.5}));
  ASSERT_TRUE(bound.pose.has_value());
  EXPECT_EQ(*bound.pose, (std::array<std::size_t, 3>{0, 1, 1}));
  ASSERT_EQ(bound.joints.size(), 1U);
  EXPECT_EQ(bound.joint_names[0], "shaft_joint");
  EXPECT_EQ(bound.joints[0].to_rad, 1.0);
}

TEST(PlantMap, BindingRefusesWhatThePlantCannotDo) {
  const FakePlant plant = ThreePortPlant();
  const std::string enc = "[[encoder]]\nchannel = 1\nunit = \"m\"\ncounts_per_unit = 1\n";
  const std::string load = "[inputs]\nload_n = 0\n";
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"position_m\"\n" + load, plant),
              AllOf(HasSubstr("map.toml:3:9"), HasSubstr("is an output of the plant"),
                    HasSubstr("inputs: force_n, load_n"), HasSubstr("plant fake")));
  EXPECT_THAT(BindError(enc + "output = \"force_n\"\n[[pwm]]\nchannel = 1\ninput = \"force_n\"\n" +
                            load,
                        plant),
              AllOf(HasSubstr("is an input of the plant"), HasSubstr("outputs: position_m")));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"k\"\n", plant),
              HasSubstr("'k' is a parameter of the fake plant"));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"nope\"\n", plant),
              HasSubstr("'nope' is not a port of the plant"));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"force_n\"\n", plant),
              AllOf(HasSubstr("'load_n' is driven by no PWM channel"), HasSubstr("[inputs]")));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"force_n\"\n[[pwm]]\nchannel = 2\n"
                        "input = \"force_n\"\n" + load,
                        plant),
              HasSubstr("driven by two PWM channels"));
  EXPECT_THAT(BindError("[[pwm]]\nchannel = 1\ninput = \"force_n\"\n[inputs]\nforce_n = 1\n"
                        "load_n = 0\n",
                        plant),
              HasSubstr("keep one"));
  const std::string angle_as_m = "[[encoder]]\nchannel = 1\noutput = \"angle_rad\"\nunit = \"m\"\n"
                                 "counts_per_unit = 1\n";
  EXPECT_THAT(BindError(angle_as_m + "[inputs]\nforce_n = 0\nload_n = 0\n", plant),
              AllOf(HasSubstr("is in rad but the map says unit = \"m\"")));
  EXPECT_THAT(BindError(enc + "output = \"speed\"\ncolumn = \"force_n\"\n[inputs]\nforce_n = 0\n"
                              "load_n = 0\n",
                        plant),
              HasSubstr("log column 'force_n' appears twice"));
}

TEST(PlantMap, AnOutputWithoutAUnitTakesTheMapsUnit) {
  const FakePlant plant = ThreePortPlant();
  const BoundPlantMap bound = BindPlantMap(
      ParsePlantMap("[[encoder]]\nchannel = 1\noutput = \"speed\"\nunit = \"rad\"\n"
                    "counts_per_unit = 3\n[inputs]\nforce_n = 0\nload_n = 0\n",
                    "m.toml"),
      plant);
  EXPECT_EQ(bound.encoders[0].counts_per_unit, 3.0);
}

}  // namespace
}  // namespace hiltwin::plant
