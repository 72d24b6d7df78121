// ns per RELbot model step: RelbotModel::Step (fixed-size Eigen, RK4) against Boost.Odeint's
// fixed-step runge_kutta4 with vector_space_algebra on the same state type and the same
// RelbotDerivative, so the difference is the integrator machinery alone. Rounds alternate
// between the two so that frequency changes and neighbours on the shared machine hit both;
// the median over rounds is the figure, the minimum is printed too.
//
// Usage: hiltwin_bench_relbot_step [steps_per_round=1000000] [rounds=9]

// Odeint copies its default-constructed fixed-size work vectors; GCC 12 reports that as
// uninitialised use (see relbot_reference.cpp). Silenced for this file.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/external/eigen/eigen_algebra.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_model.h"
#include "bench_stats.h"
#include "relbot_duty_samples.h"

namespace {

using hiltwin::app::Duty;
using hiltwin::app::RelbotState;
using Clock = hiltwin::bench::BenchClock;
using hiltwin::bench::Median;
using hiltwin::bench::NsPer;

constexpr double kStepS = 2.5e-4;  // 4 kHz, the thesis's RELbot twin rate

volatile double g_sink = 0.0;  // keeps the results observable

double TimeOdeint(const hiltwin::app::RelbotCoefficients& c, const std::vector<Duty>& duty,
                  long steps) {
  namespace odeint = boost::numeric::odeint;
  odeint::runge_kutta4<RelbotState, double, RelbotState, double, odeint::vector_space_algebra>
      stepper;
  RelbotState x = RelbotState::Zero();
  double t_s = 0.0;
  const auto start = Clock::now();
  for (long k = 0; k < steps; ++k) {
    const Duty& d = duty[static_cast<std::size_t>(k / 4) % duty.size()];
    const double left = hiltwin::app::SaturateDuty(d.left);
    const double right = hiltwin::app::SaturateDuty(d.right);
    stepper.do_step(
        [&c, left, right](const RelbotState& state, RelbotState& dxdt, double) {
          hiltwin::app::RelbotDerivative(c, state, left, right, dxdt);
        },
        x, t_s, kStepS);
    t_s += kStepS;
  }
  const auto end = Clock::now();
  g_sink = g_sink + x[hiltwin::app::relbot_state::kWheelPositionLeftM];
  return NsPer(start, end, steps);
}

double TimeDerivative(const hiltwin::app::RelbotCoefficients& c, long evaluations) {
  RelbotState x = RelbotState::Zero();
  x[hiltwin::app::relbot_state::kBodyVelocityXMPerS] = 0.3;
  RelbotState dxdt;
  const auto start = Clock::now();
  for (long k = 0; k < evaluations; ++k) {
    hiltwin::app::RelbotDerivative(c, x, 0.5, 0.4, dxdt);
    x[hiltwin::app::relbot_state::kHeadingRad] += 1e-6 * dxdt[0];  // depends on the last result
  }
  const auto end = Clock::now();
  g_sink = g_sink + x[hiltwin::app::relbot_state::kHeadingRad];
  return NsPer(start, end, evaluations);
}

double TimeHiltwin(hiltwin::app::RelbotModel& model, const std::vector<Duty>& duty, long steps) {
  return hiltwin::bench::TimeRelbotSteps(model, duty, steps, g_sink);
}

}  // namespace

int main(int argc, char** argv) {
  const auto arguments = hiltwin::bench::ParseStepsAndRounds(argc, argv);
  if (!arguments) return 2;
  const auto [steps, rounds] = *arguments;
  const std::vector<Duty> duty = hiltwin::bench::OpenLoopDutiesAt1kHz();
  const hiltwin::app::RelbotParams params;
  hiltwin::app::RelbotModel rk4(params, hiltwin::app::Integrator::kRk4, kStepS);
  hiltwin::app::RelbotModel rk2(params, hiltwin::app::Integrator::kRk2, kStepS);
  hiltwin::app::RelbotModel euler(params, hiltwin::app::Integrator::kEuler, kStepS);

  // Warm-up: caches, branch predictors, CPU frequency.
  (void)TimeHiltwin(rk4, duty, steps / 4);
  (void)TimeOdeint(rk4.coefficients(), duty, steps / 4);

  std::vector<double> ours_ns;
  std::vector<double> odeint_ns;
  std::vector<double> rk2_ns;
  std::vector<double> euler_ns;
  std::vector<double> derivative_ns;
  for (int r = 0; r < rounds; ++r) {
    ours_ns.push_back(TimeHiltwin(rk4, duty, steps));
    odeint_ns.push_back(TimeOdeint(rk4.coefficients(), duty, steps));
    rk2_ns.push_back(TimeHiltwin(rk2, duty, steps));
    euler_ns.push_back(TimeHiltwin(euler, duty, steps));
    derivative_ns.push_back(TimeDerivative(rk4.coefficients(), steps));
  }
  const double ours = Median(ours_ns);
  const double peer = Median(odeint_ns);
  std::printf("relbot_step: %ld steps x %d rounds per variant, 12 states, step %.0f us, "
              "openloop duties; median (min) ns per step\n",
              steps, rounds, kStepS * 1e6);
  std::printf("  hiltwin RelbotModel::Step rk4      %7.1f  (%7.1f)\n", ours,
              hiltwin::bench::MinOf(ours_ns));
  std::printf("  Boost.Odeint runge_kutta4, same f  %7.1f  (%7.1f)\n", peer,
              hiltwin::bench::MinOf(odeint_ns));
  std::printf("  ratio hiltwin / odeint             %7.2f   target <= 1.00: %s\n", ours / peer,
              ours / peer <= 1.0 ? "met" : "NOT met");
  std::printf("  rk4 step vs 300 ns target          %7.1f   %s\n", ours,
              ours <= 300.0 ? "met" : "NOT met");
  std::printf("  for context: rk2 %.1f, euler %.1f, one RelbotDerivative call %.1f\n",
              Median(rk2_ns), Median(euler_ns), Median(derivative_ns));
  return 0;
}

#pragma GCC diagnostic pop
