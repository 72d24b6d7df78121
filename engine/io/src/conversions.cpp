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

double PwmToDuty(std::int32_t pwm_value) noexcept {
  return static_cast<double>(pwm_value) / kPwmResolution;
}

PwmWord PwmWordFromValue(std::int32_t pwm_value, bool pin) noexcept {
  std::int32_t magnitude = pwm_value < 0 ? -pwm_value : pwm_value;
  if (magnitude > kPwmMagnitudeMax) magnitude = kPwmMagnitudeMax;
  return PwmWord{static_cast<std::uint16_t>(magnitude), pwm_value < 0, pin};
}

std::int32_t PwmValueFromWord(const PwmWord& word) noexcept {
  const auto magnitude = static_cast<std::int32_t>(word.magnitude);
  return word.negative ? -magnitude : magnitude;
}

std::int32_t PwmReaderValue(double duty) noexcept {
  if (std::isnan(duty)) return 0;
  double magnitude = std::fabs(duty);
  if (magnitude > 1.0) magnitude = 1.0;
  // High time in whole clocks of the 12-bit period counter, then the reader's divide by two.
  const auto high_clocks = static_cast<std::int32_t>(std::nearbyint(magnitude * kPwmPeriodClocks));
  std::int32_t value = high_clocks / 2;
  if (value > 2047) value = 2047;  // 11-bit register
  return duty < 0.0 ? -value : value;
}

double CountsPerMetre(const WheelGeometry& geometry) noexcept {
  return geometry.motor_rev_per_wheel_rev * geometry.counts_per_motor_rev /
         (2.0 * std::numbers::pi * geometry.wheel_radius_m);
}

std::int64_t MetresToCounts(double metres, const WheelGeometry& geometry) noexcept {
  return ValueToCounts(metres, CountsPerMetre(geometry));
}

std::int64_t ValueToCounts(double value, double counts_per_unit) noexcept {
  const double counts = value * counts_per_unit;
  if (!std::isfinite(counts)) return 0;
  if (counts >= kMaxAbsCounts) return static_cast<std::int64_t>(kMaxAbsCounts);
  if (counts <= -kMaxAbsCounts) return -static_cast<std::int64_t>(kMaxAbsCounts);
  return static_cast<std::int64_t>(std::floor(counts));
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
