#pragma once
/// What every adapter of 20-sim's "C++ class for 20-sim submodel" code shares (docs/20sim.md;
/// thesis appendix B §1-3 and appendix F): the class shape as concepts, and TwentySimCore, which
/// owns one submodel and runs its life cycle. The plant adapter (twentysim_plant.h, `--plant
/// NAME`) and the controller adapter (controller/twentysim_controller.h, `--controller
/// 20sim:NAME`) differ only in the interface they present and the error types they throw.
///
/// 20-sim generates a class derived from Submodel20sim with Initialize(u, y, t), Calculate(u,
/// y), Terminate(u, y), SetFinishTime(t), IsFinished() and a step size compiled into its
/// constructor (m_step_size) next to an integrator member (myintegmethod). What the core calls
/// when:
///   constructor  builds the submodel (its constructor allocates the variable arrays), reads
///                m_step_size and checks it and the finish time;
///   CheckStep    the caller's step against m_step_size (the step is compiled in);
///   Initialize   SetFinishTime, Initialize(u0, y0, 0.0) (allocates the integrator's work
///                arrays), the initial outputs checked;
///   Calculate    exactly one step of m_step_size (real-time);
///   Terminate    once; Rebuild: Terminate and a fresh submodel (the class has no re-init).

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hiltwin/plant/plant.h"

namespace hiltwin::plant {

/// The caller's step may differ from m_step_size by this much: a period is whole nanoseconds
/// (--rate 3000 gives 333333 ns), so a model step of 1/3000 s can never be met exactly, and
/// anything within a nanosecond is the same step.
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
/// names) and how it is run. `hiltwin_add_20sim_plant` / `hiltwin_add_20sim_controller` fill it
/// from their CMake line.
struct TwentySimSpec {
  std::string name;           ///< --plant NAME / --controller 20sim:NAME
  std::string class_name;     ///< the submodel class, for messages ("LoopController")
  std::vector<Port> inputs;   ///< u[0], u[1], ... in order
  std::vector<Port> outputs;  ///< y[0], y[1], ... in order
  /// Passed to SetFinishTime: 0 = calculate for ever (endless HiL), overriding the finish time
  /// 20-sim compiled in; > 0 = the model stops calculating once it reaches it.
  double finish_time_s = 0.0;
  std::string integrator;  ///< myintegmethod's class as read from the header; "" = not known
  std::string source_dir;  ///< the generated folder, for the run report; may be ""
};

/// One submodel of class `Submodel` and its life cycle, for an adapter that presents it as
/// `role` ("plant", "controller") and reports trouble as `Error` (bad code or use) and
/// `StepError` (a step the code was not generated for). Not thread-safe; Calculate() is the
/// real-time path.
template <class Submodel, class Error, class StepError = Error>
class TwentySimCore {
  static_assert(std::default_initializable<Submodel>,
                "a 20-sim adapter's class C must be default-constructible, as the class 20-sim "
                "generates is (C::C() allocates the variable arrays)");
  static_assert(twentysim_detail::HasInitialize<Submodel>,
                "a 20-sim adapter's class C has no Initialize(XXDouble* u, XXDouble* y, "
                "XXDouble t): is C the class of a 20-sim 'C++ class for 20-sim submodel' header?");
  static_assert(twentysim_detail::HasCalculate<Submodel>,
                "a 20-sim adapter's class C has no Calculate(XXDouble* u, XXDouble* y)");
  static_assert(twentysim_detail::HasTerminate<Submodel>,
                "a 20-sim adapter's class C has no Terminate(XXDouble* u, XXDouble* y)");
  static_assert(twentysim_detail::HasSetFinishTime<Submodel>,
                "a 20-sim adapter's class C has no SetFinishTime(XXDouble): 20-sim 4.x "
                "generates it; older code may need it added (it sets m_finish_time)");
  static_assert(twentysim_detail::HasIsFinished<Submodel>,
                "a 20-sim adapter's class C has no bool IsFinished() (state == finished)");
  static_assert(twentysim_detail::HasStepSize<Submodel>,
                "a 20-sim adapter's class C has no public m_step_size (Submodel20sim declares "
                "it)");

 public:
  /// Builds the submodel to learn its step; throws Error when that step is not a positive
  /// number (hand-edited code) or the finish time is negative.
  TwentySimCore(TwentySimSpec spec, std::string role)
      : spec_(std::move(spec)),
        role_(std::move(role)),
        u_buf_(std::max<std::size_t>(spec_.inputs.size(), 1), 0.0),
        y_buf_(std::max<std::size_t>(spec_.outputs.size(), 1), 0.0) {
    model_.emplace();
    model_step_s_ = static_cast<double>(model_->m_step_size);
    if (!(std::isfinite(model_step_s_) && model_step_s_ > 0.0)) {
      throw Error(Who() + " has m_step_size = " + twentysim_detail::FormatNumber(model_step_s_, 9) +
                  " in " + spec_.class_name + ".cpp: it must be a positive step in seconds");
    }
    if (!(std::isfinite(spec_.finish_time_s) && spec_.finish_time_s >= 0.0)) {
      throw Error(Who() + " has finish time " +
                  twentysim_detail::FormatNumber(spec_.finish_time_s, 9) +
                  " s: use 0 (run for ever) or a positive time (FINISH_TIME in its "
                  "hiltwin_add_20sim_" +
                  role_ + " line)");
    }
    model_->SetFinishTime(spec_.finish_time_s);
  }

  ~TwentySimCore() { Terminate(); }
  TwentySimCore(const TwentySimCore&) = delete;
  TwentySimCore& operator=(const TwentySimCore&) = delete;
  TwentySimCore(TwentySimCore&&) = delete;
  TwentySimCore& operator=(TwentySimCore&&) = delete;

  [[nodiscard]] const TwentySimSpec& spec() const noexcept { return spec_; }
  [[nodiscard]] double model_step_s() const noexcept { return model_step_s_; }
  [[nodiscard]] bool initialized() const noexcept { return initialized_; }
  [[nodiscard]] bool finished() const noexcept { return finished_; }
  /// The submodel itself (m_time, m_step_size, state...), for diagnostics and tests.
  [[nodiscard]] const Submodel& model() const noexcept { return *model_; }
  /// The outputs of the last Initialize or Calculate (kept over the finished state).
  [[nodiscard]] std::span<const double> outputs() const noexcept {
    return {y_buf_.data(), spec_.outputs.size()};
  }

  /// "the 20-sim plant 'msd20sim'": how messages name the submodel.
  [[nodiscard]] std::string Who() const { return "the 20-sim " + role_ + " '" + spec_.name + "'"; }

  /// Throws StepError naming --rate when `step_s` is not the step the code was generated for.
  void CheckStep(double step_s) const {
    if (std::isfinite(step_s) && std::abs(step_s - model_step_s_) <= kTwentySimStepToleranceS) {
      return;
    }
    using twentysim_detail::FormatNumber;
    const std::string step_text = FormatNumber(step_s, 9);
    throw StepError("--rate " + FormatNumber(1.0 / step_s, 6) + " Hz gives a step of " + step_text +
                    " s but " + Who() + " was generated for a step of " +
                    FormatNumber(model_step_s_, 9) + " s (m_step_size in " + spec_.class_name +
                    ".cpp): run at --rate " + twentysim_detail::RateForStep(model_step_s_) +
                    ", or regenerate the code with step size " + step_text + " s");
  }

  /// Initialize(u0, y, 0.0) on a fresh submodel (rebuilt if this one ran before), then checks
  /// the initial outputs (outputs()). `u0` holds up to inputs.size() values, the rest are 0.
  ///
  /// Why here and not in the first Calculate: the generated Calculate() initialises on its
  /// first call (state initialrun: Initialize(u, y, 0.0), no integration) and integrates only
  /// from the second call on; left to it, the first step would not advance model time and
  /// every output would lag by one period. Calling Initialize ourselves moves the class to
  /// `mainrun`, so every Calculate() is one real step of m_step_size. It also keeps the
  /// integrator's new[] (RungeKutta4's work arrays) out of the real-time path.
  void Initialize(std::span<const double> u0) {
    if (!fresh_) Rebuild();
    std::fill(u_buf_.begin(), u_buf_.end(), 0.0);
    std::copy_n(u0.begin(), std::min(u0.size(), spec_.inputs.size()), u_buf_.begin());
    std::fill(y_buf_.begin(), y_buf_.end(), 0.0);
    model_->Initialize(u_buf_.data(), y_buf_.data(), 0.0);
    // Again after Initialize (Rebuild set it before): should a 20-sim version set
    // m_finish_time there, ours still wins, and "0 = endless" holds whatever was compiled in.
    model_->SetFinishTime(spec_.finish_time_s);
    fresh_ = false;
    initialized_ = true;
    finished_ = false;
    CheckInitialOutputs();
  }

  /// One step of m_step_size with `u` held over it; the outputs at its end are outputs().
  /// Returns false once the model has reached its finish time (the generated code then stops
  /// calculating and outputs() keeps the last values). Call only while initialized().
  bool Calculate(std::span<const double> u) noexcept {
    if (!finished_) {
      // The generated code takes XXDouble* (not const): it gets our own copy of u, in a
      // buffer sized in the constructor, and writes into our y buffer, which survives the
      // finished state (Calculate then writes nothing).
      std::copy_n(u.begin(), std::min(u.size(), spec_.inputs.size()), u_buf_.begin());
      model_->Calculate(u_buf_.data(), y_buf_.data());
      finished_ = static_cast<bool>(model_->IsFinished());
    }
    return !finished_;
  }

  [[nodiscard]] bool OutputsFinite() const noexcept {
    return std::all_of(y_buf_.begin(),
                       y_buf_.begin() + static_cast<std::ptrdiff_t>(spec_.outputs.size()),
                       [](double y) { return std::isfinite(y); });
  }

  /// Terminate once: it frees the integrator's work arrays, so a second call would free them
  /// twice in code that does not null its pointers, and a call without Initialize would free
  /// pointers never allocated.
  void Terminate() noexcept {
    if (!initialized_) return;
    model_->Terminate(u_buf_.data(), y_buf_.data());
    initialized_ = false;
  }

  /// A fresh submodel: the constructor's state (parameters, initial values, m_time = 0).
  void Rebuild() {
    Terminate();
    model_.reset();  // the old one's destructor frees its arrays before the new one allocates
    model_.emplace();
    model_->SetFinishTime(spec_.finish_time_s);
    fresh_ = true;
    finished_ = false;
  }

  /// What a plant's and a controller's Info() say alike (PlantInfo, ControllerInfo): name,
  /// kind, ports, the fixed step and the report's details.
  template <class Info>
  void Describe(Info& info) const {
    info.name = spec_.name;
    info.kind = "20-sim C++ class";
    info.inputs = spec_.inputs;
    info.outputs = spec_.outputs;
    info.model_step_s = model_step_s_;
    info.step_is_fixed = true;  // compiled into the constructor
    info.details = Details();
  }

  /// The report's facts: class, step, integrator, finish time, source folder.
  [[nodiscard]] std::vector<std::pair<std::string, std::string>> Details() const {
    using twentysim_detail::FormatNumber;
    std::vector<std::pair<std::string, std::string>> details = {
        {"class", spec_.class_name},
        {"step", FormatNumber(model_step_s_, 9) + " s (m_step_size)"},
        {"integrator",
         spec_.integrator.empty() ? std::string("not known (myintegmethod)") : spec_.integrator},
        {"finish time", spec_.finish_time_s == 0.0 ? std::string("0 s (endless)")
                                                   : FormatNumber(spec_.finish_time_s, 9) + " s"},
    };
    if (!spec_.source_dir.empty()) details.emplace_back("source", spec_.source_dir);
    return details;
  }

 private:
  void CheckInitialOutputs() {  // not const: 20-sim's IsFinished() is not
    if (model_->IsFinished()) {
      throw Error(Who() + " finished during Initialize: check m_finish_time / FINISH_TIME");
    }
    for (std::size_t i = 0; i < spec_.outputs.size(); ++i) {
      if (!std::isfinite(y_buf_[i])) {
        throw Error(Who() + " starts with output " + spec_.outputs[i].name + " (y[" +
                    std::to_string(i) + "]) non-finite: check the initial values in " +
                    spec_.class_name + ".cpp's Initialize");
      }
    }
  }

  TwentySimSpec spec_;
  std::string role_;
  double model_step_s_ = 0.0;
  std::optional<Submodel> model_;  // rebuilt by Rebuild: the generated class has no re-init
  std::vector<double> u_buf_;      // sized once: Calculate copies u here (XXDouble*, not const)
  std::vector<double> y_buf_;      // the last outputs, kept over the finished state
  bool fresh_ = true;              // constructed and not yet initialised
  bool initialized_ = false;       // Initialize ran, Terminate has not
  bool finished_ = false;          // IsFinished() after the last Calculate
};

}  // namespace hiltwin::plant
