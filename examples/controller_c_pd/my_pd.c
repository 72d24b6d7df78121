/* my_pd.c -- a PD position controller for the RELbot's two wheels, as a shared library with
 * the C ABI of hiltwin/controller_abi.h: `hiltwin hil --controller lib:./my_pd.so`.
 * duty = KP * (setpoint - wheel) - KD * (wheel speed), clamped to +-1, per wheel. The
 * derivative acts on the measured wheel, not on the error, so a setpoint step does not kick. */
#include <hiltwin/controller_abi.h>
#include <stdlib.h>

/* Tuned on the 2.5 m move against the RELbot twin at ECS 1 kHz: at most 2.5 mm behind. */
#define KP 600.0 /* duty per metre of position error */
#define KD 1.2   /* duty per metre/second of wheel speed */

typedef struct {
  double step_s;
  double last_wheel_m[2]; /* the previous step's measurements, for the speed */
  int primed;             /* 0 until the first step has measured the wheels */
} my_pd;

static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_right_m", "m"}};
static const hiltwin_port outputs[] = {{"duty_left", "1"}, {"duty_right", "1"}};

static void* create(void) { return calloc(1, sizeof(my_pd)); }
static int start(void* self, double step_s) {
  my_pd* pd = self;
  pd->step_s = step_s;
  pd->primed = 0;
  return 0;
}
static int step(void* self, const double* in, double* out) {
  my_pd* pd = self;
  for (int wheel = 0; wheel < 2; ++wheel) {
    const double wheel_m = in[2 + wheel];
    if (!pd->primed) pd->last_wheel_m[wheel] = wheel_m; /* no speed before two samples */
    const double speed_m_s = (wheel_m - pd->last_wheel_m[wheel]) / pd->step_s;
    const double duty = KP * (in[wheel] - wheel_m) - KD * speed_m_s;
    out[wheel] = duty > 1.0 ? 1.0 : (duty < -1.0 ? -1.0 : duty);
    pd->last_wheel_m[wheel] = wheel_m;
  }
  pd->primed = 1;
  return 0;
}
static void finish(void* self) { (void)self; }
static void destroy(void* self) { free(self); }

static const hiltwin_controller_descriptor descriptor = {
    HILTWIN_CONTROLLER_ABI_VERSION, "my_pd", inputs, 4, outputs, 2, 0.0, /* any step */
    create, start, step, finish, destroy, NULL};
const hiltwin_controller_descriptor* hiltwin_controller(void) { return &descriptor; }
