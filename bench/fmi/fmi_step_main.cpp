// ns per FMU step: FmuPlant::Step called through plant::Plant& (fmi2SetReal -> fmi2DoStep ->
// fmi2GetReal, status checks, model time k*h) against the same three calls made directly
// through the FMU's function pointers on the same instance, with the same checks. The
// difference is what the adapter costs per step (target: under 50 ns). Rounds alternate
// between the two so frequency changes and neighbours on the shared machine hit both; the
// median over rounds is the figure, the minimum is printed too.
//
// Usage: hiltwin_bench_fmi [steps_per_round=1000000] [rounds=9] [fmu=<build>/tests/fmus/lag.fmu]

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <vector>

#include "bench_stats.h"
#include "hiltwin/fmi/fmu_plant.h"

namespace {

using Clock = hiltwin::bench::BenchClock;
using hiltwin::bench::Median;
constexpr double kStepS = 1e-3;
constexpr std::size_t kInputSamples = 1024;  // a varying input, so nothing is constant-folded

volatile double g_sink = 0.0;

std::vector<double> Inputs() {
  std::vector<double> u(kInputSamples);
  for (std::size_t i = 0; i < u.size(); ++i) {
    u[i] = (i / 256) % 2 == 0 ? 0.5 : -0.5;
  }
  return u;
}

double TimeAdapter(hiltwin::plant::Plant& plant, const std::vector<double>& inputs, long steps) {
  std::array<double, 1> y{};
  plant.Reset(y);  // model time 0, as the direct loop assumes
  bool ok = true;
  const auto start = Clock::now();
  for (long k = 0; k < steps; ++k) {
    const std::array<double, 1> u{inputs[static_cast<std::size_t>(k) % kInputSamples]};
    ok = plant.Step(u, y).ok() && ok;
  }
  const auto end = Clock::now();
  g_sink = g_sink + y[0] + (ok ? 0.0 : 1.0);
  return hiltwin::bench::NsPer(start, end, steps);
}

double TimeDirect(hiltwin::fmi::FmuPlant& plant, const std::vector<double>& inputs, long steps) {
  std::array<double, 1> y{};
  plant.Reset(y);
  const hiltwin::fmi::FmuDirectCalls fmu = plant.DirectCalls();
  bool ok = true;
  const auto start = Clock::now();
  for (long k = 0; k < steps; ++k) {
    const std::array<double, 1> u{inputs[static_cast<std::size_t>(k) % kInputSamples]};
    const fmi2Status set = fmu.set_real(fmu.component, fmu.input_refs.data(), 1, u.data());
    const fmi2Status step =
        fmu.do_step(fmu.component, static_cast<double>(k) * kStepS, kStepS, fmi2True);
    const fmi2Status get = fmu.get_real(fmu.component, fmu.output_refs.data(), 1, y.data());
    ok = set == fmi2OK && step == fmi2OK && get == fmi2OK && ok;
  }
  const auto end = Clock::now();
  g_sink = g_sink + y[0] + (ok ? 0.0 : 1.0);
  return hiltwin::bench::NsPer(start, end, steps);
}

}  // namespace

int main(int argc, char** argv) try {
  const auto arguments = hiltwin::bench::ParseStepsAndRounds(argc, argv, " [fmu]");
  if (!arguments) return 2;
  const auto [steps, rounds] = *arguments;
  const char* fmu_path = argc > 3 ? argv[3] : HILTWIN_BENCH_FMU;
  const auto plant = hiltwin::fmi::OpenFmu(fmu_path);
  if (plant->Info().inputs.size() != 1 || plant->Info().outputs.size() != 1) {
    std::fprintf(stderr, "%s: the benchmark needs an FMU with one Real input and one output\n",
                 fmu_path);
    return 2;
  }
  std::array<double, 1> y0{};
  plant->Start(kStepS, y0);
  const std::vector<double> inputs = Inputs();
  (void)TimeAdapter(*plant, inputs, steps / 4);  // warm-up: caches, predictors, frequency
  (void)TimeDirect(*plant, inputs, steps / 4);
  std::vector<double> adapter_ns;
  std::vector<double> direct_ns;
  for (int r = 0; r < rounds; ++r) {
    adapter_ns.push_back(TimeAdapter(*plant, inputs, steps));
    direct_ns.push_back(TimeDirect(*plant, inputs, steps));
  }
  const double adapter = Median(adapter_ns);
  const double direct = Median(direct_ns);
  std::printf("fmi_step: %ld steps x %d rounds, %s, step %.0f us; median (min) ns per step\n",
              steps, rounds, fmu_path, kStepS * 1e6);
  std::printf("  FmuPlant::Step via plant::Plant&             %7.1f  (%7.1f)\n", adapter,
              hiltwin::bench::MinOf(adapter_ns));
  std::printf("  fmi2SetReal+fmi2DoStep+fmi2GetReal direct    %7.1f  (%7.1f)\n", direct,
              hiltwin::bench::MinOf(direct_ns));
  std::printf("  adapter overhead (difference)                %7.1f   target < 50 ns: %s\n",
              adapter - direct, adapter - direct < 50.0 ? "met" : "NOT met");
  std::printf("  ratio adapter / direct                       %7.2f\n", adapter / direct);
  return 0;
} catch (const std::exception& error) {
  std::fprintf(stderr, "hiltwin_bench_fmi: %s\n", error.what());
  return 2;
}
