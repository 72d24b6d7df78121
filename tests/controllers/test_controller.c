/* A controller library for the loader's tests (tests/controllers/CMakeLists.txt builds one
 * library per variant from this file). The good one: out[w] = in[w] - in[2 + w] (setpoint
 * minus wheel, per wheel), with the ports of the built-in map, counting the calls of its entry
 * points in hiltwin_test_calls (exported, so a test can read them). Each HILTWIN_TEST_* macro
 * makes it wrong in one way. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hiltwin/controller_abi.h"

/* create, start, step, finish, destroy: how often each was called, over every instance. */
__attribute__((visibility("default"))) int hiltwin_test_calls[5];

typedef struct {
  int steps;
  char error[64];  /* last_error's text, owned by the state (HILTWIN_TEST_STEP_ERROR) */
  double* history; /* never allocated: calloc leaves it NULL (HILTWIN_TEST_NULL_DEREFERENCE) */
} test_state;

#if defined(HILTWIN_TEST_DUPLICATE_PORT)
static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_left_m", "m"}};
#elif defined(HILTWIN_TEST_NULL_UNIT)
static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_right_m", NULL}};
#elif defined(HILTWIN_TEST_WRONG_UNIT)
/* Valid ports of their own, but the RELbot's default map feeds wheel_right_m in metres. */
static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_right_m", "rad"}};
#else
static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_right_m", "m"}};
#endif
static const hiltwin_port outputs[] = {{"duty_left", "1"}, {"duty_right", "1"}};

static void* create(void) {
  ++hiltwin_test_calls[0];
#if defined(HILTWIN_TEST_CREATE_NULL)
  return NULL;
#else
  return calloc(1, sizeof(test_state));
#endif
}

static int start(void* self, double step_s) {
  ++hiltwin_test_calls[1];
  (void)step_s;
  ((test_state*)self)->steps = 0;
#if defined(HILTWIN_TEST_START_FAILS)
  return 3;
#else
  return 0;
#endif
}

/* unused in the variants that leave it out of the descriptor */
__attribute__((unused)) static int step(void* self, const double* in, double* out) {
  test_state* state = self;
  ++hiltwin_test_calls[2];
  ++state->steps;
#if defined(HILTWIN_TEST_NULL_DEREFERENCE)
  /* A student's forgotten allocation: the compiler cannot know the pointer is NULL, so this is
   * a plain store that faults (SIGSEGV), not a trap it inserted. */
  state->history[state->steps] = in[0];
#endif
  out[0] = in[0] - in[2];
  out[1] = in[1] - in[3];
#if defined(HILTWIN_TEST_NAN_OUTPUT)
  out[1] = nan("");
#endif
#if defined(HILTWIN_TEST_DUTY_BEYOND_LIMIT)
  out[0] = 1.5; /* beyond every duty_limit, which is at most 1 */
#endif
#if defined(HILTWIN_TEST_STEP_ERROR)
  if (state->steps >= 3) {
    strcpy(state->error, "wheel runaway: the test library stops at its third step");
    return 1;
  }
#endif
  return 0;
}

static void finish(void* self) {
  (void)self;
  ++hiltwin_test_calls[3];
}

static void destroy(void* self) {
  ++hiltwin_test_calls[4];
  /* Wiped before it is freed, so text hiltwin kept a pointer to reads empty, never stale. */
  memset(self, 0, sizeof(test_state));
  free(self);
}

__attribute__((unused)) static const char* last_error(void* self) {
  (void)self;
#if defined(HILTWIN_TEST_START_FAILS)
  return "start refused: the test library was built to refuse";
#else
  return ((test_state*)self)->error;
#endif
}

#if defined(HILTWIN_TEST_ABI_VERSION)
#define TEST_ABI_VERSION HILTWIN_TEST_ABI_VERSION
#else
#define TEST_ABI_VERSION HILTWIN_CONTROLLER_ABI_VERSION
#endif
#if defined(HILTWIN_TEST_STEP_S)
#define TEST_STEP_S HILTWIN_TEST_STEP_S
#else
#define TEST_STEP_S 0.0
#endif

static const hiltwin_controller_descriptor descriptor = {
    TEST_ABI_VERSION,
    "test_controller",
    inputs,
    4,
    outputs,
#if defined(HILTWIN_TEST_NO_OUTPUTS)
    0,
#else
    2,
#endif
    TEST_STEP_S,
    create,
    start,
#if defined(HILTWIN_TEST_NULL_STEP)
    NULL,
#else
    step,
#endif
    finish,
    destroy,
#if defined(HILTWIN_TEST_NO_LAST_ERROR)
    NULL,
#else
    last_error,
#endif
};

#if defined(HILTWIN_TEST_NO_ENTRY)
/* Exported under another name: the loader must say which symbol it wants. */
__attribute__((visibility("default"))) const hiltwin_controller_descriptor* controller(void) {
  return &descriptor;
}
#elif defined(HILTWIN_TEST_NULL_DESCRIPTOR)
const hiltwin_controller_descriptor* hiltwin_controller(void) {
  (void)descriptor;
  return NULL;
}
#else
const hiltwin_controller_descriptor* hiltwin_controller(void) { return &descriptor; }
#endif
