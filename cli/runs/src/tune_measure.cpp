// The measuring half of `hiltwin tune` (tune_measure.h).
#include "tune_measure.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <string_view>

#include "hiltwin/kernel_glue/rt_probe.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/scheduler/timing_stats.h"

namespace hiltwin::app {
namespace {

constexpr int kStepWarmup = 10'000;          // caches, branch predictors, CPU frequency
constexpr int kStepSamples = 100'000;        // p99.9 from 100 samples above it
constexpr double kOverheadCycles = 200'000;  // a few hundred ms flat out: stable to ~1 %

/// A task that exchanges and steps nothing: the loop alone, for the OS's wake-up latency.
class IdleTask final : public runtime::RunTask {
 public:
  io::ExchangeStatus Exchange(bool) noexcept override { return {.board_answered = true}; }
  runtime::StepStatus Step(const scheduler::CycleContext&) noexcept override { return {}; }
  [[nodiscard]] std::vector<std::string> LogColumns() const override { return {}; }
  [[nodiscard]] double LogTimeS() const noexcept override { return 0.0; }
  void FillLogRow(std::span<double>) const noexcept override {}
};

}  // namespace

StepCost MeasureStepCost(const Twin& twin, double rate_hz) {
  const double step_s = 1.0 / rate_hz;
  RelbotModel model(twin.params, twin.integrator, step_s);
  kernel_glue::MonotonicClock clock;
  scheduler::TimingStats stats;
  StepCost cost;
  cost.samples_ns.reserve(kStepSamples);
  for (int i = 0; i < kStepWarmup + kStepSamples; ++i) {
    const Duty duty = twin.profile->At(model.time_s());
    const kernel_glue::TimeNs start_ns = clock.NowNs();
    model.Step(duty.left, duty.right);
    const kernel_glue::TimeNs took_ns = clock.NowNs() - start_ns;
    if (i < kStepWarmup) continue;
    stats.Record(took_ns);
    cost.samples_ns.push_back(took_ns);
  }
  cost.summary = stats.Summary();
  return cost;
}

scheduler::TimingSummary ConstantSummary(kernel_glue::TimeNs ns) {
  return {.count = 1,
          .min_ns = ns,
          .mean_ns = static_cast<double>(ns),
          .p50_ns = ns,
          .p99_ns = ns,
          .p999_ns = ns,
          .max_ns = ns};
}

StepCost InjectedStepCost(kernel_glue::TimeNs ns) { return {ConstantSummary(ns), {ns}}; }

double MeasureLoopOverheadNs(const TwinRunOptions& t, double step_mean_ns) {
  TwinRunOptions flat_out = t;
  flat_out.session.clock = runtime::ClockKind::kVirtual;
  flat_out.session.duration_s = kOverheadCycles / t.session.rate_hz;
  const kernel_glue::TimeNs period_ns = kernel_glue::PeriodNsFromRateHz(t.session.rate_hz);
  const std::unique_ptr<Twin> twin = BuildTwin(flat_out, period_ns);
  runtime::SessionConfig config =
      MakeSessionConfig(flat_out.session, TwinRole("tune", t.controller_rate_hz), *twin->backend);
  const auto start = std::chrono::steady_clock::now();
  const runtime::RunReport report = RunSessionOf(std::move(config), *twin->task);
  const double wall_ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  const double per_cycle_ns =
      wall_ns / static_cast<double>(std::max<std::uint64_t>(report.cycles_run, 1));
  return std::max(0.0, per_cycle_ns - step_mean_ns);
}

scheduler::TimingSummary MeasureWakeLatency(const TwinRunOptions& t) {
  const std::unique_ptr<io::IoBackend> board = OpenBoard(t.session, io::Image::kIcoboardInverse);
  runtime::SessionConfig config =
      MakeSessionConfig(t.session, TwinRole("tune", t.controller_rate_hz), *board);
  config.task_name = "idle loop";
  IdleTask idle;
  return RunSessionOf(std::move(config), idle).latency;
}

std::vector<analysis::TuneWarning> MachineWarnings() {
  // The findings that change the timing this procedure measures; doctor lists the rest.
  constexpr std::array<std::string_view, 4> kDeciding = {"governor", "sched_fifo", "virtualisation",
                                                         "steal_time"};
  const kernel_glue::ProbeReport probe = kernel_glue::RunRtProbe();
  std::vector<analysis::TuneWarning> warnings;
  for (const std::string_view id : kDeciding) {
    const kernel_glue::ProbeCheck* check = probe.Find(id);
    if (check == nullptr || check->status == kernel_glue::CheckStatus::kOk) continue;
    warnings.push_back({check->id, check->name + ": " + check->value,
                        check->advice.empty() ? "see 'hiltwin doctor'" : check->advice});
  }
  return warnings;
}

}  // namespace hiltwin::app
