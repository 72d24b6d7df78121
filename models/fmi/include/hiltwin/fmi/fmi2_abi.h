/* The FMI 2.0 C ABI that hiltwin calls and that its test FMUs export: the types of
 * fmi2TypesPlatform.h and the function types of fmi2FunctionTypes.h, written here from the
 * signatures in the FMI 2.0 standard (Modelica Association, "Functional Mock-up Interface for
 * Model Exchange and Co-Simulation", version 2.0, sections 2.1.2-2.1.9 and 4.2). Debian 12
 * packages no FMI headers (no fmilib, no FMPy; checked with apt-cache), and the standard's
 * headers are a fixed ABI, so declaring the part we use is safer than vendoring a copy.
 *
 * Valid C (C99 or later) and C++. Only the co-simulation subset hiltwin needs is declared:
 * instance lifecycle, Real get/set, doStep. An FMU source defines
 * HILTWIN_FMI2_FUNCTION_PROTOTYPES before including this header to get the exported
 * prototypes (so the compiler checks its definitions against the standard's signatures). */
#ifndef HILTWIN_FMI_FMI2_ABI_H
#define HILTWIN_FMI_FMI2_ABI_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* fmi2TypesPlatform.h, platform "default". */
#define HILTWIN_FMI2_TYPES_PLATFORM "default"
#define HILTWIN_FMI2_VERSION "2.0"

typedef void* fmi2Component;            /* an FMU instance */
typedef void* fmi2ComponentEnvironment; /* the importer's pointer, handed back to callbacks */
typedef void* fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char fmi2Byte;

#define fmi2True 1
#define fmi2False 0

/* fmi2FunctionTypes.h */
typedef enum {
  fmi2OK,
  fmi2Warning,
  fmi2Discard,
  fmi2Error,
  fmi2Fatal,
  fmi2Pending
} fmi2Status;

typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;

typedef enum {
  fmi2DoStepStatus,
  fmi2PendingStatus,
  fmi2LastSuccessfulTime,
  fmi2Terminated
} fmi2StatusKind;

/* `message` is a printf format; the variadic arguments are its values. */
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment componentEnvironment,
                                   fmi2String instanceName, fmi2Status status,
                                   fmi2String category, fmi2String message, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t nobj, size_t size);
typedef void (*fmi2CallbackFreeMemory)(void* obj);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment componentEnvironment,
                                 fmi2Status status);

/* The importer keeps this structure alive until fmi2FreeInstance (FMI 2.0.1 clarification):
 * an FMU may keep the pointer. */
typedef struct {
  const fmi2CallbackLogger logger;
  const fmi2CallbackAllocateMemory allocateMemory;
  const fmi2CallbackFreeMemory freeMemory;
  const fmi2StepFinished stepFinished;
  const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

/* Function types, named as the standard names them (fmi2XxxTYPE). */
typedef const char* fmi2GetTypesPlatformTYPE(void);
typedef const char* fmi2GetVersionTYPE(void);
typedef fmi2Component fmi2InstantiateTYPE(fmi2String instanceName, fmi2Type fmuType,
                                          fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                          const fmi2CallbackFunctions* functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn);
typedef void fmi2FreeInstanceTYPE(fmi2Component c);
typedef fmi2Status fmi2SetupExperimentTYPE(fmi2Component c, fmi2Boolean toleranceDefined,
                                           fmi2Real tolerance, fmi2Real startTime,
                                           fmi2Boolean stopTimeDefined, fmi2Real stopTime);
typedef fmi2Status fmi2EnterInitializationModeTYPE(fmi2Component c);
typedef fmi2Status fmi2ExitInitializationModeTYPE(fmi2Component c);
typedef fmi2Status fmi2TerminateTYPE(fmi2Component c);
typedef fmi2Status fmi2ResetTYPE(fmi2Component c);
typedef fmi2Status fmi2GetRealTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                   fmi2Real value[]);
typedef fmi2Status fmi2SetRealTYPE(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                   const fmi2Real value[]);
typedef fmi2Status fmi2DoStepTYPE(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint);

#ifdef HILTWIN_FMI2_FUNCTION_PROTOTYPES
/* What an FMU exports, under exactly these names (the standard's, without a prefix). */
#define FMI2_Export __attribute__((visibility("default")))
FMI2_Export fmi2GetTypesPlatformTYPE fmi2GetTypesPlatform;
FMI2_Export fmi2GetVersionTYPE fmi2GetVersion;
FMI2_Export fmi2InstantiateTYPE fmi2Instantiate;
FMI2_Export fmi2FreeInstanceTYPE fmi2FreeInstance;
FMI2_Export fmi2SetupExperimentTYPE fmi2SetupExperiment;
FMI2_Export fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
FMI2_Export fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
FMI2_Export fmi2TerminateTYPE fmi2Terminate;
FMI2_Export fmi2ResetTYPE fmi2Reset;
FMI2_Export fmi2GetRealTYPE fmi2GetReal;
FMI2_Export fmi2SetRealTYPE fmi2SetReal;
FMI2_Export fmi2DoStepTYPE fmi2DoStep;
#endif

#ifdef __cplusplus
}
#endif

#endif /* HILTWIN_FMI_FMI2_ABI_H */
