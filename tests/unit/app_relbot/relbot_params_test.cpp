#include "hiltwin/app_relbot/relbot_params.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

namespace hiltwin::app {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string FileText() { return ReadFile(HILTWIN_RELBOT_TOML); }

// Replaces the whole line that starts with `key =` (first match) by `replacement`; returns the
// 1-based line number, so tests can expect "file:line:" in the message.
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
    (void)ParseRelbotParams(text, "test.toml");
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(RelbotParams, TomlFileEqualsBuiltInDefaults) {
  const RelbotParams from_file = LoadRelbotParams(HILTWIN_RELBOT_TOML);
  const RelbotParams defaults = DefaultRelbotParams();
  int compared = 0;
  for (const ParamSpec& spec : RelbotParamSpecs()) {
    EXPECT_EQ(from_file.*spec.member, defaults.*spec.member) << spec.table << "." << spec.key;
    ++compared;
  }
  // Every member of RelbotParams is in the table (no parameter escapes the file).
  EXPECT_EQ(static_cast<std::size_t>(compared) * sizeof(double), sizeof(RelbotParams));
}

TEST(RelbotParams, DefaultsAreValid) {
  EXPECT_NO_THROW(ValidateRelbotParams(DefaultRelbotParams(), "built-in"));
}

TEST(RelbotParams, EveryKeyCarriesAUnitOrCountSuffix) {
  for (const ParamSpec& spec : RelbotParamSpecs()) {
    const std::string key(spec.key);
    const bool has_unit = key.find('_') != std::string::npos;
    EXPECT_TRUE(has_unit) << key;
  }
}

TEST(RelbotParams, MissingKeyIsNamed) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "resistance_ohm", "# removed"), 0);
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("test.toml"), std::string::npos) << message;
  EXPECT_NE(message.find("missing"), std::string::npos) << message;
  EXPECT_NE(message.find("motor.resistance_ohm"), std::string::npos) << message;
  EXPECT_NE(message.find("add it under [motor]"), std::string::npos) << message;
}

TEST(RelbotParams, OutOfRangeValueIsNamedWithLine) {
  std::string text = FileText();
  const int line = ReplaceLine(text, "resistance_ohm", "resistance_ohm = -4.0");
  ASSERT_GT(line, 0);
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("test.toml:" + std::to_string(line) + ":"), std::string::npos)
      << message;
  EXPECT_NE(message.find("motor.resistance_ohm"), std::string::npos) << message;
  EXPECT_NE(message.find("out of range"), std::string::npos) << message;
  EXPECT_NE(message.find("> 0"), std::string::npos) << message;
}

TEST(RelbotParams, NonFiniteValuesAreRejected) {
  for (const std::string value : {"nan", "inf", "-inf"}) {
    std::string text = FileText();
    ASSERT_GT(ReplaceLine(text, "stiffness_n_per_m", "stiffness_n_per_m = " + value), 0);
    const std::string message = ErrorOf(text);
    EXPECT_NE(message.find("contact.stiffness_n_per_m"), std::string::npos) << message;
    EXPECT_NE(message.find("not a finite number"), std::string::npos) << message;
  }
}

TEST(RelbotParams, NonNumberIsRejected) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "radius_m", "radius_m = \"40 mm\""), 0);
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("wheel.radius_m must be a number"), std::string::npos) << message;
}

TEST(RelbotParams, IntegersAreAcceptedAsNumbers) {
  std::string text = FileText();
  ASSERT_GT(ReplaceLine(text, "ratio_motor_rev_per_wheel_rev", "ratio_motor_rev_per_wheel_rev = 30"),
            0);
  EXPECT_EQ(ParseRelbotParams(text, "test.toml").gear_ratio_motor_rev_per_wheel_rev, 30.0);
}

TEST(RelbotParams, UnknownKeysAndTablesAreRejected) {
  std::string text = FileText();
  const int line = ReplaceLine(text, "resistance_ohm", "resistance_ohm = 4.0\nresistance_ohms = 4.0");
  std::string message = ErrorOf(text);
  EXPECT_NE(message.find("unknown key motor.resistance_ohms"), std::string::npos) << message;
  EXPECT_NE(message.find("test.toml:" + std::to_string(line + 1) + ":"), std::string::npos)
      << message;
  message = ErrorOf(FileText() + "\n[battery]\ncapacity_mah = 2200\n");
  EXPECT_NE(message.find("unknown table [battery]"), std::string::npos) << message;
  message = ErrorOf("speed = 3\n" + FileText());
  EXPECT_NE(message.find("unknown top-level key 'speed'"), std::string::npos) << message;
}

TEST(RelbotParams, SyntaxErrorGivesLineAndColumn) {
  std::string text = FileText();
  const int line = ReplaceLine(text, "mass_kg", "mass_kg = = 0.1");
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("test.toml:" + std::to_string(line) + ":"), std::string::npos)
      << message;
  EXPECT_NE(message.find("not valid TOML"), std::string::npos) << message;
}

TEST(RelbotParams, UnreadableFileSaysSo) {
  try {
    (void)LoadRelbotParams("/nonexistent/relbot.toml");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/nonexistent/relbot.toml: cannot read"), std::string::npos) << message;
  }
}

TEST(RelbotParams, ValidateNamesTheBadMember) {
  RelbotParams p;
  p.castor_smoothing_speed_m_per_s = 0.0;  // must be > 0: it divides the Coulomb term
  try {
    ValidateRelbotParams(p, "built-in");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("castor.smoothing_speed_m_per_s"), std::string::npos);
  }
  p = RelbotParams{};
  p.wheel_radius_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ValidateRelbotParams(p, "built-in"), ConfigError);
}

TEST(RelbotParams, EncoderCountsPerMetreFollowsAppendixG) {
  const RelbotParams p;
  // metres / radius -> wheel rad; * N -> motor rad; / 2 pi * counts per rev -> counts
  EXPECT_NEAR(EncoderCountsPerMetre(p), 1.0 / 0.04 * 50.0 / (2.0 * std::numbers::pi) * 64.0,
              1e-9);
}

}  // namespace
}  // namespace hiltwin::app
