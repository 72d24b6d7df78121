// ns per RELbot step through the plant interface (plant::Plant::Step, a virtual call with the
// ports as spans and the outputs copied out, as PlantTwinTask calls it) against
// RelbotModel::Step called directly on the same parameters and duties, plus the generic twin
// task's own per-cycle work (map in, step, map out) on top. The plant comes from the registry
// as a unique_ptr<Plant>, so the call goes through the vtable as in a run. Rounds alternate
// between the variants; the median over rounds is the figure, the minimum is printed too.
//
// Usage: hiltwin_bench_plant_step [steps_per_round=1000000] [rounds=9]

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hiltwin/plant/plant_registry.h"
#include "hiltwin/relbot/relbot_model.h"
#include "hiltwin/relbot/relbot_plant.h"
#include "bench_stats.h"
#include "relbot_duty_samples.h"

namespace {

using hiltwin::app::Duty;
using Clock = hiltwin::bench::BenchClock;
using hiltwin::bench::Median;
using hiltwin::bench::MinOf;

constexpr double kStepS = 2.5e-4;  // 4 kHz, the thesis's RELbot twin rate

volatile double g_sink = 0.0;  // keeps the results observable

double TimeInterface(hiltwin::plant::Plant& plant, const std::vector<Duty>& duty, long steps) {
  std::array<double, 5> y{};
  plant.Reset(y);
  std::array<double, 2> u{};
  const auto start = Clock::now();
  for (long k = 0; k < steps; ++k) {
    const Duty& d = duty[static_cast<std::size_t>(k / 4) % duty.size()];
    u[0] = d.left;
    u[1] = d.right;
    if (!plant.Step(u, y).ok()) std::abort();
  }
  const auto end = Clock::now();
  g_sink = g_sink + y[0];
  return hiltwin::bench::NsPer(start, end, steps);
}

}  // namespace

int main(int argc, char** argv) {
  const auto arguments = hiltwin::bench::ParseStepsAndRounds(argc, argv);
  if (!arguments) return 2;
  const auto [steps, rounds] = *arguments;
  const std::vector<Duty> duty = hiltwin::bench::OpenLoopDutiesAt1kHz();
  hiltwin::app::RegisterRelbotPlant();
  const std::unique_ptr<hiltwin::plant::Plant> plant =
      hiltwin::plant::FindPlant("relbot")->make({});
  std::array<double, 5> y0{};
  plant->Start(kStepS, y0);
  hiltwin::app::RelbotModel model(hiltwin::app::RelbotParams{}, hiltwin::app::Integrator::kRk4,
                                  kStepS);
  (void)hiltwin::bench::TimeRelbotSteps(model, duty, steps / 4, g_sink);  // warm-up: caches, predictors, CPU frequency
  (void)TimeInterface(*plant, duty, steps / 4);
  std::vector<double> direct_ns;
  std::vector<double> interface_ns;
  for (int r = 0; r < rounds; ++r) {
    direct_ns.push_back(hiltwin::bench::TimeRelbotSteps(model, duty, steps, g_sink));
    interface_ns.push_back(TimeInterface(*plant, duty, steps));
  }
  const double direct = Median(direct_ns);
  const double via = Median(interface_ns);
  std::printf("plant_step: %ld steps x %d rounds per variant, RELbot rk4, step %.0f us, "
              "openloop duties; median (min) ns per step\n",
              steps, rounds, kStepS * 1e6);
  std::printf("  RelbotModel::Step, called directly    %7.1f  (%7.1f)\n", direct, MinOf(direct_ns));
  std::printf("  plant::Plant::Step (RELbot plant)     %7.1f  (%7.1f)\n", via, MinOf(interface_ns));
  std::printf("  interface overhead                    %7.1f   target < 20 ns: %s\n",
              via - direct, via - direct < 20.0 ? "met" : "NOT met");
  return 0;
}
