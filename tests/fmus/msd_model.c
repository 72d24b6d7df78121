/* Mass-spring-damper m x'' + c x' + k x = F, under-damped, stepped exactly with F held over
 * the step: the deviation e = x - F/k and v evolve by the matrix exponential of
 * [[0, 1], [-k/m, -c/m]], computed once per step size. Tests compare with the closed form. */
#include <math.h>

#include "fmu_common.h"

enum { kF = 0, kX = 1, kV = 2, kM = 3, kK = 4, kC = 5, kX0 = 6 }; /* as in msd.xml.in */

const size_t kModelRealCount = 7;

void ModelSetStartValues(FmuInstance* instance) {
  double* r = instance->r;
  r[kF] = 0.0;
  r[kM] = 1.0;
  r[kK] = 40.0;
  r[kC] = 0.8;
  r[kX0] = 0.1;
  r[kX] = r[kX0];
  r[kV] = 0.0;
  instance->cached_h_s = 0.0;
}

fmi2Status ModelExitInitialization(FmuInstance* instance) {
  double* r = instance->r;
  if (!(r[kM] > 0.0) || !(r[kK] > 0.0) || !(r[kC] >= 0.0) ||
      r[kC] * r[kC] >= 4.0 * r[kK] * r[kM]) {
    FmuLog(instance, fmi2Error, "logStatusError",
           "only under-damped parameters are supported (c = %g)", r[kC]);
    return fmi2Error;
  }
  r[kX] = r[kX0];
  r[kV] = 0.0;
  instance->cached_h_s = 0.0;
  return fmi2OK;
}

static void Transition(FmuInstance* instance, double h_s) {
  const double* r = instance->r;
  const double wn = sqrt(r[kK] / r[kM]);
  const double sigma = r[kC] / (2.0 * r[kM]);
  const double wd = sqrt(wn * wn - sigma * sigma);
  const double decay = exp(-sigma * h_s);
  const double cs = cos(wd * h_s);
  const double sn = sin(wd * h_s);
  instance->phi[0] = decay * (cs + sigma / wd * sn);
  instance->phi[1] = decay * sn / wd;
  instance->phi[2] = -decay * wn * wn / wd * sn;
  instance->phi[3] = decay * (cs - sigma / wd * sn);
  instance->cached_h_s = h_s;
}

fmi2Status ModelDoStep(FmuInstance* instance, double h_s) {
  if (h_s != instance->cached_h_s) {
    Transition(instance, h_s);
  }
  double* r = instance->r;
  const double* phi = instance->phi;
  const double e = r[kX] - r[kF] / r[kK];
  const double v = r[kV];
  r[kX] = r[kF] / r[kK] + phi[0] * e + phi[1] * v;
  r[kV] = phi[2] * e + phi[3] * v;
  return fmi2OK;
}
