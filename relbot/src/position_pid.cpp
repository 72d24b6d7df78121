#include "hiltwin/relbot/position_pid.h"

#include <algorithm>
#include <cmath>

namespace hiltwin::app {

PositionPid::PositionPid(const PidGains& gains, double period_s) noexcept
    : gains_(gains),
      period_s_(period_s),
      integral_per_step_duty_per_m_(gains.ki_duty_per_m_s * period_s),
      derivative_pole_(gains.derivative_filter_s / (gains.derivative_filter_s + period_s)),
      derivative_gain_duty_per_m_(gains.kd_duty_s_per_m / (gains.derivative_filter_s + period_s)) {}

void PositionPid::Reset(double measured_m) noexcept {
  integral_duty_ = 0.0;
  derivative_duty_ = 0.0;
  previous_measured_m_ = measured_m;
  primed_ = true;
  last_ = PidTerms{};
}

double PositionPid::Step(double setpoint_m, double measured_m) noexcept {
  const double error_m = setpoint_m - measured_m;
  if (!std::isfinite(error_m)) {
    // A broken input must not move the motor, nor poison the integral for later steps.
    last_ = PidTerms{0.0, integral_duty_, derivative_duty_, 0.0, false, true};
    return 0.0;
  }
  if (!primed_) Reset(measured_m);

  const double limit = gains_.duty_limit;
  const double p_duty = gains_.kp_duty_per_m * error_m;
  derivative_duty_ = derivative_pole_ * derivative_duty_ -
                     derivative_gain_duty_per_m_ * (measured_m - previous_measured_m_);
  previous_measured_m_ = measured_m;

  const double candidate_i = integral_duty_ + integral_per_step_duty_per_m_ * error_m;
  const double candidate_u = p_duty + candidate_i + derivative_duty_;
  // Conditional integration: while the output is beyond the limit, an error that pushes it
  // further out must not grow the integral (it would have to unwind before the output moves).
  const bool pushes_out =
      (candidate_u > limit && error_m > 0.0) || (candidate_u < -limit && error_m < 0.0);
  if (!pushes_out) integral_duty_ = candidate_i;

  const double unsaturated = p_duty + integral_duty_ + derivative_duty_;
  const double output = std::clamp(unsaturated, -limit, limit);
  last_ =
      PidTerms{p_duty, integral_duty_, derivative_duty_, output, output != unsaturated, pushes_out};
  return output;
}

}  // namespace hiltwin::app
