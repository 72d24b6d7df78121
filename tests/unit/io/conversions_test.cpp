#include "hiltwin/io/conversions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <limits>

namespace hiltwin::io {
namespace {

TEST(Conversions, DutyToPwmScalesRoundsAndClamps) {
  EXPECT_EQ(DutyToPwm(0.0), 0);
  EXPECT_EQ(DutyToPwm(0.5), 1024);
  EXPECT_EQ(DutyToPwm(-0.5), -1024);
  EXPECT_EQ(DutyToPwm(1.0), 2047);    // 2048 does not fit the generator's range
  EXPECT_EQ(DutyToPwm(-1.0), -2048);
  EXPECT_EQ(DutyToPwm(3.0), 2047);
  EXPECT_EQ(DutyToPwm(-3.0), -2048);
  EXPECT_EQ(DutyToPwm(1.0 / 2048.0 * 0.49), 0);
  EXPECT_EQ(DutyToPwm(1.0 / 2048.0 * 0.51), 1);
  EXPECT_EQ(DutyToPwm(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(DutyToPwm(std::numeric_limits<double>::infinity()), 2047);
}

TEST(Conversions, PwmToDutyIsValueOverResolution) {
  EXPECT_DOUBLE_EQ(PwmToDuty(1024), 0.5);
  EXPECT_DOUBLE_EQ(PwmToDuty(-2048), -1.0);
  EXPECT_DOUBLE_EQ(PwmToDuty(0), 0.0);
  for (int v = -2048; v <= 2047; ++v) EXPECT_EQ(DutyToPwm(PwmToDuty(v)), v);
}

TEST(Conversions, PwmWordsCarrySignAndMagnitude) {
  EXPECT_EQ(PwmWordFromValue(-2048), (PwmWord{2048, true, false}));
  EXPECT_EQ(PwmWordFromValue(5, true), (PwmWord{5, false, true}));
  EXPECT_EQ(PwmWordFromValue(99999).magnitude, 2048);
  for (int v = -2048; v <= 2047; ++v) EXPECT_EQ(PwmValueFromWord(PwmWordFromValue(v)), v);
}

TEST(Conversions, PwmReaderHalvesTheHighTimeIntoElevenBits) {
  // Thesis §2.2.2: high for 2048 of 4096 clocks reads 1024 (50 %).
  EXPECT_EQ(PwmReaderValue(0.5), 1024);
  EXPECT_EQ(PwmReaderValue(-0.5), -1024);
  EXPECT_EQ(PwmReaderValue(1.0), 2047);  // 4096 / 2 = 2048 saturates the 11-bit register
  EXPECT_EQ(PwmReaderValue(0.0), 0);
  EXPECT_EQ(PwmReaderValue(std::nan("")), 0);
  // What the ECS generates, the twin reads back exactly (except full scale).
  for (int v = -2047; v <= 2047; ++v) EXPECT_EQ(PwmReaderValue(PwmToDuty(v)), v) << v;
}

TEST(Conversions, MetresToCountsCountsMotorTurns) {
  // r = 0.05 m, 15 motor turns per wheel turn, 1024 counts per motor turn.
  const WheelGeometry g{0.05, 15.0, 1024.0};
  // One wheel turn is 2π·0.05 m of travel, 15 motor turns, 15 360 counts.
  const double one_wheel_turn_m = 2.0 * std::numbers::pi * 0.05;
  EXPECT_NEAR(CountsPerMetre(g), 15.0 * 1024.0 / one_wheel_turn_m, 1e-9);
  EXPECT_EQ(MetresToCounts(one_wheel_turn_m * (1.0 + 1e-12), g), 15 * 1024);
  EXPECT_EQ(MetresToCounts(-one_wheel_turn_m * (1.0 + 1e-12), g), -15 * 1024 - 1);
  EXPECT_NEAR(CountsToMetres(15 * 1024, g), one_wheel_turn_m, 1e-15);
  const double expected = 1.0 / one_wheel_turn_m * 15.0 * 1024.0;  // 48 892.9 counts in 1 m
  EXPECT_EQ(MetresToCounts(1.0, g), static_cast<std::int64_t>(std::floor(expected)));
  EXPECT_EQ(MetresToCounts(0.0, g), 0);
  EXPECT_EQ(MetresToCounts(-1e-12, g), -1);  // floor, not truncation: no double-width zero
  EXPECT_EQ(MetresToCounts(std::nan(""), g), 0);
  EXPECT_GT(MetresToCounts(1e300, g), 0);
  for (std::int64_t counts : {std::int64_t{-100000}, std::int64_t{-1}, std::int64_t{0},
                              std::int64_t{12345}}) {
    // Half a count above the exact position floors back to the same count.
    const double metres = CountsToMetres(counts, g) + CountsToMetres(1, g) / 2;
    EXPECT_EQ(MetresToCounts(metres, g), counts);
  }
}

TEST(Conversions, WrapToRelativeMatchesTheAppendixGLoops) {
  auto reference = [](std::int64_t value, std::int32_t resolution) {
    while (value >= resolution / 2) value -= resolution;
    while (value < -resolution / 2) value += resolution;
    return static_cast<std::int32_t>(value);
  };
  for (std::int64_t v = -40000; v <= 40000; v += 7) {
    EXPECT_EQ(WrapToRelative(v), reference(v, 16384)) << v;
    EXPECT_EQ(WrapToRelative(v, 4096), reference(v, 4096)) << v;
    // Resolutions that are not powers of two take the remainder branch.
    EXPECT_EQ(WrapToRelative(v, 1000), reference(v, 1000)) << v;
    EXPECT_EQ(WrapToRelative(v, 4000), reference(v, 4000)) << v;
  }
  EXPECT_EQ(WrapToRelative(std::numeric_limits<std::int64_t>::min(), 1000),
            reference(std::numeric_limits<std::int64_t>::min() % 1000, 1000));
  EXPECT_EQ(WrapToRelative(12345, 0), 0);  // outside the precondition, but no division by zero
  EXPECT_EQ(WrapToRelative(12345, -16384), 0);
  EXPECT_EQ(WrapToRelative(8191), 8191);
  EXPECT_EQ(WrapToRelative(8192), -8192);
  EXPECT_EQ(WrapToRelative(-8192), -8192);
  EXPECT_EQ(WrapToRelative(-8193), 8191);
  EXPECT_EQ(WrapToRelative(std::numeric_limits<std::int64_t>::max()),
            reference(std::numeric_limits<std::int64_t>::max() % 16384, 16384));
}

TEST(Conversions, UnwrapperRebuildsTheAbsolutePosition) {
  EncoderUnwrapper unwrapper;
  std::int64_t absolute = 0;
  unwrapper.Update(0);
  for (int i = 0; i < 10000; ++i) {
    absolute += (i % 1000 < 600) ? 37 : -53;  // back and forth across many wraps
    EXPECT_EQ(unwrapper.Update(WrapToRelative(absolute)), absolute);
  }
}

}  // namespace
}  // namespace hiltwin::io
