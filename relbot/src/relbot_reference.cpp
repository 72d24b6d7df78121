#include "hiltwin/relbot/relbot_reference.h"

// GCC 12 reports Odeint's copies of its default-constructed (deliberately uninitialised)
// fixed-size Eigen work vectors in make_dense_output as uninitialised use; they are written
// before they are read. Silenced for this file only, which is offline code.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)  // GCC's own warning group; clang (the fuzz build) has none of that name
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/external/eigen/eigen_algebra.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hiltwin::app {
namespace {

// Whole number of model steps per input period, or throw: both simulations must change the
// input exactly at step boundaries, or the comparison measures the sampling, not the solver.
std::uint64_t StepsPerHold(double input_hold_s, double step_s) {
  if (!(step_s > 0.0) || !std::isfinite(step_s) || !(input_hold_s > 0.0) ||
      !std::isfinite(input_hold_s)) {
    throw std::invalid_argument("step and input hold must be finite and > 0");
  }
  const double ratio = input_hold_s / step_s;
  const double rounded = std::round(ratio);
  if (rounded < 1.0 || std::abs(ratio - rounded) > 1e-9 * rounded) {
    throw std::invalid_argument("input hold " + std::to_string(input_hold_s) +
                                " s is not a whole multiple of the step " +
                                std::to_string(step_s) + " s");
  }
  return static_cast<std::uint64_t>(rounded);
}

std::uint64_t StepCount(double duration_s, double step_s) {
  if (!std::isfinite(duration_s) || duration_s < 0.0) {
    throw std::invalid_argument("duration must be finite and >= 0");
  }
  return static_cast<std::uint64_t>(std::llround(duration_s / step_s));
}

}  // namespace

std::vector<RelbotOutputs> SimulateReference(const RelbotParams& params,
                                             const InputProfile& profile, double duration_s,
                                             double sample_step_s,
                                             const ReferenceOptions& options) {
  namespace odeint = boost::numeric::odeint;
  ValidateRelbotParams(params, "RELbot parameters");
  const std::uint64_t per_hold = StepsPerHold(options.input_hold_s, sample_step_s);
  const std::uint64_t samples = StepCount(duration_s, sample_step_s);
  const RelbotCoefficients coefficients = MakeRelbotCoefficients(params);

  using Stepper = odeint::runge_kutta_dopri5<RelbotState, double, RelbotState, double,
                                             odeint::vector_space_algebra>;
  auto dense = odeint::make_dense_output(options.abs_tolerance, options.rel_tolerance, Stepper());

  std::vector<RelbotOutputs> outputs;
  outputs.reserve(samples);
  RelbotState x = RelbotState::Zero();
  std::vector<double> times;
  times.reserve(per_hold + 1);
  double dt_guess_s = sample_step_s;
  for (std::uint64_t first = 0; first < samples; first += per_hold) {
    // One integration per input period: the right-hand side is smooth inside it, so the
    // adaptive solver never steps across the input's discontinuities.
    const std::uint64_t last = std::min(samples, first + per_hold);
    const double t0_s = static_cast<double>(first) * sample_step_s;
    const Duty duty = profile.At(t0_s);
    const double left = SaturateDuty(duty.left);
    const double right = SaturateDuty(duty.right);
    const auto system = [&coefficients, left, right](const RelbotState& state, RelbotState& dxdt,
                                                     double /*t*/) {
      RelbotDerivative(coefficients, state, left, right, dxdt);
    };
    times.clear();
    for (std::uint64_t k = first; k <= last; ++k) {
      times.push_back(static_cast<double>(k) * sample_step_s);
    }
    RelbotState end_state = x;
    odeint::integrate_times(
        dense, system, end_state, times.begin(), times.end(), dt_guess_s,
        [&outputs, t0_s](const RelbotState& state, double t_s) {
          if (t_s > t0_s) outputs.push_back(OutputsOf(state));
        });
    x = end_state;
    dt_guess_s = std::max(dense.current_time_step(), 1e-12);
  }
  return outputs;
}

std::vector<RelbotOutputs> SimulateFixedStep(RelbotModel& model, const InputProfile& profile,
                                             double duration_s, double input_hold_s) {
  const double step_s = model.step_s();
  const std::uint64_t per_hold = StepsPerHold(input_hold_s, step_s);
  const std::uint64_t steps = StepCount(duration_s, step_s);
  std::vector<RelbotOutputs> outputs;
  outputs.reserve(steps);
  model.Reset();
  Duty duty;
  for (std::uint64_t k = 0; k < steps; ++k) {
    if (k % per_hold == 0) duty = profile.At(static_cast<double>(k) * step_s);
    model.Step(duty.left, duty.right);
    outputs.push_back(model.Outputs());
  }
  return outputs;
}

double RmsWheelPositionError(const std::vector<RelbotOutputs>& a,
                             const std::vector<RelbotOutputs>& b) noexcept {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dl = a[i].wheel_left_m - b[i].wheel_left_m;
    const double dr = a[i].wheel_right_m - b[i].wheel_right_m;
    sum_sq += dl * dl + dr * dr;
  }
  return std::sqrt(sum_sq / (2.0 * static_cast<double>(n)));
}

}  // namespace hiltwin::app

#pragma GCC diagnostic pop
