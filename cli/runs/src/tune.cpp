// `hiltwin tune` (tune.h): measure, recommend, validate. The maths is tuning/tuning.h's;
// this file measures and runs, always through the shared run assembly and the twin of
// `hiltwin run` (twin_build.h).
#include "hiltwin/runs/tune.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "hiltwin/io/conversions.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/relbot/relbot_reference.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/trajectory_recorder.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/scheduler/executive.h"
#include "tune_measure.h"

namespace hiltwin::app {
namespace {

bool IsVirtual(const TuneOptions& o) { return o.clock == runtime::ClockKind::kVirtual; }

bool AllInjected(const TuneOptions& o) {
  return o.inject_compute_us && o.inject_overhead_us && o.inject_latency_us;
}

kernel_glue::TimeNs NsOfUs(double us) {
  return static_cast<kernel_glue::TimeNs>(std::llround(us * 1e3));
}

void CheckInjection(const std::optional<double>& us, const char* flag, const TuneOptions& o) {
  if (!us) return;
  if (!IsVirtual(o)) {
    ThrowUsage(std::string(flag) +
          ": injected costs replace measurements on the virtual clock only; "
          "add --clock virtual, or drop it to measure this machine");
  }
  if (!std::isfinite(*us) || *us < 0.0 || *us > 1e6) {
    ThrowUsage(std::string(flag) + " " + Num(*us) + ": must be 0 .. 1000000 microseconds");
  }
}

/// Refuses, before anything is measured, a lowest candidate the model cannot integrate
/// stably (the run would refuse it only after minutes of measuring).
void CheckModelRunsAt(const TuneOptions& o, double rate_hz) {
  Twin twin;
  LoadTwinConfiguration(TwinOptionsFor(o, rate_hz, o.validate_seconds, true), twin);
  const double max_step_s = RelbotMaxStableStepS(twin.params, twin.integrator);
  if (1.0 / rate_hz > max_step_s) {
    ThrowUsage("--candidates: " + Num(rate_hz) + " Hz is too slow for the " +
          std::string(IntegratorName(twin.integrator)) + " integrator to run this model stably " +
          "(it needs at least " + Num(std::ceil(1.0 / max_step_s)) +
          " Hz); drop it or choose another --integrator");
  }
}

/// The cost tables a virtual validation run replays: each step costs a measured (or the
/// injected) compute time plus the loop overhead; each sleep wakes after the injected latency.
runtime::VirtualCycleCosts VirtualCostsOf(const TuneOptions& o, const StepCost& step,
                                          double overhead_ns) {
  runtime::VirtualCycleCosts costs;
  const auto overhead = static_cast<kernel_glue::TimeNs>(std::llround(overhead_ns));
  if (o.inject_compute_us) {
    costs.compute_ns = {NsOfUs(*o.inject_compute_us) + overhead};
  } else {
    costs.compute_ns.reserve(step.samples_ns.size());
    for (const kernel_glue::TimeNs ns : step.samples_ns) costs.compute_ns.push_back(ns + overhead);
  }
  if (o.inject_latency_us && *o.inject_latency_us > 0.0) {
    costs.wake_latency_ns = {NsOfUs(*o.inject_latency_us)};
  }
  return costs;
}

/// The profile as the twin's board reads it: sampled at the controller's instants over the
/// window and measured by the PWM reader (11 bits, io/conversions.h). The reference is driven
/// by exactly this, so it differs from the twin only by what the twin's rate changes (the
/// integration step, the sampling and the one-period delay), not by the reader's resolution,
/// which no rate can improve.
InputProfile DutyAsTheBoardReadsIt(const InputProfile& profile, double controller_rate_hz,
                                   double seconds) {
  const auto read = [](double duty) { return io::PwmToDuty(io::PwmReaderValue(duty)); };
  const auto samples = static_cast<std::size_t>(std::ceil(seconds * controller_rate_hz)) + 1;
  std::vector<ProfileKnot> knots;
  knots.reserve(2 * samples);
  for (std::size_t j = 0; j < samples; ++j) {
    const double t_s = static_cast<double>(j) / controller_rate_hz;
    const Duty duty = profile.At(t_s);
    const Duty held{read(duty.left), read(duty.right)};
    if (j > 0) knots.push_back({t_s, knots.back().duty});  // the held value up to the step
    knots.push_back({t_s, held});
  }
  knots.push_back({static_cast<double>(samples) / controller_rate_hz, knots.back().duty});
  return InputProfile::FromKnots(profile.name() + " as read by the board", std::move(knots));
}

/// Reference positions at every controller sample instant of the validation window: the same
/// model integrated by Boost.Odeint's adaptive Dormand-Prince at 1e-10 tolerances (a "much
/// higher rate" than any twin), sampled without delay.
analysis::ReferenceSamples MakeReference(const TuneOptions& o, const Twin& twin) {
  const double controller_period_s = 1.0 / o.controller_rate_hz;
  ReferenceOptions reference;
  reference.input_hold_s = controller_period_s;
  const InputProfile input =
      DutyAsTheBoardReadsIt(*twin.profile, o.controller_rate_hz, o.validate_seconds);
  const std::vector<RelbotOutputs> outputs =
      SimulateReference(twin.params, input, o.validate_seconds, controller_period_s, reference);
  analysis::ReferenceSamples samples;
  samples.controller_period_s = controller_period_s;
  for (const RelbotOutputs& out : outputs) {
    samples.wheel_left_m.push_back(out.wheel_left_m);
    samples.wheel_right_m.push_back(out.wheel_right_m);
  }
  return samples;
}

/// Runs the procedure's steps in order and reports each to the progress callback.
class TuneProcedure {
 public:
  TuneProcedure(const TuneOptions& o, const TuneProgress& progress) : o_(o), progress_(progress) {
    policy_.controller_rate_hz = o.controller_rate_hz;
    policy_.tolerance_m = o.tolerance_m;
    policy_.max_rate_hz = scheduler::kMaxRateHz;
    LoadTwinConfiguration(TwinOptionsFor(o, o.controller_rate_hz, o.validate_seconds, true),
                          config_);
    const double multiples = std::floor(policy_.max_rate_hz / o.controller_rate_hz);
    const double accuracy_steps = std::ceil(std::log2(std::max(multiples, 1.0))) + 1.0;
    steps_total_ = 3.0 + static_cast<double>(o.candidates_hz.size()) * 2.0 + 1.0 + accuracy_steps;
  }

  analysis::TuneReport Run() {
    analysis::TuneReport report;
    report.clock = runtime::ToString(o_.clock);
    report.validate_seconds = o_.validate_seconds;
    report.policy = policy_;
    Measure(report);
    Next("searching the accuracy bound (virtual runs against the reference)");
    reference_ = MakeReference(o_, config_);
    report.input = config_.profile->name();
    report.accuracy = analysis::AccuracyBound(
        [this, max_stable_step_s =
                   RelbotMaxStableStepS(config_.params, config_.integrator)](double rate_hz) {
          Next("accuracy at " + Num(rate_hz) + " Hz");
          // A rate the integrator cannot run stably is no bound; the search goes higher.
          if (1.0 / rate_hz > max_stable_step_s) return std::numeric_limits<double>::infinity();
          return RunRecorded(rate_hz, true, {}).rms_error_m;
        },
        policy_);
    report.recommendation = analysis::Recommend(report.measured, report.accuracy.bound_hz, policy_);
    Validate(report);
    report.validation = analysis::SummariseValidation(report.candidates);
    return report;
  }

 private:
  void Next(const std::string& what) {
    StopIfAsked(what);
    progress_(std::min(steps_done_ / steps_total_, 1.0), what);
    steps_done_ += 1.0;
  }

  /// A stop signal (SIGINT, SIGTERM, SIGHUP) ends the run in progress cleanly (RunSession), and
  /// tune with it: a procedure missing a step recommends nothing.
  static void StopIfAsked(const std::string& next) {
    if (!kernel_glue::StopRequested()) return;
    throw CommandError(ExitCode::kAborted,
                       std::string("stopped by ") +
                           kernel_glue::StopSignalName(kernel_glue::StopSignal()) + " before " +
                           next + ": no recommendation (run it again to the end)");
  }

  void Measure(analysis::TuneReport& report);
  void Validate(analysis::TuneReport& report);
  analysis::CandidateResult RunRecorded(double rate_hz, bool virtual_clock,
                                        runtime::VirtualCycleCosts costs);

  const TuneOptions& o_;
  const TuneProgress& progress_;
  analysis::TuningPolicy policy_;
  analysis::ReferenceSamples reference_;
  Twin config_;  ///< parameters, integrator and profile, loaded once (no board, no task)
  StepCost step_;
  double steps_total_ = 1.0;
  double steps_done_ = 0.0;
};

void TuneProcedure::Measure(analysis::TuneReport& report) {
  analysis::TimingMeasurements& m = report.measured;
  m.injected = AllInjected(o_);
  if (!m.injected) {
    Next("checking this machine (doctor)");
    report.machine_warnings = MachineWarnings();
  }
  Next("timing the model step");
  step_ = o_.inject_compute_us ? InjectedStepCost(NsOfUs(*o_.inject_compute_us))
                               : MeasureStepCost(config_, o_.candidates_hz.back());
  m.step_compute = step_.summary;
  Next("timing the loop's own work per cycle");
  m.loop_overhead_ns =
      o_.inject_overhead_us
          ? static_cast<double>(NsOfUs(*o_.inject_overhead_us))
          : MeasureLoopOverheadNs(TwinOptionsFor(o_, o_.candidates_hz.back(), 1.0, true),
                                  step_.summary.mean_ns);
  for (const double rate_hz : o_.candidates_hz) {
    Next("wake-up latency at " + Num(rate_hz) + " Hz");
    if (IsVirtual(o_)) {
      m.wake_latency.push_back(
          {rate_hz, ConstantSummary(NsOfUs(o_.inject_latency_us.value_or(0.0)))});
    } else {
      m.wake_latency.push_back(
          {rate_hz, MeasureWakeLatency(TwinOptionsFor(o_, rate_hz, o_.latency_seconds, false))});
    }
  }
  report.model = "RELbot twin, " + std::string(IntegratorName(config_.integrator));
}

void TuneProcedure::Validate(analysis::TuneReport& report) {
  std::vector<double> rates = o_.candidates_hz;
  const double recommended = report.recommendation.recommended_hz;
  // A recommendation capped below the controller rate (a machine too slow for this twin) is
  // reported with its warning but cannot run: the twin must answer every controller sample.
  if (recommended >= o_.controller_rate_hz &&
      std::find(rates.begin(), rates.end(), recommended) == rates.end()) {
    rates.push_back(recommended);
  }
  std::sort(rates.begin(), rates.end());
  const runtime::VirtualCycleCosts costs =
      IsVirtual(o_) ? VirtualCostsOf(o_, step_, report.measured.loop_overhead_ns)
                    : runtime::VirtualCycleCosts{};
  for (const double rate_hz : rates) {
    Next("validating " + Num(rate_hz) + " Hz for " + Num(o_.validate_seconds) + " s");
    analysis::CandidateResult result = RunRecorded(rate_hz, IsVirtual(o_), costs);
    result.recommended = rate_hz == recommended;
    report.candidates.push_back(std::move(result));
  }
  StopIfAsked("the summary");
  progress_(1.0, "done");
}

analysis::CandidateResult TuneProcedure::RunRecorded(double rate_hz, bool virtual_clock,
                                                     runtime::VirtualCycleCosts costs) {
  const TwinRunOptions t = TwinOptionsFor(o_, rate_hz, o_.validate_seconds, virtual_clock);
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(t, period_ns);
  runtime::SessionConfig config =
      MakeSessionConfig(t.session, TwinRole("tune", o_.controller_rate_hz), *twin->backend);
  config.task_name = "RELbot twin";
  config.virtual_costs = std::move(costs);
  TrajectoryRecorder recorder(*twin->task, period_ns, PlannedCycles(t.session));
  const runtime::RunReport run = RunSessionOf(std::move(config), recorder);
  analysis::CandidateResult result;
  result.rate_hz = rate_hz;
  result.releases = run.misses.cycles_judged;
  result.deadline_misses = run.misses.misses_judged;
  result.miss_pct = run.misses.miss_pct_judged;
  result.qos_verdict = qos::ToString(run.verdict);
  // A run cut short by SIGINT at its start has no error to report, and tune ends here.
  StopIfAsked("the error of the " + Num(rate_hz) + " Hz run");
  try {
    result.rms_error_m = analysis::ControllerViewRmsError(recorder.trajectory(), reference_);
  } catch (const std::invalid_argument&) {
    // A run that ended before the first controller sample (a fault at start-up) has no error;
    // NaN is "not measured" in the summary and null in the JSON.
    result.rms_error_m = std::numeric_limits<double>::quiet_NaN();
  }
  return result;
}

}  // namespace

TwinRunOptions TwinOptionsFor(const TuneOptions& o, double rate_hz, double seconds,
                              bool virtual_clock) {
  TwinRunOptions t;
  t.session.rate_hz = rate_hz;
  t.session.duration_s = seconds;
  t.session.clock = virtual_clock ? runtime::ClockKind::kVirtual : runtime::ClockKind::kRealtime;
  // The profile plays into the emulated board (SessionSettings' default mock), as `run` does;
  // the rules are `run`'s defaults for this rate pair.
  t.session.qos_rules = qos::DefaultRulesFor(rate_hz, o.controller_rate_hz);
  t.session.progress = false;  // tune draws its own progress bar
  t.session.priority = o.priority;
  t.session.cpus = o.cpus;
  t.input = o.input;
  t.controller_rate_hz = o.controller_rate_hz;
  t.config_path = o.config_path;
  t.integrator = o.integrator;
  return t;
}

void CheckTuneOptions(const TuneOptions& o) {
  if (!std::isfinite(o.controller_rate_hz) || o.controller_rate_hz <= 0.0 ||
      o.controller_rate_hz > scheduler::kMaxRateHz) {
    ThrowUsage("--controller-rate " + Num(o.controller_rate_hz) +
          ": must be a rate in Hz above 0 and at most 50000 (the thesis's ECS runs at 1000)");
  }
  if (!std::isfinite(o.tolerance_m) || o.tolerance_m <= 0.0) {
    ThrowUsage("--tolerance-m " + Num(o.tolerance_m) +
          ": must be a positive distance in metres (default 0.0001 = 0.1 mm)");
  }
  try {
    analysis::CheckCandidateRates(o.candidates_hz, scheduler::kMaxRateHz);
  } catch (const std::invalid_argument& e) {
    ThrowUsage(std::string("--candidates: ") + e.what());
  }
  if (o.candidates_hz.front() < o.controller_rate_hz) {
    ThrowUsage("--candidates: " + Num(o.candidates_hz.front()) + " Hz is below --controller-rate " +
          Num(o.controller_rate_hz) +
          " Hz; a twin slower than its controller cannot answer every sample");
  }
  if (!std::isfinite(o.validate_seconds) || o.validate_seconds < 0.1 ||
      o.validate_seconds > 3600.0) {
    ThrowUsage("--validate-seconds " + Num(o.validate_seconds) + ": must be 0.1 .. 3600");
  }
  if (!std::isfinite(o.latency_seconds) || o.latency_seconds < 0.1 || o.latency_seconds > 600.0) {
    ThrowUsage("--latency-seconds " + Num(o.latency_seconds) + ": must be 0.1 .. 600");
  }
  CheckInjection(o.inject_compute_us, "--inject-compute-us", o);
  CheckInjection(o.inject_overhead_us, "--inject-overhead-us", o);
  CheckInjection(o.inject_latency_us, "--inject-latency-us", o);
  for (const double rate_hz : o.candidates_hz) {
    CheckTwinRunOptions(TwinOptionsFor(o, rate_hz, o.validate_seconds, IsVirtual(o)));
  }
  CheckModelRunsAt(o, o.candidates_hz.front());
}

analysis::TuneReport RunTune(const TuneOptions& o, const TuneProgress& progress) {
  CheckTuneOptions(o);
  TuneProcedure procedure(o, progress);
  return procedure.Run();
}

}  // namespace hiltwin::app
