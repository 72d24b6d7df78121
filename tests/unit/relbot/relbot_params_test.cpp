#include "fakes/test_paths.h"
#include "hiltwin/relbot/relbot_params.h"

#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "unit/relbot/toml_number_file_tests.h"

namespace hiltwin::app {
namespace {

// relbot/relbot.toml through the behaviour every TOML number file shares, with the messages
// a user of this file sees.
struct RelbotFile {
  using Record = RelbotParams;
  inline static const char* const kPath = HILTWIN_RELBOT_TOML;
  static constexpr auto kParse = ParseRelbotParams;
  static constexpr auto kLoad = LoadRelbotParams;
  static constexpr auto kValidate = ValidateRelbotParams;
  static constexpr auto kSpecs = RelbotParamSpecs;
  static constexpr auto kDefaults = DefaultRelbotParams;

  static constexpr std::string_view kWhatToDo =
      "fix it in the file (relbot/relbot.toml lists every key with its unit and a documented "
      "value), or run without a parameter file to use the built-in set";
  static constexpr std::string_view kExpectedTables =
      "supply, motor, gear, encoder, wheel, body, contact, castor";
  static constexpr std::string_view kUnknownTable = "battery";
  static constexpr std::string_view kUnknownTopLevelKey = "speed";
  static constexpr toml_test::MissingKey kMissing{
      "resistance_ohm",
      "missing RELbot parameter motor.resistance_ohm (a number > 0 and <= 10000); add it under "
      "[motor]"};
  static constexpr toml_test::LineEdit kBelowMin{
      "resistance_ohm", "resistance_ohm = -4.0",
      "RELbot parameter motor.resistance_ohm = -4 is out of range: it must be > 0 and <= 10000"};
  // A 1 km wheel: a unit slip.
  static constexpr toml_test::LineEdit kAboveMax{
      "radius_m", "radius_m = 1000.0",
      "RELbot parameter wheel.radius_m = 1000 is out of range: it must be > 0 and <= 10"};
  static constexpr toml_test::LineEdit kNotANumber{
      "radius_m", "radius_m = \"40 mm\"",
      "RELbot parameter wheel.radius_m must be a number, not a string"};
  static constexpr toml_test::LineEdit kUnknownKey{
      "resistance_ohm", "resistance_ohms = 4.0",
      "unknown key motor.resistance_ohms (check the spelling and the unit suffix)"};
  static constexpr toml_test::NonFiniteKey kNonFinite{
      "stiffness_n_per_m", "RELbot parameter contact.stiffness_n_per_m is not a finite number"};
  static constexpr toml_test::IntegerKey<RelbotParams> kInteger{
      "ratio_motor_rev_per_wheel_rev", &RelbotParams::gear_ratio_motor_rev_per_wheel_rev, 30};
  static constexpr double RelbotParams::*kValidateMember = &RelbotParams::wheel_radius_m;
  static constexpr std::string_view kValidateNaN =
      "RELbot parameter wheel.radius_m is not a finite number";
  static constexpr std::string_view kUnreadable =
      "cannot read the RELbot parameter file (No such file or directory); check the path, or run "
      "without a parameter file to use the built-in set";
};

INSTANTIATE_TYPED_TEST_SUITE_P(RelbotParams, TomlNumberFile, RelbotFile);

TEST(RelbotParams, EveryKeyCarriesAUnitOrCountSuffix) {
  for (const ParamSpec& spec : RelbotParamSpecs()) {
    const std::string key(spec.key);
    const bool has_unit = key.find('_') != std::string::npos;
    EXPECT_TRUE(has_unit) << key;
  }
}

TEST(RelbotParams, CastorSmoothingSpeedMustBePositive) {
  RelbotParams p;
  p.castor_smoothing_speed_m_per_s = 0.0;  // must be > 0: it divides the Coulomb term
  try {
    ValidateRelbotParams(p, "built-in");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("built-in: RELbot parameter castor.smoothing_speed_m_per_s = 0 is out of "
                        "range: it must be > 0 and <= 100; "),
              std::string::npos)
        << error.what();
  }
}

TEST(RelbotParams, EncoderCountsPerMetreFollowsAppendixG) {
  const RelbotParams p;
  // metres / radius -> wheel rad; * N -> motor rad; / 2 pi * counts per rev -> counts
  EXPECT_NEAR(EncoderCountsPerMetre(p), 1.0 / 0.04 * 50.0 / (2.0 * std::numbers::pi) * 64.0,
              1e-9);
}

}  // namespace
}  // namespace hiltwin::app
