// Executive overhead per cycle with an empty step on the virtual clock: sleeping, timing
// capture, statistics and the observer call are all the work there is. Run it under
// callgrind twice with different cycle counts (callgrind_overhead.sh) so start-up cost
// cancels: instructions/cycle = (I(n2) - I(n1)) / (n2 - n1). Hardware counters are not
// available on this VM; instruction counts are repeatable whatever else the machine does.
#include <cstdio>
#include <cstdlib>

#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/scheduler/executive.h"

namespace {

class EmptyTask final : public hiltwin::scheduler::CyclicTask {
 public:
  hiltwin::scheduler::CycleAction Step(const hiltwin::scheduler::CycleContext&) noexcept override {
    return hiltwin::scheduler::CycleAction::kContinue;
  }
};

/// One observer, as a run has (the QoS monitor); counts so the call cannot be elided.
class CountingObserver final : public hiltwin::scheduler::CycleObserver {
 public:
  hiltwin::scheduler::CycleAction OnCycle(const hiltwin::scheduler::TimingSample& s) noexcept override {
    misses += s.missed ? 1U : 0U;
    return hiltwin::scheduler::CycleAction::kContinue;
  }
  unsigned long misses = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const unsigned long cycles = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1'000'000UL;
  hiltwin::kernel_glue::VirtualClock clock;
  hiltwin::scheduler::ExecutiveConfig config;
  config.period_ns = 250'000;
  config.max_cycles = cycles;
  hiltwin::scheduler::Executive executive(clock, config);
  CountingObserver observer;
  executive.AddObserver(observer);
  EmptyTask task;
  executive.Run(task);
  std::printf("cycles=%llu misses=%lu\n",
              static_cast<unsigned long long>(executive.stats().cycles_run), observer.misses);
  return 0;
}
