// An input profile played into the PWM reader (profile_pwm_source.h).
#include "hiltwin/relbot/profile_pwm_source.h"

#include <cmath>
#include <limits>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {

namespace {

// Below 2^51 ns (26 days) round(t / P) in doubles is the integer (2t + P) div 2P: t / P is
// either a half-integer, which the double holds exactly, or at least 1/(2P) away from one,
// farther than the division's rounding error (< t/P * 2^-53 < 1/(4P)), so the double's
// rounding cannot cross a half. Integers spare a division and a call of round() per frame.
constexpr std::int64_t kIntegerFramesBelowNs = std::int64_t{1} << 51;

}  // namespace

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                                   double twin_rate_hz) noexcept
    : profile_(profile),
      controller_rate_hz_(controller_rate_hz),
      twin_rate_hz_(twin_rate_hz),
      period_ns_(kernel_glue::PeriodNsFromRateHz(twin_rate_hz)),
      twin_period_ns_(static_cast<double>(period_ns_)),
      last_sample_(std::numeric_limits<double>::quiet_NaN()) {}

double ProfilePwmSource::FrameOf(std::int64_t t_ns) const noexcept {
  if (t_ns < 0) return 0.0;
  if (t_ns < kIntegerFramesBelowNs && period_ns_ > 0) {
    const std::int64_t frame = (2 * t_ns + period_ns_) / (2 * period_ns_);  // rounds to nearest
    return static_cast<double>(frame);
  }
  return std::round(static_cast<double>(t_ns) / twin_period_ns_);
}

void ProfilePwmSource::DutyAt(std::int64_t t_ns,
                              std::array<double, io::kChannels>& duty_out) noexcept {
  // Sample-and-hold at the controller's rate: the duty the ECS last wrote, on the frame grid.
  const double sample = std::floor(FrameOf(t_ns) * controller_rate_hz_ / twin_rate_hz_);
  if (!(sample == last_sample_)) {
    last_duty_ = profile_.At(sample / controller_rate_hz_, cursor_);
    last_sample_ = sample;
  }
  duty_out.fill(0.0);
  duty_out[kLeftChannel] = last_duty_.left;
  duty_out[kRightChannel] = last_duty_.right;
}

}  // namespace hiltwin::app
