/* hiltwin/controller_abi.h -- the C ABI of a controller in a shared library, for
 * `hiltwin ecs --controller lib:PATH.so` and `hiltwin hil --controller lib:PATH.so`.
 *
 * A library exports one function, hiltwin_controller(), that returns a descriptor: the ABI
 * version it was built against, its name, its ports (name and unit), the step it was written
 * for, and its entry points. hiltwin checks all of it when it loads the library (the version,
 * every entry point present, port names and units against the controller map) and refuses with
 * a message that says what is wrong, before the run starts.
 *
 * Rules for the entry points (the ECS calls step() in its real-time loop, docs/controllers.md):
 *   create()   may allocate; returns the controller's state, NULL on failure.
 *   start()    may allocate; called once before the first step with the step in seconds;
 *              returns 0, or nonzero when it cannot run (the run does not start).
 *   step()     reads input_count inputs, writes output_count outputs; must not allocate, block,
 *              print or call into the system; returns 0, or nonzero to stop the run (hiltwin
 *              sends zero duty and names the controller and its last_error in the report).
 *   finish()   called once after the last step (also after an error).
 *   destroy()  frees what create() made.
 *   last_error() may be NULL; else returns static text or text owned by the state, valid until
 *              the next call.
 * Units: "m", "rad", "1" (dimensionless, a duty), "m/s", "rad/s", or "" when it does not say.
 * The built-in map feeds setpoint_left_m, setpoint_right_m, wheel_left_m, wheel_right_m (m)
 * and drives duty_left, duty_right (1); a controller with those ports needs no map.
 *
 * This header is C99 and C++ alike; a library built against it links nothing of hiltwin.
 */
#ifndef HILTWIN_CONTROLLER_ABI_H
#define HILTWIN_CONTROLLER_ABI_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped when the descriptor or an entry point's meaning changes; hiltwin refuses another. */
#define HILTWIN_CONTROLLER_ABI_VERSION 1u

/* The name of the one symbol a controller library exports. */
#define HILTWIN_CONTROLLER_ENTRY "hiltwin_controller"

typedef struct hiltwin_port {
  const char* name; /* a C identifier-like name: letters, digits, '_' */
  const char* unit;
} hiltwin_port;

typedef struct hiltwin_controller_descriptor {
  uint32_t abi_version; /* HILTWIN_CONTROLLER_ABI_VERSION */
  const char* name;     /* the controller's own name, for the report */
  const hiltwin_port* inputs;
  uint32_t input_count;
  const hiltwin_port* outputs;
  uint32_t output_count;
  double step_s; /* the step it was written for, in seconds; 0: any step (start() gets it) */
  void* (*create)(void);
  int (*start)(void* self, double step_s);
  int (*step)(void* self, const double* inputs, double* outputs);
  void (*finish)(void* self);
  void (*destroy)(void* self);
  const char* (*last_error)(void* self);
} hiltwin_controller_descriptor;

/* Gives hiltwin_controller default visibility even in a library built with
 * -fvisibility=hidden (hiltwin_add_controller builds so, to export nothing else); the
 * definition inherits it from the declaration below. */
#if defined(__GNUC__) || defined(__clang__)
#define HILTWIN_CONTROLLER_EXPORT __attribute__((visibility("default")))
#else
#define HILTWIN_CONTROLLER_EXPORT
#endif

/* What the library defines (once, with external linkage and default visibility). */
typedef const hiltwin_controller_descriptor* (*hiltwin_controller_fn)(void);
HILTWIN_CONTROLLER_EXPORT const hiltwin_controller_descriptor* hiltwin_controller(void);

#ifdef __cplusplus
}
#endif

#endif /* HILTWIN_CONTROLLER_ABI_H */
