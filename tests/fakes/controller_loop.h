#pragma once
// What the tests of controllers that implement the ECS's position PID share (the 20-sim
// example models/controllers/pid20sim, the FMU tests/fmus/pid): the control law restated by
// hand, the allocation count of Step, and the thesis's 2.5 m closed loop against the RELbot
// model in process.
//
// The closed loop: the RELbot model (RK4 at the twin's rate) and the controller at the ECS's
// rate on one virtual timeline, without the boards: at each ECS sample the controller reads the
// setpoint of the built-in `closedloop` profile and each wheel's travel as its encoder counts it
// (whole counts), and its duties are held over the twin's steps until the next sample. The
// boards' own delays and quantisation are tests/unit/app/in_process_hil.h's; this rig holds the
// control law and the adapter, so it needs only the model.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/controller/controller.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/setpoint_profile.h"

namespace hiltwin::test {

// The ECS's built-in gains (relbot/ecs_gains.toml), restated: the controllers under test have
// them compiled in, so the expected values do not come from the code under test.
struct HandPidGains {
  double kp_duty_per_m = 100.0;
  double ki_duty_per_m_s = 1000.0;
  double kd_duty_s_per_m = 3.0;
  double tf_s = 0.005;
  double limit = 1.0;
};

// One wheel of the law in position_pid.h, step by step, as written in its comment.
class HandPid {
 public:
  explicit HandPid(double period_s, HandPidGains gains = {}) : t_s_(period_s), g_(gains) {}

  double Step(double setpoint_m, double measured_m) {
    const double e = setpoint_m - measured_m;
    p_ = g_.kp_duty_per_m * e;
    d_ = g_.tf_s / (g_.tf_s + t_s_) * d_ -
         g_.kd_duty_s_per_m / (g_.tf_s + t_s_) * (measured_m - previous_m_);
    previous_m_ = measured_m;
    const double candidate_i = i_ + g_.ki_duty_per_m_s * t_s_ * e;
    const double candidate = p_ + candidate_i + d_;
    const bool pushes_out = (candidate > g_.limit && e > 0.0) || (candidate < -g_.limit && e < 0.0);
    if (!pushes_out) i_ = candidate_i;
    return std::clamp(p_ + i_ + d_, -g_.limit, g_.limit);
  }
  [[nodiscard]] double p() const { return p_; }
  [[nodiscard]] double i() const { return i_; }
  [[nodiscard]] double d() const { return d_; }

 private:
  double t_s_;
  HandPidGains g_;
  double p_ = 0.0;
  double i_ = 0.0;
  double d_ = 0.0;
  double previous_m_ = 0.0;  // the wheels start at 0 m
};

// The index of the port named `name`; throws (a test set-up error) when there is none.
inline std::size_t PortIndex(const std::vector<controller::Port>& ports, const std::string& name) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  throw std::invalid_argument("the controller has no port " + name);
}

// The RELbot's default controller wiring (controller_registry.h), by port name.
struct PidPorts {
  std::size_t setpoint_left;
  std::size_t setpoint_right;
  std::size_t wheel_left;
  std::size_t wheel_right;
  std::size_t duty_left;
  std::size_t duty_right;
};
inline PidPorts PidPortsOf(const controller::ControllerInfo& info) {
  return {PortIndex(info.inputs, "setpoint_left_m"), PortIndex(info.inputs, "setpoint_right_m"),
          PortIndex(info.inputs, "wheel_left_m"),    PortIndex(info.inputs, "wheel_right_m"),
          PortIndex(info.outputs, "duty_left"),      PortIndex(info.outputs, "duty_right")};
}

// What `steps` calls of Step(in, out) on a started controller allocated (operator new always;
// malloc when the counter can see it), and how many of them did not return ok.
struct StepAllocations {
  std::uint64_t allocations = 0;
  int not_ok = 0;
};
inline StepAllocations CountStepAllocations(controller::Controller& controller,
                                            std::span<const double> in, int steps = 10'000) {
  std::vector<double> out(controller.Info().outputs.size(), 0.0);
  StepAllocations result;
  {
    const ScopedAllocationCount count;
    for (int k = 0; k < steps; ++k) result.not_ok += controller.Step(in, out).ok() ? 0 : 1;
    result.allocations = count.count();
  }
  return result;
}

struct ClosedLoopFigures {
  double max_abs_error_left_m = 0.0;  ///< setpoint - true travel, at every ECS sample
  double max_abs_error_right_m = 0.0;
  double final_error_left_m = 0.0;
  double final_error_right_m = 0.0;
  double max_abs_duty = 0.0;
  std::size_t steps_not_ok = 0;
};

// The figures as test properties (in --gtest_output=xml), so a run shows them, not only pass.
inline void RecordClosedLoopFigures(const ClosedLoopFigures& run) {
  ::testing::Test::RecordProperty("max_abs_error_left_mm",
                                  std::to_string(run.max_abs_error_left_m * 1e3));
  ::testing::Test::RecordProperty("max_abs_error_right_mm",
                                  std::to_string(run.max_abs_error_right_m * 1e3));
  ::testing::Test::RecordProperty("final_error_left_mm",
                                  std::to_string(run.final_error_left_m * 1e3));
  ::testing::Test::RecordProperty("max_abs_duty", std::to_string(run.max_abs_duty));
}

// Runs `controller` (started here at the ECS's step) against the RELbot model over the whole
// `closedloop` profile.
inline ClosedLoopFigures RunRelbotClosedLoop(controller::Controller& controller,
                                             double ecs_rate_hz = 1000.0,
                                             double twin_rate_hz = 4000.0) {
  const app::RelbotParams params = app::DefaultRelbotParams();
  app::RelbotModel model(params, app::Integrator::kRk4, 1.0 / twin_rate_hz);
  const app::SetpointProfile profile = app::ClosedLoopProfile();
  const double counts_per_m = app::EncoderCountsPerMetre(params);
  const auto twin_steps_per_sample = static_cast<int>(std::lround(twin_rate_hz / ecs_rate_hz));
  const double period_s = 1.0 / ecs_rate_hz;
  const PidPorts ports = PidPortsOf(controller.Info());
  std::vector<double> in(controller.Info().inputs.size(), 0.0);
  std::vector<double> out(controller.Info().outputs.size(), 0.0);
  controller.Start(period_s);

  ClosedLoopFigures figures;
  const auto samples = static_cast<long>(std::lround(profile.length_s() * ecs_rate_hz));
  for (long k = 0; k <= samples; ++k) {
    const app::WheelPositions setpoint = profile.At(static_cast<double>(k) * period_s);
    const app::RelbotOutputs truth = model.Outputs();
    in[ports.setpoint_left] = setpoint.left_m;
    in[ports.setpoint_right] = setpoint.right_m;
    in[ports.wheel_left] = std::floor(truth.wheel_left_m * counts_per_m) / counts_per_m;
    in[ports.wheel_right] = std::floor(truth.wheel_right_m * counts_per_m) / counts_per_m;
    if (!controller.Step(in, out).ok()) ++figures.steps_not_ok;
    figures.final_error_left_m = setpoint.left_m - truth.wheel_left_m;
    figures.final_error_right_m = setpoint.right_m - truth.wheel_right_m;
    figures.max_abs_error_left_m =
        std::max(figures.max_abs_error_left_m, std::abs(figures.final_error_left_m));
    figures.max_abs_error_right_m =
        std::max(figures.max_abs_error_right_m, std::abs(figures.final_error_right_m));
    const double duty_left = out[ports.duty_left];
    const double duty_right = out[ports.duty_right];
    figures.max_abs_duty =
        std::max({figures.max_abs_duty, std::abs(duty_left), std::abs(duty_right)});
    for (int j = 0; j < twin_steps_per_sample; ++j) model.Step(duty_left, duty_right);
  }
  controller.Finish();
  return figures;
}

}  // namespace hiltwin::test
