// An input profile played into the PWM reader (profile_pwm_source.h).
#include "hiltwin/relbot/profile_pwm_source.h"

#include <cmath>
#include <limits>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                                   double twin_rate_hz) noexcept
    : profile_(profile),
      controller_rate_hz_(controller_rate_hz),
      twin_rate_hz_(twin_rate_hz),
      twin_period_ns_(static_cast<double>(kernel_glue::PeriodNsFromRateHz(twin_rate_hz))),
      last_sample_(std::numeric_limits<double>::quiet_NaN()) {}

void ProfilePwmSource::DutyAt(std::int64_t t_ns,
                              std::array<double, io::kChannels>& duty_out) noexcept {
  // Sample-and-hold at the controller's rate: the duty the ECS last wrote, on the frame grid.
  const double frame = t_ns < 0 ? 0.0 : std::round(static_cast<double>(t_ns) / twin_period_ns_);
  const double sample = std::floor(frame * controller_rate_hz_ / twin_rate_hz_);
  if (!(sample == last_sample_)) {
    last_duty_ = profile_.At(sample / controller_rate_hz_, cursor_);
    last_sample_ = sample;
  }
  duty_out.fill(0.0);
  duty_out[kLeftChannel] = last_duty_.left;
  duty_out[kRightChannel] = last_duty_.right;
}

}  // namespace hiltwin::app
