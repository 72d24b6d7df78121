// Whether a controller reads the encoders often enough (issue 34: a 10 Hz ECS against a 4 kHz
// twin decoded 0 edges, ended 119 mm off and still passed, without a word).
#include "hiltwin/relbot/encoder_reading.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace hiltwin::app {
namespace {

using ::testing::HasSubstr;

EncoderReading Reading(double controller_hz, std::optional<double> twin_hz) {
  return {controller_hz, twin_hz, TopCountsPerSecond(DefaultRelbotParams()), "--ecs-rate"};
}

TEST(EncoderReading, TheRelbotsTopCountRateIsItsMotorsNoLoadSpeed) {
  // 12 V / 0.01 V s/rad = 1200 rad/s at the motor, 64 counts per turn.
  EXPECT_NEAR(TopCountsPerSecond(DefaultRelbotParams()), 1200.0 * 64.0 / (2.0 * 3.14159265), 0.1);
}

TEST(EncoderReading, TheDefaultPairFollowsTheCounts) {
  EXPECT_TRUE(EncoderReadingWarnings(Reading(1000.0, 4000.0)).empty());
  EXPECT_TRUE(EncoderReadingWarnings(Reading(1000.0, std::nullopt)).empty());
}

TEST(EncoderReading, AControllerThatReadsLessOftenThanTheLinesKeepIsWarnedWithTheRateToUse) {
  const auto lines = EncoderReadingWarnings(Reading(10.0, 4000.0));
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0],
            "the controller at 10 Hz reads the encoders every 400 periods of the twin at 4000 Hz; "
            "the emulated encoder lines keep 128, so the edges in between are lost and the "
            "counts jump undecoded (resyncs): raise --ecs-rate to at least 32 Hz");
  // The edge: 128 twin periods per read still decode, 129 do not.
  EXPECT_TRUE(EncoderReadingWarnings(Reading(31.25, 4000.0)).empty());
  EXPECT_EQ(EncoderReadingWarnings(Reading(31.0, 4000.0)).size(), 1U);
  // A real board's readers count every edge: only the wrap matters there.
  EXPECT_TRUE(EncoderReadingWarnings(Reading(10.0, std::nullopt)).empty());
}

TEST(EncoderReading, ACountThatCanWrapBetweenTwoReadsIsWarned) {
  // 12223 counts/s: 1 Hz lets a wheel move more than 8191 counts between two reads.
  const auto lines = EncoderReadingWarnings(Reading(1.0, std::nullopt));
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_THAT(lines[0], HasSubstr("at its top speed a wheel moves 12223 counts between two reads "
                                  "of the controller at 1 Hz; the 14-bit count wraps"));
  EXPECT_THAT(lines[0], HasSubstr("raise --ecs-rate to at least 2 Hz"));
  EXPECT_TRUE(EncoderReadingWarnings(Reading(2.0, std::nullopt)).empty());
  // A plant of unknown speed: only the history is checked.
  EncoderReading unknown = Reading(1.0, std::nullopt);
  unknown.top_counts_per_s.reset();
  EXPECT_TRUE(EncoderReadingWarnings(unknown).empty());
}

}  // namespace
}  // namespace hiltwin::app
