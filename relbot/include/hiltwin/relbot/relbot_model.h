#pragma once
/// Explicit RELbot plant model after thesis ch. 6 (equations in docs/relbot-model.md): two
/// drivetrains (DC motor without inductance, gearbox, one equivalent inertia each), a
/// wheel-to-body spring-damper in X per wheel, a rigid body split into X, Y and yaw parts, and
/// castor friction. Inputs: left and right duty in [-1, 1]. Outputs: wheel positions (m) and
/// the centre-of-mass pose in the world frame. Step() is the real-time path: noexcept,
/// fixed-size Eigen, no allocation.

#include <Eigen/Core>
#include <complex>
#include <cstdint>
#include <vector>

#include "hiltwin/relbot/integrator.h"
#include "hiltwin/relbot/relbot_params.h"

namespace hiltwin::app {

/// Number of continuous states.
inline constexpr int kRelbotStateSize = 12;

/// Continuous state vector; see RelbotStateIndex for the meaning of each entry.
using RelbotState = Eigen::Matrix<double, kRelbotStateSize, 1>;

/// Position of each quantity in RelbotState (body frame: X forward, Y left, origin at CoM).
namespace relbot_state {
inline constexpr int kWheelSpeedLeftRadPerS = 0;   ///< wheel angular velocity, left
inline constexpr int kWheelSpeedRightRadPerS = 1;  ///< wheel angular velocity, right
inline constexpr int kWheelPositionLeftM = 2;      ///< wheel travel r*phi, left (output)
inline constexpr int kWheelPositionRightM = 3;     ///< wheel travel r*phi, right (output)
inline constexpr int kSpringDeflectionLeftM = 4;   ///< wheel-to-body spring, left
inline constexpr int kSpringDeflectionRightM = 5;  ///< wheel-to-body spring, right
inline constexpr int kBodyVelocityXMPerS = 6;      ///< body velocity along body X
inline constexpr int kBodyVelocityYMPerS = 7;      ///< body velocity along body Y (side slip)
inline constexpr int kYawRateRadPerS = 8;          ///< body rotation rate about Z
inline constexpr int kWorldXM = 9;                 ///< CoM x in the world frame
inline constexpr int kWorldYM = 10;                ///< CoM y in the world frame
inline constexpr int kHeadingRad = 11;             ///< heading theta (0 = world X), CCW +
}  // namespace relbot_state

/// Model outputs.
struct RelbotOutputs {
  double wheel_left_m = 0.0;   ///< left wheel travel (what its encoder measures, in metres)
  double wheel_right_m = 0.0;  ///< right wheel travel
  double x_m = 0.0;            ///< centre of mass, world frame
  double y_m = 0.0;            ///< centre of mass, world frame
  double theta_rad = 0.0;      ///< heading, world frame, unwrapped
};

/// Constants of the equations, computed once from RelbotParams so the derivative does no
/// divisions by parameters.
struct RelbotCoefficients {
  double supply_voltage_v = 0.0;
  double drive_per_volt = 0.0;        ///< N k_t / (R J_eq)            [rad/s^2/V]
  double drive_damping_per_s = 0.0;   ///< N^2 (k_t k_e / R + b_m) / J_eq [1/s]
  double force_to_wheel_accel = 0.0;  ///< r / J_eq                    [rad/s^2/N]
  double wheel_radius_m = 0.0;
  double half_track_m = 0.0;
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
  double lateral_damping_n_s_per_m = 0.0;
  double inv_body_mass_per_kg = 0.0;
  double inv_yaw_inertia_per_kg_m2 = 0.0;
  double castor_offset_m = 0.0;
  double castor_viscous_n_s_per_m = 0.0;
  double castor_coulomb_n = 0.0;
  double castor_smoothing_sq_m2_per_s2 = 0.0;
};

/// Derives the coefficients; params must be valid (ValidateRelbotParams).
[[nodiscard]] RelbotCoefficients MakeRelbotCoefficients(const RelbotParams& params) noexcept;

/// Equivalent inertia of one drivetrain seen at the wheel: N^2 J_rotor + J_wheel + m_wheel r^2.
[[nodiscard]] double EquivalentWheelInertiaKgM2(const RelbotParams& params) noexcept;

/// Duty as the drivers apply it: clamped to [-1, 1]; NaN becomes 0 (motor off).
[[nodiscard]] double SaturateDuty(double duty) noexcept;

/// The model's equations, dx/dt = f(x, u): the one place they are written. Used by every
/// integrator of RelbotModel and by the Boost.Odeint reference. `duty_*` must be saturated.
void RelbotDerivative(const RelbotCoefficients& c, const RelbotState& x, double duty_left,
                      double duty_right, RelbotState& dxdt) noexcept;

/// Outputs read from a state.
[[nodiscard]] RelbotOutputs OutputsOf(const RelbotState& x) noexcept;

/// Eigenvalues (1/s) of the model's Jacobian at rest with zero duty. At rest the castor's
/// smoothed Coulomb friction is steepest, so these are the fastest modes the integrator meets.
[[nodiscard]] std::vector<std::complex<double>> RelbotModesAtRest(const RelbotCoefficients& c);

/// Largest fixed step (s) at which `integrator` integrates the RELbot stably.
[[nodiscard]] double RelbotMaxStableStepS(const RelbotParams& params, Integrator integrator);

/// The heading's cosine and sine at the heading whose bits are `heading_bits`; starts at
/// heading 0, where both are exact.
struct RelbotHeadingTrigCache {
  std::uint64_t heading_bits = 0;
  double cos_h = 1.0;
  double sin_h = 0.0;
};

/// The RELbot plant at a fixed step with a chosen explicit integrator.
class RelbotModel {
 public:
  using State = RelbotState;

  /// Validates params (throws ConfigError) and step_s (finite, > 0, <= 0.1 s, and no longer
  /// than RelbotMaxStableStepS: a step that makes the model diverge is refused with the
  /// reason, not discovered as NaN mid-run). Starts at rest at the world origin, heading 0.
  RelbotModel(const RelbotParams& params, Integrator integrator = Integrator::kRk4,
              double step_s = 2.5e-4);

  /// Back to rest at the world origin; the step counter restarts.
  void Reset() noexcept;
  /// Advances one step with the duties held over it (saturated by SaturateDuty).
  void Step(double duty_left, double duty_right) noexcept;
  /// Outputs at the current time.
  [[nodiscard]] RelbotOutputs Outputs() const noexcept { return OutputsOf(state_); }
  /// False once any state became NaN or infinite (a diverged model: stop the run).
  /// x * 0 is a zero for every finite x and NaN for NaN and +-Inf, so the sum is NaN exactly
  /// when a state is not finite: one vectorised pass, where allFinite() tests each entry
  /// with a branch of its own (a twelfth of a step).
  [[nodiscard]] bool StateIsFinite() const noexcept { return (state_ * 0.0).sum() == 0.0; }

  [[nodiscard]] const State& state() const noexcept { return state_; }
  /// Replaces the state (tests, restoring a snapshot).
  void set_state(const State& state) noexcept { state_ = state; }
  [[nodiscard]] const RelbotParams& params() const noexcept { return params_; }
  [[nodiscard]] const RelbotCoefficients& coefficients() const noexcept { return coefficients_; }
  [[nodiscard]] Integrator integrator() const noexcept { return integrator_; }
  [[nodiscard]] double step_s() const noexcept { return step_s_; }
  /// Steps taken since construction or Reset().
  [[nodiscard]] std::uint64_t steps() const noexcept { return steps_; }
  /// Model time: steps() * step_s().
  [[nodiscard]] double time_s() const noexcept { return static_cast<double>(steps_) * step_s_; }

 private:
  RelbotParams params_;
  RelbotCoefficients coefficients_;
  Integrator integrator_;
  double step_s_;
  std::uint64_t steps_ = 0;
  State state_ = State::Zero();
  RelbotHeadingTrigCache trig_cache_;  ///< valid for any state: keyed by the heading's bits
};

}  // namespace hiltwin::app
