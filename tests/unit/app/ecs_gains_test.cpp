#include "fakes/test_paths.h"
#include "hiltwin/relbot/ecs_gains.h"

#include <gtest/gtest.h>

#include <string>

#include "unit/relbot/toml_number_file_tests.h"

namespace hiltwin::app {
namespace {

// relbot/ecs_gains.toml through the behaviour every TOML number file shares, with the
// messages a user of this file sees.
struct EcsGainsFile {
  using Record = PidGains;
  inline static const char* const kPath = HILTWIN_ECS_GAINS_TOML;
  static constexpr auto kParse = ParseEcsGains;
  static constexpr auto kLoad = LoadEcsGains;
  static constexpr auto kValidate = ValidateEcsGains;
  static constexpr auto kSpecs = EcsGainSpecs;
  static constexpr auto kDefaults = DefaultEcsGains;

  static constexpr std::string_view kWhatToDo =
      "fix it in the file (relbot/ecs_gains.toml lists every key with its unit and the tuned "
      "value), or run without a gains file to use the built-in gains";
  static constexpr std::string_view kExpectedTables = "pid and output";
  static constexpr std::string_view kUnknownTable = "feedforward";
  static constexpr std::string_view kUnknownTopLevelKey = "rate_hz";
  static constexpr toml_test::MissingKey kMissing{
      "ki_duty_per_m_s",
      "missing ECS gain pid.ki_duty_per_m_s (a number >= 0 and <= 1e+07); add it under [pid]"};
  static constexpr toml_test::LineEdit kBelowMin{
      "kp_duty_per_m", "kp_duty_per_m = -60.0",
      "ECS gain pid.kp_duty_per_m = -60 is out of range: it must be >= 0 and <= 100000"};
  static constexpr toml_test::LineEdit kAboveMax{
      "duty_limit", "duty_limit = 1.5",
      "ECS gain output.duty_limit = 1.5 is out of range: it must be > 0 and <= 1"};
  static constexpr toml_test::LineEdit kNotANumber{
      "derivative_filter_s", "derivative_filter_s = \"4 ms\"",
      "ECS gain pid.derivative_filter_s must be a number, not a string"};
  static constexpr toml_test::LineEdit kUnknownKey{
      "kd_duty_s_per_m", "kd_duty_s_per_mm = 1.0",
      "unknown key pid.kd_duty_s_per_mm (check the spelling and the unit suffix)"};
  static constexpr toml_test::NonFiniteKey kNonFinite{
      "kd_duty_s_per_m", "ECS gain pid.kd_duty_s_per_m is not a finite number"};
  static constexpr toml_test::IntegerKey<PidGains> kInteger{"kp_duty_per_m",
                                                            &PidGains::kp_duty_per_m, 75};
  static constexpr double PidGains::*kValidateMember = &PidGains::ki_duty_per_m_s;
  static constexpr std::string_view kValidateNaN =
      "ECS gain pid.ki_duty_per_m_s is not a finite number";
  static constexpr std::string_view kUnreadable =
      "cannot read the ECS gains file (No such file or directory); check the path, or run "
      "without a gains file to use the built-in gains";
};

INSTANTIATE_TYPED_TEST_SUITE_P(EcsGains, TomlNumberFile, EcsGainsFile);

TEST(EcsGains, EveryKeyCarriesAUnit) {
  for (const EcsGainSpec& spec : EcsGainSpecs()) {
    const std::string key(spec.key);
    const bool unit = key.ends_with("_per_m") || key.ends_with("_per_m_s") || key.ends_with("_s") ||
                      key.starts_with("duty_");
    EXPECT_TRUE(unit) << key;
  }
}

TEST(EcsGains, DutyLimitOfZeroIsOutOfRange) {
  // A zero limit would pin the output at 0 and leave the robot standing without a word.
  std::string text = toml_test::ReadFile(HILTWIN_ECS_GAINS_TOML);
  const int line = toml_test::ReplaceLine(text, "duty_limit", "duty_limit = 0.0");
  ASSERT_GT(line, 0);
  EXPECT_EQ(toml_test::WithoutColumn(toml_test::ErrorOf(ParseEcsGains, text)),
            toml_test::AtLine(line,
                              "ECS gain output.duty_limit = 0 is out of range: it must be > 0 "
                              "and <= 1",
                              EcsGainsFile::kWhatToDo));
}

}  // namespace
}  // namespace hiltwin::app
