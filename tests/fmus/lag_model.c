/* First-order lag y' = (K u - y) / tau, stepped exactly with u held over the step:
 * y <- K u + (y - K u) exp(-h / tau). So y(t) = K u (1 - exp(-t / tau)) from y = 0 holds to
 * rounding, and tests compare against it tightly. */
#include <math.h>

#include "fmu_common.h"

enum { kU = 0, kY = 1, kK = 2, kTau = 3 }; /* value references, as in lag.xml.in */

const size_t kModelRealCount = 4;

void ModelSetStartValues(FmuInstance* instance) {
  instance->r[kU] = 0.0;
  instance->r[kY] = 0.0;
  instance->r[kK] = 2.0;
  instance->r[kTau] = 0.5;
}

fmi2Status ModelExitInitialization(FmuInstance* instance) {
#ifdef HILTWIN_FMU_FAIL_INIT
  FmuLog(instance, fmi2Error, "logStatusError", "this FMU never initialises (test variant %g)",
         1.0);
  return fmi2Error;
#endif
  if (!(instance->r[kTau] > 0.0)) {
    FmuLog(instance, fmi2Error, "logStatusError", "tau = %g s must be positive",
           instance->r[kTau]);
    return fmi2Error;
  }
#ifdef HILTWIN_FMU_STEADY_START
  /* Initialised in equilibrium with the input it was given, as a model with a steady-state
   * initialisation is: y = K u, so the output holds while u does. */
  instance->r[kY] = instance->r[kK] * instance->r[kU];
#endif
  return fmi2OK;
}

fmi2Status ModelDoStep(FmuInstance* instance, double h_s) {
  double* r = instance->r;
  const double target = r[kK] * r[kU];
  r[kY] = target + (r[kY] - target) * exp(-h_s / r[kTau]);
#ifdef HILTWIN_FMU_NAN_AFTER_STEPS
  /* A model that diverges: its output turns NaN and it still reports fmi2OK, as a broken
   * model does; the twin must catch it (the fault matrix's "model producing NaN"). */
  if (instance->steps >= HILTWIN_FMU_NAN_AFTER_STEPS) r[kY] = nan("");
#endif
  return fmi2OK;
}
