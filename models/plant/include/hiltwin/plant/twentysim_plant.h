#pragma once
/// A plant made of 20-sim's "C++ class for 20-sim submodel" code (docs/20sim.md; thesis appendix
/// B §1-3). 20-sim generates a class derived from Submodel20sim with Initialize(u, y, t),
/// Calculate(u, y), Terminate(u, y), SetFinishTime(t), IsFinished() and a step size compiled into
/// its constructor (m_step_size) next to an integrator member (myintegmethod). TwentySimPlant
/// wraps any class of that shape; `hiltwin_add_20sim_plant` (cmake/TwentySimPlant.cmake)
/// instantiates it for a generated folder and registers it under the plant's name.
///
/// What the adapter calls when:
///   constructor  builds the submodel (its constructor allocates the variable arrays) and reads
///                m_step_size for Info();
///   Start        checks the twin's step against m_step_size, SetFinishTime(finish time), then
///                Initialize(u = 0, y0, 0.0) (allocates the integrator's work arrays);
///   Step         Calculate(u, y): exactly one step of m_step_size (real-time);
///   Reset        Terminate, a fresh submodel, Start again at the same step;
///   Finish       Terminate, once.

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hiltwin/plant/plant.h"
#include "hiltwin/plant/plant_registry.h"

namespace hiltwin::plant {

/// The twin's step may differ from m_step_size by this much: the twin's period is whole
/// nanoseconds (--rate 3000 gives 333333 ns), so a model step of 1/3000 s can never be met
/// exactly, and anything within a nanosecond is the same step.
inline constexpr double kTwentySimStepToleranceS = 1e-9;

namespace twentysim_detail {

// One concept per member, so that a class of the wrong shape fails on a static_assert that
// names the missing member instead of a page of template diagnostics. XXDouble is double in
// every 20-sim version (xxtypes.h), so the signatures are spelled with double.
template <class M>
concept HasInitialize = requires(M& m, double* u, double* y, double t) {
  m.Initialize(u, y, t);
};
template <class M>
concept HasCalculate = requires(M& m, double* u, double* y) {
  m.Calculate(u, y);
};
template <class M>
concept HasTerminate = requires(M& m, double* u, double* y) {
  m.Terminate(u, y);
};
template <class M>
concept HasSetFinishTime = requires(M& m, double t) {
  m.SetFinishTime(t);
};
template <class M>
concept HasIsFinished = requires(M& m) {
  { m.IsFinished() } -> std::convertible_to<bool>;
};
template <class M>
concept HasStepSize = requires(const M& m) {
  { m.m_step_size } -> std::convertible_to<double>;
};

inline std::string FormatNumber(double value, int significant_digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", significant_digits, value);
  return text;
}

/// The shortest rate in Hz whose whole-nanosecond period (kernel_glue::PeriodNsFromRateHz
/// rounds 1e9 / rate) meets `model_step_s` within the tolerance: "1000" for 0.001 s, "3000"
/// for 1/3000 s, and as many digits as it takes for an odd step.
inline std::string RateForStep(double model_step_s) {
  for (int digits = 6; digits <= 17; ++digits) {
    std::string text = FormatNumber(1.0 / model_step_s, digits);
    const double rate_hz = std::strtod(text.c_str(), nullptr);
    const double period_s = std::floor(1e9 / rate_hz + 0.5) * 1e-9;
    if (std::abs(period_s - model_step_s) <= kTwentySimStepToleranceS) return text;
  }
  return FormatNumber(1.0 / model_step_s, 17);
}

}  // namespace twentysim_detail

/// A class of the shape 20-sim generates for "C++ class for 20-sim submodel".
template <class M>
concept TwentySimSubmodel = std::default_initializable<M> && twentysim_detail::HasInitialize<M> &&
    twentysim_detail::HasCalculate<M> && twentysim_detail::HasTerminate<M> &&
    twentysim_detail::HasSetFinishTime<M> && twentysim_detail::HasIsFinished<M> &&
    twentysim_detail::HasStepSize<M>;

/// What the generated code cannot say about itself: its ports (20-sim's u[] and y[] carry no
/// names) and how the twin runs it. `hiltwin_add_20sim_plant` fills it from its CMake line.
struct TwentySimPlantSpec {
  std::string plant_name;     ///< --plant NAME
  std::string class_name;     ///< the submodel class, for messages ("LoopController")
  std::vector<Port> inputs;   ///< u[0], u[1], ... in order
  std::vector<Port> outputs;  ///< y[0], y[1], ... in order
  /// Passed to SetFinishTime: 0 = calculate for ever (endless HiL), overriding the finish time
  /// 20-sim compiled in; > 0 = Step reports kFinished once the model reaches it.
  double finish_time_s = 0.0;
  std::string integrator;  ///< myintegmethod's class as read from the header; "" = not known
  std::string source_dir;  ///< the generated folder, for the run report; may be ""
};

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
  static_assert(std::default_initializable<Submodel>,
                "TwentySimPlant<C>: C must be default-constructible, as the class 20-sim "
                "generates is (C::C() allocates the variable arrays)");
  static_assert(twentysim_detail::HasInitialize<Submodel>,
                "TwentySimPlant<C>: C has no Initialize(XXDouble* u, XXDouble* y, XXDouble t): "
                "is C the class of a 20-sim 'C++ class for 20-sim submodel' header?");
  static_assert(twentysim_detail::HasCalculate<Submodel>,
                "TwentySimPlant<C>: C has no Calculate(XXDouble* u, XXDouble* y)");
  static_assert(twentysim_detail::HasTerminate<Submodel>,
                "TwentySimPlant<C>: C has no Terminate(XXDouble* u, XXDouble* y)");
  static_assert(twentysim_detail::HasSetFinishTime<Submodel>,
                "TwentySimPlant<C>: C has no SetFinishTime(XXDouble): 20-sim 4.x generates "
                "it; older code may need it added (it sets m_finish_time)");
  static_assert(twentysim_detail::HasIsFinished<Submodel>,
                "TwentySimPlant<C>: C has no bool IsFinished() (state == finished)");
  static_assert(twentysim_detail::HasStepSize<Submodel>,
                "TwentySimPlant<C>: C has no public m_step_size (Submodel20sim declares it)");

 public:
  /// Builds the submodel to learn its step; throws PlantError when that step is not a
  /// positive number (hand-edited code) or the finish time is negative.
  explicit TwentySimPlant(TwentySimPlantSpec spec)
      : spec_(std::move(spec)),
        u_buf_(std::max<std::size_t>(spec_.inputs.size(), 1), 0.0),
        y_buf_(std::max<std::size_t>(spec_.outputs.size(), 1), 0.0) {
    model_.emplace();
    model_step_s_ = static_cast<double>(model_->m_step_size);
    if (!(std::isfinite(model_step_s_) && model_step_s_ > 0.0)) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name +
                       "' has m_step_size = " + twentysim_detail::FormatNumber(model_step_s_, 9) +
                       " in " + spec_.class_name + ".cpp: it must be a positive step in seconds");
    }
    if (!(std::isfinite(spec_.finish_time_s) && spec_.finish_time_s >= 0.0)) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name + "' has finish time " +
                       twentysim_detail::FormatNumber(spec_.finish_time_s, 9) +
                       " s: use 0 (run for ever) or a positive time (FINISH_TIME in "
                       "plants/CMakeLists.txt)");
    }
    model_->SetFinishTime(spec_.finish_time_s);
    info_ = MakeInfo();
  }

  ~TwentySimPlant() override { Finish(); }
  TwentySimPlant(const TwentySimPlant&) = delete;
  TwentySimPlant& operator=(const TwentySimPlant&) = delete;
  TwentySimPlant(TwentySimPlant&&) = delete;
  TwentySimPlant& operator=(TwentySimPlant&&) = delete;

  [[nodiscard]] const PlantInfo& Info() const noexcept override { return info_; }

  /// Held for Start and Reset: Initialize computes the initial outputs from them.
  void SetInitialInputs(std::span<const double> u0) override {
    if (u0.size() != spec_.inputs.size()) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name + "' has " +
                       std::to_string(spec_.inputs.size()) + " inputs, SetInitialInputs was " +
                       "given " + std::to_string(u0.size()) + " values");
    }
    initial_u_.assign(u0.begin(), u0.end());
  }

  void Start(double step_s, std::span<double> y0) override {
    CheckStep(step_s);
    if (y0.size() != spec_.outputs.size()) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name + "' has " +
                       std::to_string(spec_.outputs.size()) + " outputs, Start was given " +
                       std::to_string(y0.size()) + " values");
    }
    if (!fresh_) Rebuild();  // a second Start begins from the constructor's state again
    std::fill(u_buf_.begin(), u_buf_.end(), 0.0);
    std::copy(initial_u_.begin(), initial_u_.end(), u_buf_.begin());
    std::fill(y_buf_.begin(), y_buf_.end(), 0.0);
    // Initialise here, not in the first Step. The generated Calculate() initialises on its
    // first call (state initialrun: Initialize(u, y, 0.0), no integration) and integrates only
    // from the second call on; left to Step, the twin's first cycle would not advance model
    // time, and every output would lag the board by one period. Calling Initialize ourselves
    // moves the class to `mainrun`, so every Calculate() is one real step of m_step_size. It
    // also keeps the integrator's new[] (RungeKutta4's work arrays) out of the real-time path.
    // No board inputs exist yet: the initial outputs are computed with the plant map's
    // constants (SetInitialInputs) and 0 for the PWM-driven inputs.
    model_->Initialize(u_buf_.data(), y_buf_.data(), 0.0);
    // Again after Initialize (Rebuild set it before): should a 20-sim version set m_finish_time
    // there, ours still wins, and "0 = endless" holds whatever the generator compiled in.
    model_->SetFinishTime(spec_.finish_time_s);
    fresh_ = false;
    initialized_ = true;
    finished_ = false;
    step_s_ = step_s;
    CheckInitialOutputs();
    std::copy_n(y_buf_.begin(), y0.size(), y0.begin());
  }

  /// One step of m_step_size with `u` held over it. Writes the outputs at its end into `y`;
  /// once the model has reached its finish time, keeps writing the last outputs and returns
  /// kFinished (the generated code stops calculating).
  [[nodiscard]] PlantStatus Step(std::span<const double> u, std::span<double> y) noexcept override {
    if (!initialized_) {
      return PlantStatus::Fault("the 20-sim plant was stepped before Start or after Finish");
    }
    if (!finished_) {
      // The generated code takes XXDouble* (not const): it gets our own copy of u, in a
      // buffer sized in the constructor, and writes into our y buffer, which survives the
      // finished state (Calculate then writes nothing).
      std::copy_n(u.begin(), std::min(u.size(), spec_.inputs.size()), u_buf_.begin());
      model_->Calculate(u_buf_.data(), y_buf_.data());
      finished_ = static_cast<bool>(model_->IsFinished());
    }
    std::copy_n(y_buf_.begin(), std::min(y.size(), spec_.outputs.size()), y.begin());
    if (finished_) {
      return PlantStatus::Finished("the 20-sim model reached its finish time (m_finish_time)");
    }
    for (std::size_t i = 0; i < spec_.outputs.size(); ++i) {
      if (!std::isfinite(y_buf_[i])) {
        return PlantStatus::Fault("the 20-sim model's output became non-finite (NaN or Inf)");
      }
    }
    return PlantStatus::Ok();
  }

  /// A fresh submodel (the constructor's state: parameters, initial values, m_time = 0),
  /// started again at the step of the last Start.
  void Reset(std::span<double> y0) override {
    if (step_s_ <= 0.0) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name + "' was reset before Start");
    }
    Rebuild();
    Start(step_s_, y0);
  }

  /// Terminate once: it frees the integrator's work arrays, so a second call would free them
  /// twice in code that does not null its pointers, and a call without Initialize would free
  /// pointers never allocated.
  void Finish() noexcept override {
    if (!initialized_) return;
    model_->Terminate(u_buf_.data(), y_buf_.data());
    initialized_ = false;
  }

  /// The submodel itself (m_time, m_step_size, state...), for diagnostics and tests.
  [[nodiscard]] const Submodel& model() const noexcept { return *model_; }

 private:
  PlantInfo MakeInfo() const {
    PlantInfo info;
    info.name = spec_.plant_name;
    info.kind = "20-sim C++ class";
    info.inputs = spec_.inputs;
    info.outputs = spec_.outputs;
    info.model_step_s = model_step_s_;
    info.step_is_fixed = true;  // compiled into the constructor
    info.details = {
        {"class", spec_.class_name},
        {"step", twentysim_detail::FormatNumber(model_step_s_, 9) + " s (m_step_size)"},
        {"integrator",
         spec_.integrator.empty() ? std::string("not known (myintegmethod)") : spec_.integrator},
        {"finish time", spec_.finish_time_s == 0.0
                            ? std::string("0 s (endless)")
                            : twentysim_detail::FormatNumber(spec_.finish_time_s, 9) + " s"},
    };
    if (!spec_.source_dir.empty()) info.details.emplace_back("source", spec_.source_dir);
    return info;
  }

  void CheckStep(double step_s) const {
    if (std::isfinite(step_s) && std::abs(step_s - model_step_s_) <= kTwentySimStepToleranceS) {
      return;
    }
    using twentysim_detail::FormatNumber;
    const std::string step_text = FormatNumber(step_s, 9);
    throw PlantStepError("--rate " + FormatNumber(1.0 / step_s, 6) + " Hz gives a step of " +
                         step_text + " s but the 20-sim plant '" + spec_.plant_name +
                         "' was generated for a step of " + FormatNumber(model_step_s_, 9) +
                         " s (m_step_size in " + spec_.class_name + ".cpp): run at --rate " +
                         twentysim_detail::RateForStep(model_step_s_) +
                         ", or regenerate the code with step size " + step_text + " s");
  }

  void CheckInitialOutputs() {  // not const: 20-sim's IsFinished() is not
    if (model_->IsFinished()) {
      throw PlantError("the 20-sim plant '" + spec_.plant_name +
                       "' finished during Initialize: check m_finish_time / FINISH_TIME");
    }
    for (std::size_t i = 0; i < spec_.outputs.size(); ++i) {
      if (!std::isfinite(y_buf_[i])) {
        throw PlantError("the 20-sim plant '" + spec_.plant_name + "' starts with output " +
                         spec_.outputs[i].name + " (y[" + std::to_string(i) +
                         "]) non-finite: check the initial values in " + spec_.class_name +
                         ".cpp's Initialize");
      }
    }
  }

  void Rebuild() {
    Finish();
    model_.reset();  // the old one's destructor frees its arrays before the new one allocates
    model_.emplace();
    model_->SetFinishTime(spec_.finish_time_s);
    fresh_ = true;
    finished_ = false;
  }

  TwentySimPlantSpec spec_;
  PlantInfo info_;
  double model_step_s_ = 0.0;
  std::optional<Submodel> model_;  // rebuilt by Reset: the generated class has no re-init
  std::vector<double> u_buf_;      // sized once: Step copies u here (XXDouble*, not const)
  std::vector<double> initial_u_;  // SetInitialInputs' values; empty: all 0
  std::vector<double> y_buf_;      // the last outputs, kept over the finished state
  double step_s_ = 0.0;            // of the last Start; 0 before it
  bool fresh_ = true;              // constructed and not yet initialised
  bool initialized_ = false;       // Initialize ran, Terminate has not
  bool finished_ = false;          // IsFinished() after the last Calculate
};

}  // namespace hiltwin::plant
