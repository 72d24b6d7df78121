#include "hiltwin/app_relbot/ecs_gains.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace hiltwin::app {
namespace {

std::string FileText() {
  std::ifstream in(HILTWIN_ECS_GAINS_TOML);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Replaces the first line that starts with `key =` by `replacement`; returns its 1-based
// number so tests can expect "file:line:" in the message.
int ReplaceLine(std::string& text, const std::string& key, const std::string& replacement) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  int number = 0;
  int found = 0;
  while (std::getline(in, line)) {
    ++number;
    if (found == 0 && line.rfind(key + " =", 0) == 0) {
      found = number;
      line = replacement;
    }
    out << line << '\n';
  }
  text = out.str();
  return found;
}

std::string ErrorOf(const std::string& text) {
  try {
    (void)ParseEcsGains(text, "gains.toml");
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(EcsGains, TomlFileEqualsBuiltInDefaults) {
  const PidGains from_file = LoadEcsGains(HILTWIN_ECS_GAINS_TOML);
  const PidGains defaults = DefaultEcsGains();
  int compared = 0;
  for (const EcsGainSpec& spec : EcsGainSpecs()) {
    EXPECT_EQ(from_file.*spec.member, defaults.*spec.member) << spec.table << "." << spec.key;
    ++compared;
  }
  // Every member of PidGains is in the file: no gain escapes it.
  EXPECT_EQ(static_cast<std::size_t>(compared) * sizeof(double), sizeof(PidGains));
}

TEST(EcsGains, DefaultsAreValidAndEveryKeyCarriesAUnit) {
  EXPECT_NO_THROW(ValidateEcsGains(DefaultEcsGains(), "built-in"));
  for (const EcsGainSpec& spec : EcsGainSpecs()) {
    const std::string key(spec.key);
    const bool unit = key.ends_with("_per_m") || key.ends_with("_per_m_s") || key.ends_with("_s") ||
                      key.starts_with("duty_");
    EXPECT_TRUE(unit) << key;
  }
}

TEST(EcsGains, MissingKeyIsNamedWithItsTable) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "ki_duty_per_m_s", "# removed"), 0);
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("gains.toml: missing ECS gain pid.ki_duty_per_m_s"), std::string::npos)
      << message;
  EXPECT_NE(message.find("add it under [pid]"), std::string::npos) << message;
}

TEST(EcsGains, OutOfRangeValueNamesFileLineKeyAndRange) {
  std::string text = FileText();
  const int line = ReplaceLine(text, "kp_duty_per_m", "kp_duty_per_m = -60.0");
  ASSERT_GT(line, 0);
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("gains.toml:" + std::to_string(line) + ":"), std::string::npos) << message;
  EXPECT_NE(message.find("pid.kp_duty_per_m = -60 is out of range: it must be >= 0"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("app_relbot/ecs_gains.toml"), std::string::npos) << message;

  text = FileText();
  ASSERT_GT(ReplaceLine(text, "duty_limit", "duty_limit = 0.0"), 0);
  EXPECT_NE(ErrorOf(text).find("output.duty_limit = 0 is out of range: it must be > 0 and <= 1"),
            std::string::npos)
      << ErrorOf(text);
  text = FileText();
  ASSERT_GT(ReplaceLine(text, "duty_limit", "duty_limit = 1.5"), 0);
  EXPECT_NE(ErrorOf(text).find("output.duty_limit = 1.5 is out of range"), std::string::npos);
}

TEST(EcsGains, UnknownKeyAndTableAreRejected) {
  std::string text = FileText();
  const int line = ReplaceLine(text, "kd_duty_s_per_m", "kd_duty_s_per_mm = 1.0");
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("gains.toml:" + std::to_string(line) + ":"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown key pid.kd_duty_s_per_mm (check the spelling and the unit"),
            std::string::npos)
      << message;
  EXPECT_NE(ErrorOf(FileText() + "\n[feedforward]\nkv_duty_s_per_m = 1.0\n")
                .find("unknown table [feedforward]"),
            std::string::npos);
  EXPECT_NE(ErrorOf("rate_hz = 1000\n" + FileText()).find("unknown top-level key 'rate_hz'"),
            std::string::npos);
}

TEST(EcsGains, WrongTypeAndBadTomlAreReported) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "derivative_filter_s", "derivative_filter_s = \"4 ms\""), 0);
  EXPECT_NE(ErrorOf(text).find("pid.derivative_filter_s must be a number, not a string"),
            std::string::npos)
      << ErrorOf(text);
  const std::string bad = ErrorOf("[pid\nkp_duty_per_m = 1\n");
  EXPECT_NE(bad.find("gains.toml:1:"), std::string::npos) << bad;
  EXPECT_NE(bad.find("not valid TOML"), std::string::npos) << bad;
}

TEST(EcsGains, IntegersAreAcceptedAsNumbers) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "kp_duty_per_m", "kp_duty_per_m = 75"), 0);
  EXPECT_EQ(ParseEcsGains(text, "gains.toml").kp_duty_per_m, 75.0);
}

TEST(EcsGains, ValidateNamesTheSourceAndRejectsNaN) {
  PidGains gains = DefaultEcsGains();
  gains.ki_duty_per_m_s = std::numeric_limits<double>::quiet_NaN();
  try {
    ValidateEcsGains(gains, "--gains");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("--gains: ECS gain pid.ki_duty_per_m_s is not a "
                        "finite number"),
              std::string::npos)
        << error.what();
  }
}

TEST(EcsGains, UnreadableFileSaysSo) {
  try {
    (void)LoadEcsGains("/nonexistent/ecs_gains.toml");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("/nonexistent/ecs_gains.toml: cannot read the ECS "
                        "gains file"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace hiltwin::app
