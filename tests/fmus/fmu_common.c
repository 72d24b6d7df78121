/* The FMI 2.0 functions of hiltwin's test FMUs (see fmu_common.h). */
#define _POSIX_C_SOURCE 200809L
#include "fmu_common.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

void FmuLog(const FmuInstance* instance, fmi2Status status, const char* category,
            const char* message, double value) {
  if (instance->callbacks->logger != NULL) {
    instance->callbacks->logger(instance->callbacks->componentEnvironment,
                                instance->instance_name, status, category, message, value);
  }
}

const char* fmi2GetTypesPlatform(void) { return HILTWIN_FMI2_TYPES_PLATFORM; }
const char* fmi2GetVersion(void) { return HILTWIN_FMI2_VERSION; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
  (void)fmuResourceLocation;
  (void)visible;
  (void)loggingOn;
  if (functions == NULL || functions->allocateMemory == NULL || functions->freeMemory == NULL ||
      fmuType != fmi2CoSimulation || fmuGUID == NULL || strcmp(fmuGUID, HILTWIN_FMU_GUID) != 0) {
    return NULL;
  }
  FmuInstance* instance = (FmuInstance*)functions->allocateMemory(1, sizeof(FmuInstance));
  if (instance == NULL) {
    return NULL;
  }
  instance->callbacks = functions;
  snprintf(instance->instance_name, sizeof instance->instance_name, "%s",
           instanceName != NULL ? instanceName : "");
  ModelSetStartValues(instance);
  return instance;
}

void fmi2FreeInstance(fmi2Component c) {
  FmuInstance* instance = (FmuInstance*)c;
  if (instance != NULL) {
    instance->callbacks->freeMemory(instance);
  }
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
  (void)toleranceDefined;
  (void)tolerance;
  (void)stopTimeDefined;
  (void)stopTime;
  ((FmuInstance*)c)->time_s = startTime;
  return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return ModelExitInitialization((FmuInstance*)c);
}

fmi2Status fmi2Terminate(fmi2Component c) {
  (void)c;
  return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
  FmuInstance* instance = (FmuInstance*)c;
  ModelSetStartValues(instance);
  instance->time_s = 0.0;
  instance->steps = 0;
  return fmi2OK;
}

static fmi2Status CheckReferences(const FmuInstance* instance, const fmi2ValueReference vr[],
                                  size_t nvr) {
  for (size_t i = 0; i < nvr; ++i) {
    if (vr[i] >= kModelRealCount) {
      FmuLog(instance, fmi2Error, "logStatusError", "no Real with value reference %g",
             (double)vr[i]);
      return fmi2Error;
    }
  }
  return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
  const FmuInstance* instance = (const FmuInstance*)c;
  if (CheckReferences(instance, vr, nvr) != fmi2OK) {
    return fmi2Error;
  }
  for (size_t i = 0; i < nvr; ++i) {
    value[i] = instance->r[vr[i]];
  }
  return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
  FmuInstance* instance = (FmuInstance*)c;
  if (CheckReferences(instance, vr, nvr) != fmi2OK) {
    return fmi2Error;
  }
  for (size_t i = 0; i < nvr; ++i) {
    instance->r[vr[i]] = value[i];
  }
  return fmi2OK;
}

#ifdef HILTWIN_FMU_BUSY_US
static void Spin(long microseconds) {
  struct timespec start;
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &start);
  do {
    clock_gettime(CLOCK_MONOTONIC, &now);
  } while ((now.tv_sec - start.tv_sec) * 1000000L + (now.tv_nsec - start.tv_nsec) / 1000L <
           microseconds);
}
#endif

#ifndef HILTWIN_FMU_OMIT_DO_STEP
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
  (void)noSetFMUStatePriorToCurrentCommunicationPoint;
  FmuInstance* instance = (FmuInstance*)c;
  /* The importer's time must be the FMU's: a drifting communication point is a bug there. */
  if (fabs(currentCommunicationPoint - instance->time_s) > 1e-9 * (1.0 + instance->time_s)) {
    FmuLog(instance, fmi2Error, "logStatusError", "communication point %.17g is not my time",
           currentCommunicationPoint);
    return fmi2Error;
  }
#ifdef HILTWIN_FMU_FAIL_AFTER_STEPS
  if (instance->steps >= HILTWIN_FMU_FAIL_AFTER_STEPS) {
    FmuLog(instance, fmi2Error, "logStatusError", "failing on purpose at t = %g s",
           currentCommunicationPoint);
    return fmi2Error;
  }
#endif
#ifdef HILTWIN_FMU_LOG_EVERY_STEP
  FmuLog(instance, fmi2OK, "logEvents", "step at t = %.3f s", currentCommunicationPoint);
#endif
#ifdef HILTWIN_FMU_BUSY_US
  Spin(HILTWIN_FMU_BUSY_US);
#endif
  const fmi2Status status = ModelDoStep(instance, communicationStepSize);
  instance->time_s = currentCommunicationPoint + communicationStepSize;
  ++instance->steps;
  return status;
}
#endif
