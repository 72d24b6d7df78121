#pragma once
/// The ECS's discrete position PID for one wheel (thesis §7.2, appendix E): setpoint and
/// measured wheel travel in metres in, motor duty out. Derivative on the measurement through a
/// first-order filter, integral with conditional integration (anti-windup), output saturated
/// to ±duty_limit. Step() is the real-time path: noexcept, allocation-free, O(1).
///
/// Discretisation at the controller period T (s), error e = r - y:
///   P_k = kp · e_k
///   D_k = a · D_{k-1} - (kd / (Tf + T)) · (y_k - y_{k-1}),  a = Tf / (Tf + T)
///         (backward Euler of -kd·s/(Tf·s + 1) on y: stable for every Tf >= 0, Tf = 0 is the
///         plain backward difference)
///   I_k = I_{k-1} + ki · T · e_k, kept at I_{k-1} while the output is saturated and e_k would
///         drive it further into saturation
///   u_k = clamp(P_k + I_k + D_k, ±duty_limit)
///
/// Why the derivative acts on the measurement: a setpoint step (a CSV profile may contain one)
/// then moves the output by kp·Δr only, not by a kd/T spike ("derivative kick"). Why the filter:
/// one encoder count (0.0785 mm at the default parameters) in one 1 ms period is a 0.0785 m/s
/// velocity step; unfiltered, kd turns every count into a duty spike.
///
/// Why conditional integration rather than back-calculation: it needs no further tuning
/// constant (back-calculation's tracking time), and it never lets the integral grow while the
/// actuator cannot follow, so after a saturation (a blocked wheel, a setpoint step) the output
/// leaves the limit as soon as the error turns. The integral itself is not clamped to the duty
/// limit: with the derivative on the measurement, driving at speed v leaves a steady D = -kd·v
/// (about -1.9 duty at 0.625 m/s with the default gains) that only the integral cancels, so
/// the integral must be free to exceed the limit while P + I + D stays within it. Its bound is
/// the conditional rule: it stops growing the moment the output saturates in its direction.

#include <cstdint>

namespace hiltwin::app {

/// PID gains and output limit, in the units their names carry. Duty is a fraction of the
/// supply voltage in [-1, 1]; positions are wheel travel in metres.
struct PidGains {
  double kp_duty_per_m = 0.0;        ///< proportional: duty per metre of error
  double ki_duty_per_m_s = 0.0;      ///< integral: duty per (metre · second) of error
  double kd_duty_s_per_m = 0.0;      ///< derivative: duty per (metre / second) of travel speed
  double derivative_filter_s = 0.0;  ///< time constant Tf of the derivative's low-pass
  double duty_limit = 1.0;           ///< |output| <= duty_limit, in (0, 1]
};

/// What one step computed (for logs and tests).
struct PidTerms {
  double p_duty = 0.0;
  double i_duty = 0.0;  ///< the integral after this step
  double d_duty = 0.0;
  double output_duty = 0.0;       ///< after saturation
  bool saturated = false;         ///< P + I + D exceeded ±duty_limit
  bool integration_held = false;  ///< anti-windup held the integral this step
};

/// One wheel's position controller.
class PositionPid {
 public:
  /// `gains` must be valid (ValidateEcsGains) and `period_s` finite and > 0; the coefficients
  /// of the discretisation are computed here, once.
  PositionPid(const PidGains& gains, double period_s) noexcept;

  /// Clears the integral and the derivative and takes `measured_m` as the previous
  /// measurement, so the next Step sees no derivative kick whatever the wheel's position.
  void Reset(double measured_m) noexcept;

  /// One controller period: returns the duty to apply. Before the first Reset the first Step
  /// resets on its own measurement. A non-finite setpoint or measurement returns 0 (motor
  /// off) and leaves the controller's state untouched.
  double Step(double setpoint_m, double measured_m) noexcept;

  [[nodiscard]] const PidTerms& last() const noexcept { return last_; }
  [[nodiscard]] double integral_duty() const noexcept { return integral_duty_; }
  [[nodiscard]] const PidGains& gains() const noexcept { return gains_; }
  [[nodiscard]] double period_s() const noexcept { return period_s_; }

 private:
  PidGains gains_;
  double period_s_;
  double integral_per_step_duty_per_m_;  ///< ki · T
  double derivative_pole_;               ///< a = Tf / (Tf + T)
  double derivative_gain_duty_per_m_;    ///< kd / (Tf + T)
  double integral_duty_ = 0.0;
  double derivative_duty_ = 0.0;
  double previous_measured_m_ = 0.0;
  bool primed_ = false;
  PidTerms last_{};
};

}  // namespace hiltwin::app
