// The LTTng channel's size for a loop rate: the arithmetic of ChannelSizeFor, by hand.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include "hiltwin/trace_capture/lttng_session.h"

namespace {

using hiltwin::trace_capture::ChannelSizeFor;
using hiltwin::trace_capture::kCycleEventBytes;
using hiltwin::trace_capture::LttngChannelSize;

constexpr std::uint64_t kKiB = 1024;

// Seconds of events at `rate_hz` the whole buffer (all sub-buffers) holds.
double SecondsHeld(const LttngChannelSize& size, double rate_hz) {
  return static_cast<double>(size.subbuf_bytes * size.subbuf_count) /
         (rate_hz * static_cast<double>(kCycleEventBytes));
}

TEST(ChannelSize, OneKilohertzTakesTheFloorOf256KiB) {
  // 1000/s * 80 B * 0.1 s = 8000 B, far below the 256 KiB floor.
  const LttngChannelSize size = ChannelSizeFor(1000.0);
  EXPECT_EQ(size.subbuf_bytes, 256 * kKiB);
  EXPECT_EQ(size.subbuf_count, 8U);
  EXPECT_EQ(size.switch_timer_us, 100'000U);
}

TEST(ChannelSize, TwentyKilohertzHoldsMoreThanASecond) {
  // 20000/s * 80 B * 0.1 s = 160000 B -> the next power of two is 262144 (256 KiB); 8 of them
  // are 2 MiB, 2097152 / 1.6 MB/s = 1.31 s of events between consumer visits.
  const LttngChannelSize size = ChannelSizeFor(20'000.0);
  EXPECT_EQ(size.subbuf_bytes, 262'144U);
  EXPECT_EQ(size.subbuf_count, 8U);
  EXPECT_NEAR(SecondsHeld(size, 20'000.0), 1.31, 0.01);
  // The switch timer hands sub-buffers over far more often than the buffer fills.
  EXPECT_LT(static_cast<double>(size.switch_timer_us) * 1e-6, SecondsHeld(size, 20'000.0) / 4);
}

TEST(ChannelSize, FortyKilohertzRoundsUpToThe512KiBPowerOfTwo) {
  // 320000 B per 0.1 s: above 256 KiB, so 512 KiB.
  EXPECT_EQ(ChannelSizeFor(40'000.0).subbuf_bytes, 512 * kKiB);
}

TEST(ChannelSize, HundredKilohertzTakes1MiBSubBuffers) {
  // 100000/s * 80 B * 0.1 s = 800000 B -> 1048576 (1 MiB); 8 MiB hold 1.05 s.
  const LttngChannelSize size = ChannelSizeFor(100'000.0);
  EXPECT_EQ(size.subbuf_bytes, 1024 * kKiB);
  EXPECT_EQ(size.subbuf_count, 8U);
  EXPECT_NEAR(SecondsHeld(size, 100'000.0), 1.05, 0.01);
}

TEST(ChannelSize, EveryRateGetsPowersOfTwoAndAtLeastEightTenthsOfASecond) {
  for (double rate_hz = 100.0; rate_hz <= 1e6; rate_hz *= 1.7) {
    const LttngChannelSize size = ChannelSizeFor(rate_hz);
    EXPECT_TRUE(std::has_single_bit(size.subbuf_bytes)) << rate_hz;
    EXPECT_TRUE(std::has_single_bit(size.subbuf_count)) << rate_hz;
    EXPECT_GE(SecondsHeld(size, rate_hz), 0.8) << rate_hz;
  }
}

TEST(ChannelSize, ANonsenseRateGetsTheFloor) {
  for (double rate_hz : {0.0, -5.0, std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
    EXPECT_EQ(ChannelSizeFor(rate_hz).subbuf_bytes, 256 * kKiB) << rate_hz;
  }
}

}  // namespace
