/* grading_pid.c -- the grading example's three controllers (README.md), one source built three
 * times with different gains: `hiltwin test campaigns/relbot_course.toml` grades each.
 *   tuned_pid.so    the defaults below: KP 100, KI 1000, KD 3   (passes every scenario)
 *   sluggish_p.so   KP 3, KI 0, KD 0                 (fails the step's settling time)
 *   unstable_pi.so  KP 100, KI 20000, KD 0           (fails every closed-loop scenario)
 * (controllers.cmake passes them as -DGRADING_KP=... to each build.) One source rather than
 * three: the three differ in their gains and in nothing else, which is the lesson of the
 * example, and the build compiles 90 lines of C three times.
 *
 * Per wheel, at the ECS's period T, error e = setpoint - wheel:
 *   duty = KP e + I + D, clamped to +-1;
 *   I += KI T e, held while the duty is saturated in the direction e pushes (anti-windup);
 *   D = a D - KD / (TF + T) (wheel_k - wheel_k-1), a = TF / (TF + T): the derivative of the
 *   measured wheel, not of the error (no kick on a setpoint step), through a TF low-pass (one
 *   encoder count in one period must not turn into a duty spike).
 * This is the law of the built-in `--controller pid` (relbot/include/hiltwin/relbot/
 * position_pid.h) and the tuned gains are its gains (relbot/ecs_gains.toml). */
#include <hiltwin/controller_abi.h>
#include <stdlib.h>

/* The controller's name, for the run report: a bare word, made a string here so the build's -D
 * needs no quoting. */
#ifndef GRADING_NAME
#define GRADING_NAME tuned_pid
#endif
#define GRADING_STRING_(word) #word
#define GRADING_STRING(word) GRADING_STRING_(word)
#ifndef GRADING_KP
#define GRADING_KP 100.0 /* duty per metre of error */
#endif
#ifndef GRADING_KI
#define GRADING_KI 1000.0 /* duty per metre-second of error */
#endif
#ifndef GRADING_KD
#define GRADING_KD 3.0 /* duty per metre/second of measured wheel speed */
#endif
#ifndef GRADING_TF
#define GRADING_TF 0.005 /* s: the derivative's low-pass */
#endif

typedef struct {
  double step_s;
  double integral_duty[2];
  double derivative_duty[2];
  double last_wheel_m[2];
  int primed; /* 0 until the first step has measured the wheels */
} grading_pid;

static const hiltwin_port inputs[] = {{"setpoint_left_m", "m"}, {"setpoint_right_m", "m"},
                                      {"wheel_left_m", "m"},    {"wheel_right_m", "m"}};
static const hiltwin_port outputs[] = {{"duty_left", "1"}, {"duty_right", "1"}};

static void* create(void) { return calloc(1, sizeof(grading_pid)); }
static int start(void* self, double step_s) {
  grading_pid* pid = self;
  pid->step_s = step_s;
  pid->primed = 0;
  for (int wheel = 0; wheel < 2; ++wheel) {
    pid->integral_duty[wheel] = 0.0;
    pid->derivative_duty[wheel] = 0.0;
  }
  return 0;
}
static double clamp_duty(double duty) { return duty > 1.0 ? 1.0 : (duty < -1.0 ? -1.0 : duty); }
static int step(void* self, const double* in, double* out) {
  grading_pid* pid = self;
  const double pole = GRADING_TF / (GRADING_TF + pid->step_s);
  for (int wheel = 0; wheel < 2; ++wheel) {
    const double wheel_m = in[2 + wheel];
    const double error_m = in[wheel] - wheel_m;
    if (!pid->primed) pid->last_wheel_m[wheel] = wheel_m; /* no speed before two samples */
    pid->derivative_duty[wheel] =
        pole * pid->derivative_duty[wheel] -
        GRADING_KD / (GRADING_TF + pid->step_s) * (wheel_m - pid->last_wheel_m[wheel]);
    const double p_duty = GRADING_KP * error_m;
    const double candidate_i = pid->integral_duty[wheel] + GRADING_KI * pid->step_s * error_m;
    const double candidate_u = p_duty + candidate_i + pid->derivative_duty[wheel];
    /* While the output is beyond the limit, an error that pushes it further out must not grow
     * the integral: it would have to unwind before the output could move. */
    const int pushes_out =
        (candidate_u > 1.0 && error_m > 0.0) || (candidate_u < -1.0 && error_m < 0.0);
    if (!pushes_out) pid->integral_duty[wheel] = candidate_i;
    out[wheel] = clamp_duty(p_duty + pid->integral_duty[wheel] + pid->derivative_duty[wheel]);
    pid->last_wheel_m[wheel] = wheel_m;
  }
  pid->primed = 1;
  return 0;
}
static void finish(void* self) { (void)self; }
static void destroy(void* self) { free(self); }

static const hiltwin_controller_descriptor descriptor = {
    HILTWIN_CONTROLLER_ABI_VERSION, GRADING_STRING(GRADING_NAME), inputs, 4, outputs, 2,
    0.0, /* any step */
    create, start, step, finish, destroy, NULL};
const hiltwin_controller_descriptor* hiltwin_controller(void) { return &descriptor; }
