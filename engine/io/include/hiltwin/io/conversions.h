#pragma once
/// Signal conversions between the models and the FPGA (thesis §6.5.1 and appendix G), in one
/// place: PWM value <-> duty, wheel metres <-> encoder counts, absolute <-> relative encoder
/// position, and the PWM reader's quantisation. All noexcept and allocation-free.

#include <cstdint>
#include <cmath>

#include "hiltwin/io/frame.h"

namespace hiltwin::io {

/// PWM value of duty 1.0: the generator takes integers in [-2048, 2047] (thesis §6.5.1).
constexpr std::int32_t kPwmResolution = 2048;
constexpr std::int32_t kPwmValueMin = -2048;
constexpr std::int32_t kPwmValueMax = 2047;
/// Encoder counts per turn of the 14-bit relative position (thesis appendix G: [-8192, 8191]).
constexpr std::int32_t kEncoderResolution = 16384;
/// The FPGA clock (thesis §2.2.2).
constexpr std::int64_t kFpgaClockHz = 100'000'000;
constexpr std::int64_t kNsPerFpgaClock = 10;
/// The PWM reader's 12-bit period counter: 4096 clocks per PWM period (24.4 kHz).
constexpr std::int32_t kPwmPeriodClocks = 4096;

/// Duty in [-1, 1] to a PWM value: duty · 2048 rounded to nearest, clamped to
/// [-2048, 2047]. NaN maps to 0 so a broken model output cannot drive the motor.
[[nodiscard]] std::int32_t DutyToPwm(double duty) noexcept;
/// PWM value to duty: value / 2048 (appendix G, `channel / PWM_RESOLUTION`).
/// The per-cycle conversions are inline: the drivers and the board call them per channel.
[[nodiscard]] inline double PwmToDuty(std::int32_t pwm_value) noexcept {
  return static_cast<double>(pwm_value) / kPwmResolution;
}
/// Signed PWM value <-> frame word (magnitude + direction bit).
[[nodiscard]] inline PwmWord PwmWordFromValue(std::int32_t pwm_value, bool pin = false) noexcept {
  std::int32_t magnitude = pwm_value < 0 ? -pwm_value : pwm_value;
  if (magnitude > kPwmMagnitudeMax) magnitude = kPwmMagnitudeMax;
  return PwmWord{static_cast<std::uint16_t>(magnitude), pwm_value < 0, pin};
}
[[nodiscard]] inline std::int32_t PwmValueFromWord(const PwmWord& word) noexcept {
  const auto magnitude = static_cast<std::int32_t>(word.magnitude);
  return word.negative ? -magnitude : magnitude;
}

/// What the twin's PWM reader measures for an input of `duty` (thesis §2.2.2): the high time in
/// clocks of a 4096-clock period, halved into an 11-bit value (so 2048 saturates at 2047), with
/// the sign from the direction pin.
[[nodiscard]] inline std::int32_t PwmReaderValue(double duty) noexcept {
  if (std::isnan(duty)) return 0;
  double magnitude = std::fabs(duty);
  if (magnitude > 1.0) magnitude = 1.0;
  // High time in whole clocks of the 12-bit period counter, rounded to nearest even as
  // std::nearbyint does in the default rounding mode: for 0 <= x <= 4096, x + 2^52 has no
  // fraction bits left, so the addition rounds x exactly so (without the libm call).
  constexpr double kRound = 4503599627370496.0;  // 2^52
  const double high = (magnitude * kPwmPeriodClocks + kRound) - kRound;
  const auto high_clocks = static_cast<std::int32_t>(high);
  std::int32_t value = high_clocks / 2;
  if (value > 2047) value = 2047;  // 11-bit register
  return duty < 0.0 ? -value : value;
}

/// Wheel geometry for metres <-> counts: counts = metres · N · CPR / (2π · r). metres / r is
/// wheel radians; the motor turns N times per wheel turn, so motor radians = wheel radians · N;
/// the encoder is on the motor shaft, so counts = motor radians / (2π) · CPR. Thesis appendix G's
/// `metres / wheel_radius / gear_ratio * encoder_counts_per_rotation` differs: it divides by the
/// ratio and has no 2π (docs/relbot-model.md, "Encoder counts differ from thesis appendix G").
struct WheelGeometry {
  double wheel_radius_m = 0.05;
  double motor_rev_per_wheel_rev = 1.0;     ///< gearbox reduction N
  double counts_per_motor_rev = 4096.0;     ///< encoder counts per motor turn (quadrature, 4x)
};

/// Encoder counts per metre of wheel travel for `geometry`.
[[nodiscard]] double CountsPerMetre(const WheelGeometry& geometry) noexcept;

/// The largest magnitude of absolute encoder counts: ValueToCounts clamps to ±kMaxAbsCounts.
constexpr double kMaxAbsCounts = 4.611686018427387904e18;  // 2^62

/// A plant output to absolute encoder counts: floor(value · counts_per_unit), the one rule
/// every encoder channel uses (plant maps, plant/plant_map.h). Non-finite results give 0;
/// results are clamped to ±kMaxAbsCounts. Inline: the twin's task calls it per channel and
/// cycle.
[[nodiscard]] inline std::int64_t ValueToCounts(double value, double counts_per_unit) noexcept {
  const double counts = value * counts_per_unit;
  if (!std::isfinite(counts)) return 0;
  if (counts >= kMaxAbsCounts) return static_cast<std::int64_t>(kMaxAbsCounts);
  if (counts <= -kMaxAbsCounts) return -static_cast<std::int64_t>(kMaxAbsCounts);
  // std::floor without the libm call: |counts| < 2^62, so the truncation is exact as an
  // integer and as a double; one less when it rounded a negative fraction up.
  const auto truncated = static_cast<std::int64_t>(counts);
  return counts < static_cast<double>(truncated) ? truncated - 1 : truncated;
}

/// Wheel travel in metres to absolute encoder counts, floored: appendix G truncates towards
/// zero, which makes the count around zero two counts wide; flooring keeps every count equal.
/// Non-finite inputs give 0; results are clamped to ±2^62.
[[nodiscard]] std::int64_t MetresToCounts(double metres, const WheelGeometry& geometry) noexcept;
/// Absolute encoder counts to wheel travel in metres (the inverse, for the ECS and tests).
[[nodiscard]] double CountsToMetres(std::int64_t counts, const WheelGeometry& geometry) noexcept;

/// Absolute position to the relative position in [-resolution/2, resolution/2) (appendix G
/// `calc_value`, without its loops, and for any resolution that is a positive even number;
/// a resolution below 2 gives 0).
[[nodiscard]] std::int32_t WrapToRelative(std::int64_t absolute_counts,
                                          std::int32_t resolution) noexcept;
/// WrapToRelative for the encoders' 14 bits, inline (every channel of every cycle): a mask;
/// unsigned arithmetic wraps by definition, so no input can overflow.
[[nodiscard]] inline std::int32_t WrapToRelative(std::int64_t absolute_counts) noexcept {
  constexpr std::int64_t kHalf = kEncoderResolution / 2;
  constexpr auto kMask = static_cast<std::uint64_t>(kEncoderResolution) - 1U;
  const std::uint64_t shifted =
      (static_cast<std::uint64_t>(absolute_counts) + static_cast<std::uint64_t>(kHalf)) & kMask;
  return static_cast<std::int32_t>(static_cast<std::int64_t>(shifted) - kHalf);
}

/// Rebuilds an absolute position from successive relative readings, assuming the position moved
/// less than half a turn between two readings (the same assumption the encoder emulator makes).
class EncoderUnwrapper {
 public:
  EncoderUnwrapper() noexcept = default;
  explicit EncoderUnwrapper(std::int32_t resolution) noexcept : resolution_(resolution) {}
  /// Feeds one relative reading; returns the absolute position.
  std::int64_t Update(std::int32_t relative_counts) noexcept;
  /// Forgets history: the next reading becomes the absolute position as is.
  void Reset() noexcept { primed_ = false; absolute_ = 0; }
  [[nodiscard]] std::int64_t absolute() const noexcept { return absolute_; }

 private:
  std::int32_t resolution_ = kEncoderResolution;
  std::int32_t last_relative_ = 0;
  std::int64_t absolute_ = 0;
  bool primed_ = false;
};

}  // namespace hiltwin::io
