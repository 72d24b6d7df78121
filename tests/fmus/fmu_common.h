/* Shared body of hiltwin's test FMUs: every FMI 2.0 function on an array of Reals indexed by
 * value reference; each model (lag_model.c, msd_model.c) supplies start values, the check at
 * the end of initialisation and one exact step. Variants are compile definitions:
 *   HILTWIN_FMU_GUID "..."            the guid, also written into modelDescription.xml
 *   HILTWIN_FMU_OMIT_DO_STEP          no fmi2DoStep exported (the missing-symbol test)
 *   HILTWIN_FMU_FAIL_AFTER_STEPS N    fmi2DoStep returns fmi2Error from step N on
 *   HILTWIN_FMU_LOG_EVERY_STEP        fmi2DoStep logs one message per step
 *   HILTWIN_FMU_BUSY_US N             fmi2DoStep spins N microseconds (a model too slow) */
#ifndef HILTWIN_TEST_FMU_COMMON_H
#define HILTWIN_TEST_FMU_COMMON_H

#define HILTWIN_FMI2_FUNCTION_PROTOTYPES
#include "hiltwin/fmi/fmi2_abi.h"

#define FMU_MAX_REALS 16

typedef struct {
  double r[FMU_MAX_REALS]; /* value reference -> value */
  const fmi2CallbackFunctions* callbacks;
  char instance_name[64];
  double time_s;
  unsigned long steps;
  /* Model scratch: the exact transition over one step, cached for its step size. */
  double cached_h_s;
  double phi[4];
  /* Model scratch of relbot_model.c: its 12 states and its coefficients. */
  double work[32];
} FmuInstance;

/* Supplied by the model. */
extern const size_t kModelRealCount;
void ModelSetStartValues(FmuInstance* instance);
fmi2Status ModelExitInitialization(FmuInstance* instance);
fmi2Status ModelDoStep(FmuInstance* instance, double h_s);

/* Logs through the importer's callback. */
void FmuLog(const FmuInstance* instance, fmi2Status status, const char* category,
            const char* message, double value);

#endif
