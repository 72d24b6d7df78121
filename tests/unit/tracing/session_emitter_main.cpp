// Runs the run assembly (runtime::RunSession) with a task that is not the RELbot: no I/O, no
// model, for the live-session test that proves every application gets the cycle and qos
// tracepoints from the framework. `<exe> CYCLES MISSED_CYCLE`: virtual clock at 1 kHz, an
// injected 1.5 ms overrun at MISSED_CYCLE (a miss, caught up by the next cycle).
#include <cstdlib>
#include <string>

#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"

namespace {

class NothingTask final : public hiltwin::runtime::RunTask {
 public:
  hiltwin::io::ExchangeStatus Exchange(bool) noexcept override { return {}; }
  hiltwin::runtime::StepStatus Step(const hiltwin::scheduler::CycleContext&) noexcept override {
    return {};
  }
  std::vector<std::string> LogColumns() const override { return {}; }
  double LogTimeS() const noexcept override { return 0.0; }
  void FillLogRow(std::span<double>) const noexcept override {}
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const auto cycles = static_cast<std::uint64_t>(std::strtoull(argv[1], nullptr, 10));
  hiltwin::runtime::SessionConfig config;
  config.clock = hiltwin::runtime::ClockKind::kVirtual;
  config.rate_hz = 1000.0;
  config.executive.period_ns = 1'000'000;
  config.executive.max_cycles = cycles;
  config.qos.rules = {hiltwin::qos::MakeMissRatioRule(50.0)};
  config.qos.planned_cycles = cycles;
  config.injector.Add(
      hiltwin::runtime::ParseOverrunInjection(std::string("at=") + argv[2] + ",extra-us=1500"));
  NothingTask task;
  hiltwin::runtime::RunSession session(config, task);
  return session.Run().cycles_run == cycles ? 0 : 1;
}
