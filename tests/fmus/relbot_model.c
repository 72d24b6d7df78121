/* The RELbot (relbot/src/relbot_model.cpp, default parameters) as a co-simulation FMU: the same
 * 12 states and equations, stepped by classical RK4 with the duties held over the step, so a
 * doStep costs about what the built-in model's step costs (four derivative evaluations, a sqrt
 * each, a sincos while the heading changes). A plant-sized FMU for hiltwin_bench_fmi_loop, where
 * lag.fmu's step (one exp) says little about a real model; the unit tests compare it with the
 * built-in model. Ports as the built-in model's: inputs duty_left, duty_right (saturated to
 * [-1, 1], NaN -> 0); outputs wheel_left_m, wheel_right_m, x_m, y_m, theta_rad. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fmu_common.h"

enum { kDutyL = 0, kDutyR = 1, kWheelL = 2, kWheelR = 3, kXOut = 4, kYOut = 5, kHeadingOut = 6 };

const size_t kModelRealCount = 7;

enum { kStates = 12 };
/* State indices, as relbot_state in relbot_model.h. */
enum {
  kSpeedL, kSpeedR, kPosL, kPosR, kDeflL, kDeflR, kVx, kVy, kYawRate, kWorldX, kWorldY, kHeading
};

/* Coefficients (MakeRelbotCoefficients) from RelbotParams' defaults, in work[kStates + ...]. */
enum {
  kDrivePerDuty, /* drive_per_volt times the supply voltage */
  kDriveDamping,
  kForceToWheelAccel,
  kWheelRadius,
  kHalfTrack,
  kStiffness,
  kDamping,
  kLateralDamping,
  kInvBodyMass,
  kInvYawInertia,
  kCastorOffset,
  kCastorViscous,
  kCastorCoulomb,
  kCastorSmoothingSq,
  kCoefficients
};

/* The heading's cosine and sine in work[kTrig...], kept while the heading is bit-identical to
 * the one they were computed for (the built-in model's exact memo: driving straight, every
 * stage of every step meets the same heading). Start: heading +0, whose cos and sin are exactly
 * 1 and +0. */
enum { kTrig = kStates + kCoefficients, kTrigHeading = kTrig, kTrigCos, kTrigSin, kWorkUsed };
typedef char WorkFitsAll[kWorkUsed <= 32 ? 1 : -1];

static void MakeCoefficients(double* c) {
  const double supply_v = 12.0, resistance = 4.0, k_t = 0.01, k_e = 0.01, rotor_j = 1.0e-6;
  const double viscous = 2.0e-6, n = 50.0, radius = 0.04, wheel_mass = 0.1, wheel_j = 8.0e-5;
  const double j_eq = n * n * rotor_j + wheel_j + wheel_mass * radius * radius;
  c[kDrivePerDuty] = n * k_t / (resistance * j_eq) * supply_v;
  c[kDriveDamping] = n * n * (k_t * k_e / resistance + viscous) / j_eq;
  c[kForceToWheelAccel] = radius / j_eq;
  c[kWheelRadius] = radius;
  c[kHalfTrack] = 0.5 * 0.17;
  c[kStiffness] = 2.0e4;
  c[kDamping] = 150.0;
  c[kLateralDamping] = 200.0;
  c[kInvBodyMass] = 1.0 / 1.8;
  c[kInvYawInertia] = 1.0 / 0.01;
  c[kCastorOffset] = 0.10;
  c[kCastorViscous] = 0.2;
  c[kCastorCoulomb] = 0.12;
  c[kCastorSmoothingSq] = 0.01 * 0.01;
}

static void PublishOutputs(FmuInstance* instance) {
  const double* x = instance->work;
  instance->r[kWheelL] = x[kPosL];
  instance->r[kWheelR] = x[kPosR];
  instance->r[kXOut] = x[kWorldX];
  instance->r[kYOut] = x[kWorldY];
  instance->r[kHeadingOut] = x[kHeading];
}

void ModelSetStartValues(FmuInstance* instance) {
  memset(instance->r, 0, sizeof instance->r);
  memset(instance->work, 0, sizeof instance->work);
  MakeCoefficients(instance->work + kStates);
  instance->work[kTrigCos] = 1.0;
}

fmi2Status ModelExitInitialization(FmuInstance* instance) {
  memset(instance->work, 0, kStates * sizeof instance->work[0]);
  PublishOutputs(instance);
  return fmi2OK;
}

static double Saturate(double duty) {
  if (isnan(duty)) return 0.0;
  return duty > 1.0 ? 1.0 : (duty < -1.0 ? -1.0 : duty);
}

static void Trig(double* cache, double heading) {
  uint64_t bits;
  uint64_t cached_bits;
  memcpy(&bits, &heading, sizeof bits);
  memcpy(&cached_bits, &cache[kTrigHeading], sizeof cached_bits);
  if (bits != cached_bits) {
    cache[kTrigHeading] = heading;
    cache[kTrigCos] = cos(heading);
    cache[kTrigSin] = sin(heading);
  }
}

/* relbot_model.cpp's Derivative, term for term; inlined into the four stages, as the built-in
 * model flattens its step. */
static inline __attribute__((always_inline)) void Derivative(const double* c, double drive_l,
                                                             double drive_r, double* trig,
                                                             const double* x, double* dxdt) {
  Trig(trig, x[kHeading]);
  const double cos_h = trig[kTrigCos];
  const double sin_h = trig[kTrigSin];
  const double vx = x[kVx], vy = x[kVy], yaw_rate = x[kYawRate];
  const double wheel_v_l = c[kWheelRadius] * x[kSpeedL];
  const double wheel_v_r = c[kWheelRadius] * x[kSpeedR];
  const double defl_rate_l = wheel_v_l - (vx - c[kHalfTrack] * yaw_rate);
  const double defl_rate_r = wheel_v_r - (vx + c[kHalfTrack] * yaw_rate);
  const double force_l = c[kStiffness] * x[kDeflL] + c[kDamping] * defl_rate_l;
  const double force_r = c[kStiffness] * x[kDeflR] + c[kDamping] * defl_rate_r;
  const double castor_vy = vy - c[kCastorOffset] * yaw_rate;
  const double castor_gain =
      c[kCastorViscous] +
      c[kCastorCoulomb] / sqrt(vx * vx + castor_vy * castor_vy + c[kCastorSmoothingSq]);
  const double castor_fx = -castor_gain * vx;
  const double castor_fy = -castor_gain * castor_vy;
  const double lateral_f = -c[kLateralDamping] * vy;
  dxdt[kSpeedL] = drive_l - c[kDriveDamping] * x[kSpeedL] - c[kForceToWheelAccel] * force_l;
  dxdt[kSpeedR] = drive_r - c[kDriveDamping] * x[kSpeedR] - c[kForceToWheelAccel] * force_r;
  dxdt[kPosL] = wheel_v_l;
  dxdt[kPosR] = wheel_v_r;
  dxdt[kDeflL] = defl_rate_l;
  dxdt[kDeflR] = defl_rate_r;
  dxdt[kVx] = (force_l + force_r + castor_fx) * c[kInvBodyMass] + yaw_rate * vy;
  dxdt[kVy] = (lateral_f + castor_fy) * c[kInvBodyMass] - yaw_rate * vx;
  dxdt[kYawRate] = (c[kHalfTrack] * (force_r - force_l) - c[kCastorOffset] * castor_fy) *
                   c[kInvYawInertia];
  dxdt[kWorldX] = vx * cos_h - vy * sin_h;
  dxdt[kWorldY] = vx * sin_h + vy * cos_h;
  dxdt[kHeading] = yaw_rate;
}

fmi2Status ModelDoStep(FmuInstance* instance, double h_s) {
  const double* c = instance->work + kStates;
  double* x = instance->work;
  const double drive_l = c[kDrivePerDuty] * Saturate(instance->r[kDutyL]);
  const double drive_r = c[kDrivePerDuty] * Saturate(instance->r[kDutyR]);
  double* trig = instance->work;
  double k1[kStates], k2[kStates], k3[kStates], k4[kStates], tmp[kStates];
  Derivative(c, drive_l, drive_r, trig, x, k1);
  for (int i = 0; i < kStates; ++i) tmp[i] = x[i] + 0.5 * h_s * k1[i];
  Derivative(c, drive_l, drive_r, trig, tmp, k2);
  for (int i = 0; i < kStates; ++i) tmp[i] = x[i] + 0.5 * h_s * k2[i];
  Derivative(c, drive_l, drive_r, trig, tmp, k3);
  for (int i = 0; i < kStates; ++i) tmp[i] = x[i] + h_s * k3[i];
  Derivative(c, drive_l, drive_r, trig, tmp, k4);
  for (int i = 0; i < kStates; ++i) {
    x[i] += h_s / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  PublishOutputs(instance);
  return fmi2OK;
}
