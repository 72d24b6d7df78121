// An input profile played into the PWM reader (profile_pwm_source.h).
#include "hiltwin/relbot/profile_pwm_source.h"

#include <cmath>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/relbot_channels.h"

namespace hiltwin::app {

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                                   double twin_rate_hz) noexcept
    : profile_(profile),
      controller_rate_hz_(controller_rate_hz),
      twin_rate_hz_(twin_rate_hz),
      twin_period_ns_(static_cast<double>(kernel_glue::PeriodNsFromRateHz(twin_rate_hz))) {}

void ProfilePwmSource::DutyAt(std::int64_t t_ns,
                              std::array<double, io::kChannels>& duty_out) noexcept {
  // Sample-and-hold at the controller's rate: the duty the ECS last wrote, on the frame grid.
  const double frame = t_ns < 0 ? 0.0 : std::round(static_cast<double>(t_ns) / twin_period_ns_);
  const double sample = std::floor(frame * controller_rate_hz_ / twin_rate_hz_);
  const Duty duty = profile_.At(sample / controller_rate_hz_);
  duty_out.fill(0.0);
  duty_out[kLeftChannel] = duty.left;
  duty_out[kRightChannel] = duty.right;
}

}  // namespace hiltwin::app
