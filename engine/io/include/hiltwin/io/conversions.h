#pragma once
/// Signal conversions between the models and the FPGA (thesis §6.5.1 and appendix G), in one
/// place: PWM value <-> duty, wheel metres <-> encoder counts, absolute <-> relative encoder
/// position, and the PWM reader's quantisation. All noexcept and allocation-free.

#include <cstdint>

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
[[nodiscard]] double PwmToDuty(std::int32_t pwm_value) noexcept;
/// Signed PWM value <-> frame word (magnitude + direction bit).
[[nodiscard]] PwmWord PwmWordFromValue(std::int32_t pwm_value, bool pin = false) noexcept;
[[nodiscard]] std::int32_t PwmValueFromWord(const PwmWord& word) noexcept;

/// What the twin's PWM reader measures for an input of `duty` (thesis §2.2.2): the high time in
/// clocks of a 4096-clock period, halved into an 11-bit value (so 2048 saturates at 2047), with
/// the sign from the direction pin.
[[nodiscard]] std::int32_t PwmReaderValue(double duty) noexcept;

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
/// results are clamped to ±kMaxAbsCounts.
[[nodiscard]] std::int64_t ValueToCounts(double value, double counts_per_unit) noexcept;

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
                                          std::int32_t resolution = kEncoderResolution) noexcept;

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
