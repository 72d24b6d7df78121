#pragma once
/// Offline simulations of the RELbot for comparison (the role 20-sim plays in thesis ch. 5):
/// an independent reference integrated by Boost.Odeint's adaptive Dormand-Prince 5(4) with
/// dense output, and the twin's own fixed-step model driven by the same sampled inputs.
/// Both hold the profile's duty constant over each input period, as the PWM path does when a
/// controller updates at 1/input_hold_s. Not for the real-time path (they allocate results).

#include <vector>

#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_model.h"

namespace hiltwin::app {

/// How inputs are sampled and how tight the reference integration is.
struct ReferenceOptions {
  double input_hold_s = 1.0e-3;  ///< duty sampled from the profile at k*input_hold_s and held
  double abs_tolerance = 1.0e-10;
  double rel_tolerance = 1.0e-10;
};

/// Outputs at t = k * sample_step_s for k = 1 .. round(duration_s / sample_step_s), from rest.
/// input_hold_s must be a whole multiple of sample_step_s. Throws std::invalid_argument.
[[nodiscard]] std::vector<RelbotOutputs> SimulateReference(const RelbotParams& params,
                                                           const InputProfile& profile,
                                                           double duration_s, double sample_step_s,
                                                           const ReferenceOptions& options = {});

/// The same experiment with RelbotModel (its integrator and step_s): outputs after each step.
/// `model` is Reset() first. Throws std::invalid_argument as SimulateReference.
[[nodiscard]] std::vector<RelbotOutputs> SimulateFixedStep(RelbotModel& model,
                                                           const InputProfile& profile,
                                                           double duration_s,
                                                           double input_hold_s = 1.0e-3);

/// Root mean square of the wheel-position differences (both wheels) over the common samples.
[[nodiscard]] double RmsWheelPositionError(const std::vector<RelbotOutputs>& a,
                                           const std::vector<RelbotOutputs>& b) noexcept;

}  // namespace hiltwin::app
