/* A position PID per wheel as a controller FMU, the ECS's control law (relbot/position_pid.h)
 * with its built-in gains (relbot/ecs_gains.toml) as parameters: inputs setpoint_left_m,
 * setpoint_right_m, wheel_left_m, wheel_right_m [m], outputs duty_left, duty_right [1] (the
 * RELbot's default controller wiring). Each fmi2DoStep samples the inputs held over the step
 * and sets the duties for the next one, with T = the communication step:
 *   e = r - y;  P = kp e;  D = a D' - kd / (tf + T) (y - y'),  a = tf / (tf + T);
 *   I = I' + ki T e, held while P + I + D is beyond the limit and e pushes it further;
 *   duty = clamp(P + I + D, -limit, limit).
 * The previous travel y' starts at 0 m, where the RELbot's wheels start. */
#include "fmu_common.h"

enum { /* value references, as in pid.xml.in */
  kSetpointLeft = 0,
  kSetpointRight = 1,
  kWheelLeft = 2,
  kWheelRight = 3,
  kDutyLeft = 4,
  kDutyRight = 5,
  kKp = 6,
  kKi = 7,
  kKd = 8,
  kTf = 9,
  kLimit = 10
};
/* work[]: per wheel w, the integral at 3 w, the derivative at 3 w + 1, the previous travel at
 * 3 w + 2. */
enum { kStatesPerWheel = 3 };

const size_t kModelRealCount = 11;

void ModelSetStartValues(FmuInstance* instance) {
  double* r = instance->r;
  int i;
  for (i = 0; i < FMU_MAX_REALS; ++i) r[i] = 0.0;
  r[kKp] = 100.0;
  r[kKi] = 1000.0;
  r[kKd] = 3.0;
  r[kTf] = 0.005;
  r[kLimit] = 1.0;
  for (i = 0; i < 2 * kStatesPerWheel; ++i) instance->work[i] = 0.0;
}

fmi2Status ModelExitInitialization(FmuInstance* instance) {
  const double* r = instance->r;
  if (!(r[kTf] >= 0.0) || !(r[kLimit] > 0.0)) {
    FmuLog(instance, fmi2Error, "logStatusError", "tf and duty_limit must be >= 0 and > 0 (%g)",
           r[kLimit]);
    return fmi2Error;
  }
  return fmi2OK;
}

static double WheelStep(FmuInstance* instance, int wheel, double h_s) {
  const double* r = instance->r;
  double* s = instance->work + kStatesPerWheel * wheel;
  const double measured = r[kWheelLeft + wheel];
  const double e = r[kSetpointLeft + wheel] - measured;
  const double limit = r[kLimit];
  const double p = r[kKp] * e;
  const double d = r[kTf] / (r[kTf] + h_s) * s[1] - r[kKd] / (r[kTf] + h_s) * (measured - s[2]);
  double i = s[0] + r[kKi] * h_s * e;
  double out = p + i + d;
  if ((out > limit && e > 0.0) || (out < -limit && e < 0.0)) i = s[0];
  out = p + i + d;
  s[0] = i;
  s[1] = d;
  s[2] = measured;
  return out > limit ? limit : out < -limit ? -limit : out;
}

fmi2Status ModelDoStep(FmuInstance* instance, double h_s) {
  instance->r[kDutyLeft] = WheelStep(instance, 0, h_s);
  instance->r[kDutyRight] = WheelStep(instance, 1, h_s);
  return fmi2OK;
}
