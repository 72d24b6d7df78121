// toml_numbers.h on its own, with a two-key record. The behaviour the RELbot and ECS files share
// is tested through their public functions (toml_number_file_tests.h); this covers what neither
// file uses.
#include "hiltwin/relbot/toml_numbers.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "hiltwin/relbot/config_error.h"

namespace hiltwin::app {
namespace {

struct Probe {
  double gain_per_m = 1.0;
  double force_n = 2.0;
};

constexpr std::array<TomlNumberSpec<Probe>, 2> kProbeSpecs{{
    {"loop", "gain_per_m", &Probe::gain_per_m, 0.0, false, 10.0},
    {"loop", "force_n", &Probe::force_n, 0.0, true, kTomlNoUpperLimit},
}};

constexpr TomlNumbersWording kProbeWording{
    .value_name = "probe value",
    .file_name = "probe file",
    .expected_tables = "loop",
    .file_hint = "probe.toml shows how",
    .fallback = "do without",
};

std::string ErrorOf(const std::string& text) {
  try {
    (void)ParseTomlNumbers(text, "probe.toml", kProbeSpecs, kProbeWording);
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(TomlNumbers, EveryKeyLandsInItsMember) {
  const Probe probe = ParseTomlNumbers("[loop]\ngain_per_m = 3.5\nforce_n = 1e9\n", "probe.toml",
                                       kProbeSpecs, kProbeWording);
  EXPECT_EQ(probe.gain_per_m, 3.5);
  EXPECT_EQ(probe.force_n, 1e9);
}

TEST(TomlNumbers, AnUnboundedRangeNamesOnlyItsMinimum) {
  EXPECT_EQ(ErrorOf("[loop]\ngain_per_m = 3.5\n"),
            "probe.toml: missing probe value loop.force_n (a number > 0); add it under [loop]; "
            "fix it in the file (probe.toml shows how), or do without");
  Probe probe;
  probe.force_n = -1.0;
  try {
    ValidateTomlNumbers(probe, "built-in", kProbeSpecs, kProbeWording);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              "built-in: probe value loop.force_n = -1 is out of range: it must be > 0; fix it in "
              "the file (probe.toml shows how), or do without");
  }
}

TEST(TomlNumbers, InfinityIsNotANumberEvenWithoutAnUpperLimit) {
  Probe probe;
  probe.force_n = kTomlNoUpperLimit;
  EXPECT_THROW(ValidateTomlNumbers(probe, "built-in", kProbeSpecs, kProbeWording), ConfigError);
}

}  // namespace
}  // namespace hiltwin::app
