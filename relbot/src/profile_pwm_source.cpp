// An input profile played into the PWM reader (profile_pwm_source.h).
#include "hiltwin/relbot/profile_pwm_source.h"

#include <algorithm>
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

// The last frame counted in integers: frame * period stays at or below 2^51 ns (period > 0).
constexpr std::int64_t LastIntegerFrame(std::int64_t period_ns) {
  return kIntegerFramesBelowNs / period_ns;
}

}  // namespace

ProfilePwmSource::ProfilePwmSource(const InputProfile& profile, double controller_rate_hz,
                                   double twin_rate_hz) noexcept
    : profile_(profile),
      controller_rate_hz_(controller_rate_hz),
      twin_rate_hz_(twin_rate_hz),
      period_ns_(kernel_glue::PeriodNsFromRateHz(twin_rate_hz)),
      twin_period_ns_(static_cast<double>(period_ns_)),
      last_sample_(std::numeric_limits<double>::quiet_NaN()),
      ranges_(period_ns_ > 0 && controller_rate_hz > 0.0 && twin_rate_hz > 0.0 &&
              std::isfinite(controller_rate_hz) && std::isfinite(twin_rate_hz)),
      frames_per_sample_(ranges_ ? twin_rate_hz / controller_rate_hz : 0.0),
      last_frame_(ranges_ ? static_cast<double>(LastIntegerFrame(period_ns_)) : 0.0) {}

double ProfilePwmSource::FrameOf(std::int64_t t_ns) const noexcept {
  if (t_ns < 0) return 0.0;
  if (t_ns < kIntegerFramesBelowNs && period_ns_ > 0) {
    const std::int64_t frame = (2 * t_ns + period_ns_) / (2 * period_ns_);  // rounds to nearest
    return static_cast<double>(frame);
  }
  return std::round(static_cast<double>(t_ns) / twin_period_ns_);
}

void ProfilePwmSource::Resample(std::int64_t t_ns) noexcept {
  // Sample-and-hold at the controller's rate: the duty the ECS last wrote, on the frame grid.
  // A player going forward frame by frame lands in the frame the held range ended at, whose
  // sample was found with that end.
  const double sample = t_ns >= held_until_ns_ && t_ns < next_frame_end_ns_
                            ? next_sample_
                            : SampleOf(FrameOf(t_ns));
  if (!(sample == last_sample_)) {
    last_duty_ = profile_.At(sample / controller_rate_hz_, cursor_);
    last_sample_ = sample;
  }
  held_.fill(0.0);
  held_[kLeftChannel] = last_duty_.left;
  held_[kRightChannel] = last_duty_.right;
  held_from_ns_ = t_ns;
  HoldUntilNextSample(sample, t_ns);
}

void ProfilePwmSource::HoldUntilNextSample(double sample, std::int64_t t_ns) noexcept {
  // Outside the integer frames, or for rates no sample grid is made of, the range stays
  // empty and every call looks up again (as every call did before the range was kept).
  held_until_ns_ = t_ns;
  next_frame_end_ns_ = t_ns;
  if (!ranges_ || t_ns < 0 || t_ns >= kIntegerFramesBelowNs || !(sample < 0x1p52)) return;
  // The first frame f with SampleOf(f) >= sample + 1, i.e. f * c / r >= sample + 1 in the
  // contract's doubles: estimated, then settled by that very test (monotonic in f).
  const double next = sample + 1.0;
  double frame = std::min(std::trunc(next * frames_per_sample_), last_frame_);
  while (frame > 0.0 && FrameRatio(frame - 1.0) >= next) frame -= 1.0;
  double ratio = FrameRatio(frame);
  while (!(ratio >= next)) {
    if (frame >= last_frame_) {
      held_until_ns_ = kIntegerFramesBelowNs;
      return;
    }
    frame += 1.0;
    ratio = FrameRatio(frame);
  }
  // FrameOf(t) = (2t + P) div 2P >= f  <=>  t >= f * P - floor(P / 2).
  const std::int64_t first_ns = static_cast<std::int64_t>(frame) * period_ns_ - period_ns_ / 2;
  if (first_ns <= t_ns) return;  // cannot be (t_ns reads an earlier sample): stay empty
  held_until_ns_ = first_ns;
  next_frame_end_ns_ = std::min(first_ns + period_ns_, kIntegerFramesBelowNs);
  next_sample_ = std::floor(ratio);
}

}  // namespace hiltwin::app
