#include "hiltwin/relbot/profile_pwm_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {
namespace {

// The duty frame `t_ns` reads, computed from scratch as the source's contract says: the
// controller's last sample on the frame grid, looked up in the profile without a cursor.
Duty FromScratch(const InputProfile& profile, double controller_hz, double twin_hz,
                 std::int64_t t_ns) {
  const auto period_ns = static_cast<double>(kernel_glue::PeriodNsFromRateHz(twin_hz));
  const double frame = t_ns < 0 ? 0.0 : std::round(static_cast<double>(t_ns) / period_ns);
  const double sample = std::floor(frame * controller_hz / twin_hz);
  return profile.At(sample / controller_hz);
}

// The source keeps the last sample's duty and a cursor into the profile: what it plays must
// still be the contract's duty, bit for bit, frame after frame, after a jump back to the
// start (a board re-initialised) and at random times.
TEST(ProfilePwmSource, PlaysTheControllersSamplesBitForBitInAnyOrder) {
  const InputProfile profile = OpenLoopProfile();
  for (const auto& rates_hz :
       {std::pair{1000.0, 4000.0}, std::pair{1000.0, 7000.0}, std::pair{250.0, 4000.0},
        std::pair{4000.0, 4000.0}}) {
    // Named copies, not a structured binding: the lambdas below capture them (C++20 allows
    // capturing a binding; clang-tidy's clang 14 does not).
    const double controller_hz = rates_hz.first;
    const double twin_hz = rates_hz.second;
    ProfilePwmSource source(profile, controller_hz, twin_hz);
    const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(twin_hz);
    std::array<double, io::kChannels> duty{};
    const auto expect_plays = [&](std::int64_t t_ns) {
      duty.fill(9.0);
      source.DutyAt(t_ns, duty);
      const Duty expected = FromScratch(profile, controller_hz, twin_hz, t_ns);
      ASSERT_EQ(duty[kLeftChannel], expected.left) << t_ns << " ns at " << twin_hz << " Hz";
      ASSERT_EQ(duty[kRightChannel], expected.right) << t_ns << " ns at " << twin_hz << " Hz";
      for (std::size_t c = 0; c < io::kChannels; ++c) {
        if (c != kLeftChannel && c != kRightChannel) {
          ASSERT_EQ(duty[c], 0.0);
        }
      }
    };
    const auto frames = static_cast<std::int64_t>(80.0 * twin_hz);  // over two repetitions
    for (std::int64_t k = 0; k < frames; k += 1) expect_plays(k * period_ns);
    expect_plays(0);
    expect_plays(-5);
    std::uint64_t seed = 99;
    for (int k = 0; k < 5000; ++k) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      expect_plays(static_cast<std::int64_t>(seed >> (30 + k % 24)));  // ns to months, any ns
    }
    // Half a period either side of a frame, and where the frame's integer arithmetic hands
    // over to doubles (2^51 ns, 26 days).
    for (const std::int64_t base : {std::int64_t{0}, std::int64_t{1} << 40,
                                    (std::int64_t{1} << 51) - period_ns, std::int64_t{1} << 51,
                                    std::int64_t{1} << 60}) {
      for (std::int64_t k = 0; k < 9; ++k) {
        const std::int64_t frame_start = base - base % period_ns + k * period_ns;
        for (const std::int64_t offset : {period_ns / 2 - 1, period_ns / 2, period_ns / 2 + 1,
                                          period_ns - 1}) {
          expect_plays(frame_start + offset);
        }
      }
    }
  }
}

// The source plays a held sample again for any time in the range it knows the sample covers
// (up to the first nanosecond of the next sample's first frame): every nanosecond around
// those boundaries, times off the frame grid walked forward, and rate pairs whose samples
// change every frame or at uneven frames must still read the contract's duty.
TEST(ProfilePwmSource, AHeldSampleEndsAtTheNanosecondTheNextOneStarts) {
  const InputProfile profile = OpenLoopProfile();
  for (const auto& rates_hz :
       {std::pair{1000.0, 4000.0}, std::pair{1000.0, 7000.0}, std::pair{3000.0, 7000.0},
        std::pair{333.0, 4000.0}, std::pair{5000.0, 4000.0}, std::pair{50000.0, 3.0},
        std::pair{1.0, 50000.0}, std::pair{4000.0, 4000.0}}) {
    // Named copies for the lambda to capture (see the test above).
    const double controller_hz = rates_hz.first;
    const double twin_hz = rates_hz.second;
    ProfilePwmSource source(profile, controller_hz, twin_hz);
    const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(twin_hz);
    std::array<double, io::kChannels> duty{};
    const auto expect_plays = [&](std::int64_t t_ns) {
      source.DutyAt(t_ns, duty);
      const Duty expected = FromScratch(profile, controller_hz, twin_hz, t_ns);
      ASSERT_EQ(duty[kLeftChannel], expected.left) << t_ns << " ns, " << controller_hz << " Hz";
      ASSERT_EQ(duty[kRightChannel], expected.right) << t_ns << " ns, " << controller_hz;
    };
    // Every nanosecond across the half-period edges of the first frames and of frames
    // around 1.7 s (on a ramp of the profile), forward.
    for (const std::int64_t first_frame :
         {std::int64_t{0}, std::int64_t{1'700'000'000} / period_ns}) {
      for (std::int64_t f = first_frame; f < first_frame + 12; ++f) {
        const std::int64_t edge = f * period_ns + period_ns / 2;
        for (std::int64_t t = edge - 3; t <= edge + 3; ++t) expect_plays(t);
      }
    }
    // Off the grid, forward over 40 s (a step of 37.129 us against any period).
    for (std::int64_t t = 0; t < 40'000'000'000; t += 37'129) expect_plays(t);
    // Up to where frames leave integers, and across it.
    const std::int64_t top = std::int64_t{1} << 51;
    for (std::int64_t t = top - 4 * period_ns; t < top + 2 * period_ns; t += period_ns / 3 + 1) {
      expect_plays(t);
    }
  }
}

}  // namespace
}  // namespace hiltwin::app
