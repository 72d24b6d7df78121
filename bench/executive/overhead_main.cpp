// Per-cycle overhead with an empty step on the virtual clock, in three assemblies:
//   executive  the executive alone with one counting observer: sleeping, timing capture,
//              statistics and the observer call are all the work there is;
//   qos        the per-cycle work `hiltwin run` did before the run assembly existed, minus
//              the model: the stop-flag check, a task that times its (empty) exchange with
//              two clock reads and consults the overrun injector, and the old application
//              observer (cycle tracepoint, QoS Record with skipped releases, Live, qos
//              tracepoint), default rules;
//   session    runtime::RunSession with an empty task and the same rules: what every command
//              pays per cycle for lifecycle rules, timed I/O, commands and the ledger.
// Run it under callgrind twice with different cycle counts (callgrind_overhead.sh) so start-up
// cost cancels: instructions/cycle = (I(n2) - I(n1)) / (n2 - n1). Hardware counters are not
// available on this VM; instruction counts are repeatable whatever else the machine does.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/tracing/trace.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/scheduler/executive.h"

namespace {

namespace sched = hiltwin::scheduler;

class EmptyTask final : public sched::CyclicTask {
 public:
  sched::CycleAction Step(const sched::CycleContext&) noexcept override {
    return sched::CycleAction::kContinue;
  }
};

/// One observer, as a run has; counts so the call cannot be elided.
class CountingObserver final : public sched::CycleObserver {
 public:
  sched::CycleAction OnCycle(const sched::TimingSample& s) noexcept override {
    misses += s.missed ? 1U : 0U;
    return sched::CycleAction::kContinue;
  }
  unsigned long misses = 0;
};

/// The old application observer (app_relbot QosObserver before the run assembly), verbatim.
class QosRecorder final : public sched::CycleObserver {
 public:
  explicit QosRecorder(hiltwin::qos::QosMonitor& monitor) : monitor_(monitor) {}
  sched::CycleAction OnCycle(const sched::TimingSample& sample) noexcept override {
    HILTWIN_TRACE(cycle, sample.cycle, sample.release_ns, sample.wake_ns, sample.start_ns,
                  sample.end_ns, sample.io_ns, sample.releases_skipped,
                  static_cast<std::uint8_t>(sample.missed), std::uint8_t{1});
    bool stop = monitor_.Record(sample.cycle, sample.missed);
    for (std::uint32_t i = 1; i <= sample.releases_skipped; ++i) {
      stop = monitor_.Record(sample.cycle + i, true) || stop;
    }
    // (It also fired a per-cycle `qos` tracepoint, an event that no longer exists.)
    return stop ? sched::CycleAction::kStop : sched::CycleAction::kContinue;
  }

 private:
  hiltwin::qos::QosMonitor& monitor_;
};

/// The old twin task's bookkeeping around its work: a timed exchange and the injector.
class TimedEmptyTask final : public sched::CyclicTask {
 public:
  explicit TimedEmptyTask(hiltwin::kernel_glue::Clock& clock) : clock_(clock) {}
  sched::CycleAction Step(const sched::CycleContext& context) noexcept override {
    const hiltwin::kernel_glue::TimeNs start_ns = clock_.NowNs();
    SetIoNsOfLastStep(clock_.NowNs() - start_ns);
    const hiltwin::kernel_glue::TimeNs extra_ns = injector_.ExtraNs(context.cycle);
    if (extra_ns > 0) clock_.SpendNs(extra_ns);
    return sched::CycleAction::kContinue;
  }
 private:
  hiltwin::kernel_glue::Clock& clock_;
  hiltwin::runtime::OverrunInjector injector_;
};

/// A run task with no I/O and no model.
class EmptyRunTask final : public hiltwin::runtime::RunTask {
 public:
  hiltwin::io::ExchangeStatus Exchange(bool) noexcept override { return {}; }
  hiltwin::runtime::StepStatus Step(const sched::CycleContext&) noexcept override { return {}; }
  std::vector<std::string> LogColumns() const override { return {}; }
  double LogTimeS() const noexcept override { return 0.0; }
  void FillLogRow(std::span<double>) const noexcept override {}
};

hiltwin::qos::QosConfig DefaultQos(unsigned long cycles) {
  hiltwin::qos::QosConfig qos;
  qos.rules = hiltwin::qos::DefaultRules();
  qos.planned_cycles = cycles;
  return qos;
}

int RunSession(unsigned long cycles) {
  hiltwin::runtime::SessionConfig config;
  config.clock = hiltwin::runtime::ClockKind::kVirtual;
  config.executive.period_ns = 250'000;
  config.executive.max_cycles = cycles;
  config.qos = DefaultQos(cycles);
  EmptyRunTask task;
  hiltwin::runtime::RunSession session(config, task);
  const hiltwin::runtime::RunReport report = session.Run();
  std::printf("session cycles=%llu misses=%llu\n", static_cast<unsigned long long>(report.cycles_run),
              static_cast<unsigned long long>(report.misses.deadline_misses));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const unsigned long cycles = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1'000'000UL;
  const std::string mode = argc > 2 ? argv[2] : "executive";
  if (mode == "session") return RunSession(cycles);
  if (mode != "executive" && mode != "qos") {
    std::fprintf(stderr, "usage: %s [cycles] [executive|qos|session]\n", argv[0]);
    return 2;
  }
  hiltwin::kernel_glue::VirtualClock clock;
  sched::ExecutiveConfig config;
  config.period_ns = 250'000;
  config.max_cycles = cycles;
  sched::Executive executive(clock, config);
  CountingObserver observer;
  hiltwin::qos::QosMonitor monitor(DefaultQos(cycles));
  QosRecorder recorder(monitor);
  EmptyTask empty;
  TimedEmptyTask timed(clock);
  if (mode == "qos") {
    executive.SetStopCheck(&hiltwin::kernel_glue::StopRequested);
    executive.AddObserver(recorder);
    executive.Run(timed);
  } else {
    executive.AddObserver(observer);
    executive.Run(empty);
  }
  std::printf("%s cycles=%llu misses=%lu\n", mode.c_str(),
              static_cast<unsigned long long>(executive.stats().cycles_run), observer.misses);
  return 0;
}
