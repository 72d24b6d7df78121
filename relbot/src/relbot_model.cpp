#include "hiltwin/relbot/relbot_model.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>
#include <string>

namespace hiltwin::app {

double EquivalentWheelInertiaKgM2(const RelbotParams& p) noexcept {
  // Thesis §6.3.1: rotor inertia, wheel inertia and wheel mass pulled through the gear and
  // wheel transformers into one I-element, which gives the drivetrain preferred causality.
  const double n = p.gear_ratio_motor_rev_per_wheel_rev;
  return n * n * p.motor_rotor_inertia_kg_m2 + p.wheel_inertia_kg_m2 +
         p.wheel_mass_kg * p.wheel_radius_m * p.wheel_radius_m;
}

RelbotCoefficients MakeRelbotCoefficients(const RelbotParams& p) noexcept {
  const double n = p.gear_ratio_motor_rev_per_wheel_rev;
  const double j_eq = EquivalentWheelInertiaKgM2(p);
  RelbotCoefficients c;
  c.supply_voltage_v = p.supply_voltage_v;
  c.drive_per_volt = n * p.motor_torque_constant_n_m_per_a / (p.motor_resistance_ohm * j_eq);
  c.drive_damping_per_s = n * n *
                          (p.motor_torque_constant_n_m_per_a *
                               p.motor_back_emf_constant_v_s_per_rad / p.motor_resistance_ohm +
                           p.motor_viscous_friction_n_m_s_per_rad) /
                          j_eq;
  c.force_to_wheel_accel = p.wheel_radius_m / j_eq;
  c.wheel_radius_m = p.wheel_radius_m;
  c.half_track_m = 0.5 * p.track_width_m;
  c.stiffness_n_per_m = p.contact_stiffness_n_per_m;
  c.damping_n_s_per_m = p.contact_damping_n_s_per_m;
  c.lateral_damping_n_s_per_m = p.contact_lateral_damping_n_s_per_m;
  c.inv_body_mass_per_kg = 1.0 / p.body_mass_kg;
  c.inv_yaw_inertia_per_kg_m2 = 1.0 / p.body_yaw_inertia_kg_m2;
  c.castor_offset_m = p.castor_offset_m;
  c.castor_viscous_n_s_per_m = p.castor_viscous_friction_n_s_per_m;
  c.castor_coulomb_n = p.castor_coulomb_friction_n;
  c.castor_smoothing_sq_m2_per_s2 =
      p.castor_smoothing_speed_m_per_s * p.castor_smoothing_speed_m_per_s;
  return c;
}

double SaturateDuty(double duty) noexcept {
  if (std::isnan(duty)) return 0.0;  // a corrupt input switches the motor off, never drives it
  return duty > 1.0 ? 1.0 : (duty < -1.0 ? -1.0 : duty);
}

namespace {

/// Cosine and sine of the heading.
struct HeadingTrig {
  double cos_h;
  double sin_h;
};

HeadingTrig TrigOf(double heading) noexcept { return {std::cos(heading), std::sin(heading)}; }

/// Drive acceleration of each drivetrain, drive_per_volt * duty * V: constant while the duties
/// are held over a step, so a step computes it once for all its stages.
struct HeldDrive {
  double left;
  double right;
};

HeldDrive DriveOf(const RelbotCoefficients& c, double duty_left, double duty_right) noexcept {
  // Motor without inductance: current follows voltage (and back-EMF, in the derivative) at once.
  const double volts_l = duty_left * c.supply_voltage_v;
  const double volts_r = duty_right * c.supply_voltage_v;
  return {c.drive_per_volt * volts_l, c.drive_per_volt * volts_r};
}

// The equations, written once for RelbotDerivative and RelbotModel::Step, inlined into each
// stage of a step. `trig(heading)` gives the heading's HeadingTrig: sincos is asked for first so
// that nothing else is live across its call.
template <class Trig>
[[gnu::always_inline]] inline void Derivative(const RelbotCoefficients& c, const HeldDrive& drive,
                                              Trig& trig, const RelbotState& x,
                                              RelbotState& dxdt) noexcept {
  namespace s = relbot_state;
  const HeadingTrig heading = trig(x[s::kHeadingRad]);
  const double wheel_speed_l = x[s::kWheelSpeedLeftRadPerS];
  const double wheel_speed_r = x[s::kWheelSpeedRightRadPerS];
  const double vx = x[s::kBodyVelocityXMPerS];
  const double vy = x[s::kBodyVelocityYMPerS];
  const double yaw_rate = x[s::kYawRateRadPerS];

  // Wheel-to-body spring-damper in X (thesis §6.3.2/§6.3.3): the wheel centre against the body
  // point above it; the left wheel sits at body Y = +track/2, the right at -track/2.
  const double wheel_v_l = c.wheel_radius_m * wheel_speed_l;
  const double wheel_v_r = c.wheel_radius_m * wheel_speed_r;
  const double deflection_rate_l = wheel_v_l - (vx - c.half_track_m * yaw_rate);
  const double deflection_rate_r = wheel_v_r - (vx + c.half_track_m * yaw_rate);
  const double force_l = c.stiffness_n_per_m * x[s::kSpringDeflectionLeftM] +
                         c.damping_n_s_per_m * deflection_rate_l;
  const double force_r = c.stiffness_n_per_m * x[s::kSpringDeflectionRightM] +
                         c.damping_n_s_per_m * deflection_rate_r;

  // Drivetrain: the held drive against back-EMF and viscous friction, and the spring's force.
  const double wheel_accel_l = drive.left - c.drive_damping_per_s * wheel_speed_l -
                               c.force_to_wheel_accel * force_l;
  const double wheel_accel_r = drive.right - c.drive_damping_per_s * wheel_speed_r -
                               c.force_to_wheel_accel * force_r;

  // Castor at body (-offset, 0), swivelling so its friction opposes its velocity: viscous plus
  // Coulomb rolling resistance, the Coulomb part smoothed near standstill so the equations
  // stay continuous (no sign() the fixed-step integrators would chatter on).
  const double castor_vx = vx;
  const double castor_vy = vy - c.castor_offset_m * yaw_rate;
  const double castor_gain =
      c.castor_viscous_n_s_per_m +
      c.castor_coulomb_n / std::sqrt(castor_vx * castor_vx + castor_vy * castor_vy +
                                     c.castor_smoothing_sq_m2_per_s2);
  const double castor_fx = -castor_gain * castor_vx;
  const double castor_fy = -castor_gain * castor_vy;
  const double lateral_f = -c.lateral_damping_n_s_per_m * vy;

  // Rigid body split into X, Y and yaw parts (thesis §6.3.3), written in the body frame, hence
  // the rotating-frame terms yaw_rate*vy and -yaw_rate*vx.
  const double body_ax = (force_l + force_r + castor_fx) * c.inv_body_mass_per_kg + yaw_rate * vy;
  const double body_ay = (lateral_f + castor_fy) * c.inv_body_mass_per_kg - yaw_rate * vx;
  const double yaw_accel = (c.half_track_m * (force_r - force_l) -
                            c.castor_offset_m * castor_fy) *
                           c.inv_yaw_inertia_per_kg_m2;

  dxdt[s::kWheelSpeedLeftRadPerS] = wheel_accel_l;
  dxdt[s::kWheelSpeedRightRadPerS] = wheel_accel_r;
  dxdt[s::kWheelPositionLeftM] = wheel_v_l;
  dxdt[s::kWheelPositionRightM] = wheel_v_r;
  dxdt[s::kSpringDeflectionLeftM] = deflection_rate_l;
  dxdt[s::kSpringDeflectionRightM] = deflection_rate_r;
  dxdt[s::kBodyVelocityXMPerS] = body_ax;
  dxdt[s::kBodyVelocityYMPerS] = body_ay;
  dxdt[s::kYawRateRadPerS] = yaw_accel;
  dxdt[s::kWorldXM] = vx * heading.cos_h - vy * heading.sin_h;
  dxdt[s::kWorldYM] = vx * heading.sin_h + vy * heading.cos_h;
  dxdt[s::kHeadingRad] = yaw_rate;
}

}  // namespace

void RelbotDerivative(const RelbotCoefficients& c, const RelbotState& x, double duty_left,
                      double duty_right, RelbotState& dxdt) noexcept {
  const auto trig = [](double heading) noexcept { return TrigOf(heading); };
  Derivative(c, DriveOf(c, duty_left, duty_right), trig, x, dxdt);
}

RelbotOutputs OutputsOf(const RelbotState& x) noexcept {
  namespace s = relbot_state;
  return RelbotOutputs{x[s::kWheelPositionLeftM], x[s::kWheelPositionRightM], x[s::kWorldXM],
                       x[s::kWorldYM], x[s::kHeadingRad]};
}

std::vector<std::complex<double>> RelbotModesAtRest(const RelbotCoefficients& c) {
  // Central differences of f around rest; each state's scale is O(1), so 1e-6 is well
  // inside the linear range and far above rounding.
  constexpr double kDelta = 1e-6;
  Eigen::Matrix<double, kRelbotStateSize, kRelbotStateSize> jacobian;
  for (int i = 0; i < kRelbotStateSize; ++i) {
    RelbotState up = RelbotState::Zero();
    RelbotState down = RelbotState::Zero();
    up[i] = kDelta;
    down[i] = -kDelta;
    RelbotState f_up;
    RelbotState f_down;
    RelbotDerivative(c, up, 0.0, 0.0, f_up);
    RelbotDerivative(c, down, 0.0, 0.0, f_down);
    jacobian.col(i) = (f_up - f_down) / (2.0 * kDelta);
  }
  const Eigen::EigenSolver<decltype(jacobian)> solver(jacobian, false);
  const auto& values = solver.eigenvalues();
  return {values.data(), values.data() + values.size()};
}

double RelbotMaxStableStepS(const RelbotParams& params, Integrator integrator) {
  return MaxStableStepS(integrator, RelbotModesAtRest(MakeRelbotCoefficients(params)));
}

namespace {

void CheckStable(const RelbotCoefficients& c, Integrator integrator, double step_s) {
  const std::vector<std::complex<double>> modes = RelbotModesAtRest(c);
  const double max_step_s = MaxStableStepS(integrator, modes);
  if (step_s <= max_step_s) return;
  // Name the mode that sets the limit, so a user changing parameters knows which one bites.
  std::complex<double> limiting{0.0, 0.0};
  for (const auto& mode : modes) {
    if (MaxStableStepS(integrator, std::span(&mode, 1)) == max_step_s) limiting = mode;
  }
  std::ostringstream message;
  message.precision(3);
  message << "the RELbot model diverges with " << IntegratorName(integrator) << " at a step of "
          << step_s * 1e3 << " ms (" << 1.0 / step_s << " Hz): its mode at "
          << limiting.real() << (limiting.imag() >= 0 ? " + " : " - ") << std::abs(limiting.imag())
          << "i 1/s (linearised at rest) is integrated stably only up to a step of "
          << max_step_s * 1e3 << " ms; choose an update rate of at least "
          << std::ceil(1.0 / max_step_s) << " Hz";
  if (integrator != Integrator::kRk4) {
    message << " (rk4: at least " << std::ceil(1.0 / MaxStableStepS(Integrator::kRk4, modes))
            << " Hz)";
  }
  throw ConfigError(message.str());
}

}  // namespace

RelbotModel::RelbotModel(const RelbotParams& params, Integrator integrator, double step_s)
    : params_(params), integrator_(integrator), step_s_(step_s) {
  ValidateRelbotParams(params_, "RELbot parameters");
  if (!std::isfinite(step_s) || !(step_s > 0.0) || step_s > 0.1) {
    std::ostringstream message;
    message << "RELbot model step " << step_s
            << " s is out of range: it must be > 0 and <= 0.1 s; choose an update rate of at "
               "least 10 Hz (the thesis runs the RELbot twin at 4 kHz)";
    throw ConfigError(message.str());
  }
  coefficients_ = MakeRelbotCoefficients(params_);
  CheckStable(coefficients_, integrator_, step_s_);
}

void RelbotModel::Reset() noexcept {
  state_.setZero();
  steps_ = 0;
}

namespace {

// One stage's derivative in RelbotModel::Step: the held drive, and the heading's cosine and
// sine reused from the last stage while the heading has not changed, bit for bit (at rest and
// driving straight every stage of every step meets the same heading, and sincos was a quarter
// of a stage).
class ModelStage {
 public:
  ModelStage(const RelbotCoefficients& c, HeldDrive drive, RelbotHeadingTrigCache& cache) noexcept
      : c_(c), drive_(drive), cache_(cache) {}
  [[gnu::always_inline]] void operator()(const RelbotState& x, RelbotState& dxdt) const noexcept {
    const auto trig = [this](double heading) noexcept { return Trig(heading); };
    Derivative(c_, drive_, trig, x, dxdt);
  }

 private:
  [[nodiscard]] HeadingTrig Trig(double heading) const noexcept {
    const auto bits = std::bit_cast<std::uint64_t>(heading);
    if (bits != cache_.heading_bits) {
      const HeadingTrig trig = TrigOf(heading);
      cache_ = {bits, trig.cos_h, trig.sin_h};
    }
    return {cache_.cos_h, cache_.sin_h};
  }
  const RelbotCoefficients& c_;
  HeldDrive drive_;
  RelbotHeadingTrigCache& cache_;
};

}  // namespace

// Flattened: g++ -O2 keeps Eigen's assignment loops (the stages' x + a k) out of line, three
// calls a step; inlined they cost a tenth less.
[[gnu::flatten]] void RelbotModel::Step(double duty_left, double duty_right) noexcept {
  const ModelStage stage(coefficients_,
                         DriveOf(coefficients_, SaturateDuty(duty_left), SaturateDuty(duty_right)),
                         trig_cache_);
  IntegrateStep(integrator_, stage, state_, step_s_);
  ++steps_;
}

}  // namespace hiltwin::app
