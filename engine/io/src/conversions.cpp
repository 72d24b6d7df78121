#include "hiltwin/io/conversions.h"

#include <cmath>
#include <numbers>

namespace hiltwin::io {

std::int32_t DutyToPwm(double duty) noexcept {
  if (std::isnan(duty)) return 0;
  const double scaled = std::nearbyint(duty * kPwmResolution);
  if (scaled <= kPwmValueMin) return kPwmValueMin;
  if (scaled >= kPwmValueMax) return kPwmValueMax;
  return static_cast<std::int32_t>(scaled);
}

double CountsPerMetre(const WheelGeometry& geometry) noexcept {
  return geometry.motor_rev_per_wheel_rev * geometry.counts_per_motor_rev /
         (2.0 * std::numbers::pi * geometry.wheel_radius_m);
}

std::int64_t MetresToCounts(double metres, const WheelGeometry& geometry) noexcept {
  return ValueToCounts(metres, CountsPerMetre(geometry));
}

double CountsToMetres(std::int64_t counts, const WheelGeometry& geometry) noexcept {
  return static_cast<double>(counts) / CountsPerMetre(geometry);
}

std::int32_t WrapToRelative(std::int64_t absolute_counts, std::int32_t resolution) noexcept {
  if (resolution < 2) return 0;  // outside the precondition: no position can be represented
  const std::int64_t half = resolution / 2;
  if (resolution > 0 && (resolution & (resolution - 1)) == 0) {
    // Power of two (the usual 16384): a mask instead of a division, on the per-cycle path.
    // Unsigned arithmetic wraps by definition, so no input can overflow.
    const auto mask = static_cast<std::uint64_t>(resolution) - 1U;
    const std::uint64_t shifted = (static_cast<std::uint64_t>(absolute_counts) +
                                   static_cast<std::uint64_t>(half)) & mask;
    return static_cast<std::int32_t>(static_cast<std::int64_t>(shifted) - half);
  }
  // Remainder first, so no intermediate can overflow whatever the input.
  std::int64_t r = absolute_counts % resolution;
  if (r < -half) r += resolution;
  if (r >= half) r -= resolution;
  return static_cast<std::int32_t>(r);
}

std::int64_t EncoderUnwrapper::Update(std::int32_t relative_counts) noexcept {
  if (!primed_) {
    primed_ = true;
    absolute_ = relative_counts;
  } else {
    absolute_ += WrapToRelative(std::int64_t{relative_counts} - last_relative_, resolution_);
  }
  last_relative_ = relative_counts;
  return absolute_;
}

}  // namespace hiltwin::io
