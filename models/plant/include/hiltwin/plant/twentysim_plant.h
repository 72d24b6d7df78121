#pragma once
/// A plant made of 20-sim's "C++ class for 20-sim submodel" code (docs/20sim.md; thesis appendix
/// B §1-3). TwentySimPlant wraps any class of that shape (twentysim_submodel.h: the shape, and
/// the life cycle the controller adapter shares); `hiltwin_add_20sim_plant`
/// (cmake/TwentySimPlant.cmake) instantiates it for a generated folder and registers it under
/// the plant's name.
///
/// What the adapter calls when:
///   constructor  builds the submodel and reads m_step_size for Info();
///   Start        checks the twin's step against m_step_size, then Initialize(u0, y0, 0.0)
///                with the plant map's constants as u0 (TwentySimCore::Initialize);
///   Step         Calculate(u, y): exactly one step of m_step_size (real-time);
///   Reset        Terminate, a fresh submodel, Start again at the same step;
///   Finish       Terminate, once.

#include <algorithm>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_registry.h"
#include "hiltwin/plant/twentysim_submodel.h"

namespace hiltwin::plant {

/// The plant's name for the shared spec (hiltwin_add_20sim_plant fills it).
using TwentySimPlantSpec = TwentySimSpec;

/// Throws PlantError for the PlantOptions a 20-sim plant cannot honour (--config, --integrator):
/// the generated code has its parameters and integrator compiled in.
inline void RefuseTwentySimOptions(const PlantOptions& options, std::string_view plant_name,
                                   std::string_view class_name) {
  std::string flag;
  if (!options.config_path.empty()) {
    flag = "--config " + options.config_path;
  } else if (!options.integrator.empty()) {
    flag = "--integrator " + options.integrator;
  } else {
    return;
  }
  std::string message = flag + " cannot be honoured: the 20-sim plant '";
  message.append(plant_name).append("' has its parameters and integrator compiled in: ");
  message.append("change them in 20-sim and regenerate, or edit m_step_size / myintegmethod in ");
  message.append(class_name).append(".cpp/.h as thesis appendix B §3 says (docs/20sim.md)");
  throw PlantError(message);
}

/// Any 20-sim submodel class as a Plant. Not thread-safe; Step() is the real-time path.
template <class Submodel>
class TwentySimPlant final : public Plant {
 public:
  /// Builds the submodel to learn its step; throws PlantError when that step is not a
  /// positive number (hand-edited code) or the finish time is negative.
  explicit TwentySimPlant(TwentySimPlantSpec spec) : core_(std::move(spec), "plant") {
    core_.Describe(info_);
  }

  ~TwentySimPlant() override = default;  // the core terminates the submodel
  TwentySimPlant(const TwentySimPlant&) = delete;
  TwentySimPlant& operator=(const TwentySimPlant&) = delete;
  TwentySimPlant(TwentySimPlant&&) = delete;
  TwentySimPlant& operator=(TwentySimPlant&&) = delete;

  [[nodiscard]] const PlantInfo& Info() const noexcept override { return info_; }

  /// Held for Start and Reset: Initialize computes the initial outputs from them.
  void SetInitialInputs(std::span<const double> u0) override {
    if (u0.size() != info_.inputs.size()) {
      throw PlantError(core_.Who() + " has " + std::to_string(info_.inputs.size()) +
                       " inputs, SetInitialInputs was given " + std::to_string(u0.size()) +
                       " values");
    }
    initial_u_.assign(u0.begin(), u0.end());
  }

  void Start(double step_s, std::span<double> y0) override {
    core_.CheckStep(step_s);
    if (y0.size() != info_.outputs.size()) {
      throw PlantError(core_.Who() + " has " + std::to_string(info_.outputs.size()) +
                       " outputs, Start was given " + std::to_string(y0.size()) + " values");
    }
    // No board inputs exist yet: the initial outputs are computed with the plant map's
    // constants (SetInitialInputs) and 0 for the PWM-driven inputs.
    core_.Initialize(initial_u_);
    step_s_ = step_s;
    std::copy_n(core_.outputs().begin(), y0.size(), y0.begin());
  }

  /// One step of m_step_size with `u` held over it. Writes the outputs at its end into `y`;
  /// once the model has reached its finish time, keeps writing the last outputs and returns
  /// kFinished (the generated code stops calculating).
  [[nodiscard]] PlantStatus Step(std::span<const double> u, std::span<double> y) noexcept override {
    if (!core_.initialized()) {
      return PlantStatus::Fault("the 20-sim plant was stepped before Start or after Finish");
    }
    const bool running = core_.Calculate(u);
    const std::span<const double> out = core_.outputs();
    std::copy_n(out.begin(), std::min(y.size(), out.size()), y.begin());
    if (!running) {
      return PlantStatus::Finished("the 20-sim model reached its finish time (m_finish_time)");
    }
    if (!core_.OutputsFinite()) {
      return PlantStatus::Fault("the 20-sim model's output became non-finite (NaN or Inf)");
    }
    return PlantStatus::Ok();
  }

  /// A fresh submodel (the constructor's state: parameters, initial values, m_time = 0),
  /// started again at the step of the last Start.
  void Reset(std::span<double> y0) override {
    if (step_s_ <= 0.0) throw PlantError(core_.Who() + " was reset before Start");
    core_.Rebuild();
    Start(step_s_, y0);
  }

  void Finish() noexcept override { core_.Terminate(); }

  /// The submodel itself (m_time, m_step_size, state...), for diagnostics and tests.
  [[nodiscard]] const Submodel& model() const noexcept { return core_.model(); }

 private:
  TwentySimCore<Submodel, PlantError, PlantStepError> core_;
  PlantInfo info_;
  std::vector<double> initial_u_;  // SetInitialInputs' values; empty: all 0
  double step_s_ = 0.0;            // of the last Start; 0 before it
};

}  // namespace hiltwin::plant
