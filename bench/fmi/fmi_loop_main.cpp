// An FMU plant's whole loop against a bare FMI 2.0 master stepping the same FMU (issue 36:
// "within 3x of a bare FMI master by CPU time"). The FMU is tests/fmus' lag.fmu: its step does
// real work (an exp() per step, y <- K u + (y - K u) exp(-h / tau)), where msd.fmu's is four
// multiply-adds with a cached transition matrix, so lag is the fairer of the two trivial FMUs.
//   (a) `hiltwin run --plant fmu:lag.fmu --plant-map <u from PWM 1, y to encoder 1>
//       --clock virtual`: the twin at 4 kHz, as fast as it runs: the loop, the mock board's
//       exchange, QoS, statistics and the FMU's SetReal/DoStep/GetReal per cycle.
//   (b) the bare master: the FMU opened and started (fmi2Instantiate, fmi2SetupExperiment,
//       initialisation), then per step fmi2SetReal, fmi2DoStep, fmi2GetReal through the FMU's
//       own function pointers, nothing else.
// CPU time per step: (a) the child's user + system time for 2D s minus that for D s, over the
// 4000 D cycles between (start-up and the FMU's unpacking cancel); (b) the thread's CPU time
// over the steps. Instructions per step (callgrind, load-independent): (a) all threads, 2D
// against D seconds; (b) a ToggleCounting bracket around 2N against N steps.
//
// Usage: hiltwin_bench_fmi_loop HILTWIN [seconds=20] [rounds=3] [fmu=<build>/tests/fmus/lag.fmu]
//        hiltwin_bench_fmi_loop --bare-steps N [fmu]   (one bracket, for callgrind)
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "hiltwin/fmi/fmu_plant.h"
#include "hiltwin/kernel_glue/process.h"

namespace {

namespace fs = std::filesystem;
constexpr double kRateHz = 4000.0;
constexpr double kStepS = 1.0 / kRateHz;

volatile double g_sink = 0.0;

double ThreadCpuS() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

double ChildrenCpuS() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// The bare master's steps: the input alternates as a PWM duty would, the output is kept.
// Returns false when a call did not return fmi2OK.
bool BareSteps(const hiltwin::fmi::FmuDirectCalls& fmu, long first, long steps) {
  bool ok = true;
  std::array<double, 1> y{};
  for (long k = first; k < first + steps; ++k) {
    const std::array<double, 1> u{(k / 1024) % 2 == 0 ? 0.5 : -0.5};
    ok = fmu.set_real(fmu.component, fmu.input_refs.data(), 1, u.data()) == fmi2OK && ok;
    ok = fmu.do_step(fmu.component, static_cast<double>(k) * kStepS, kStepS, fmi2True) ==
             fmi2OK && ok;
    ok = fmu.get_real(fmu.component, fmu.output_refs.data(), 1, y.data()) == fmi2OK && ok;
  }
  g_sink = g_sink + y[0];
  return ok;
}

std::unique_ptr<hiltwin::fmi::FmuPlant> StartedFmu(const char* fmu_path) {
  auto plant = hiltwin::fmi::OpenFmu(fmu_path);
  if (plant->Info().inputs.size() != 1 || plant->Info().outputs.size() != 1) {
    throw std::runtime_error(std::string(fmu_path) + ": one Real input and one output needed");
  }
  std::array<double, 1> y0{};
  plant->Start(kStepS, y0);
  return plant;
}

// `--bare-steps N`: N bare steps between two ToggleCounting() calls.
int CountedBareSteps(long steps, const char* fmu_path) {
  const auto plant = StartedFmu(fmu_path);
  const hiltwin::fmi::FmuDirectCalls fmu = plant->DirectCalls();
  hiltwin::bench::ToggleCounting();
  const bool ok = BareSteps(fmu, 0, steps);
  hiltwin::bench::ToggleCounting();
  return ok ? 0 : 3;
}

double BareCpuNsPerStep(const char* fmu_path, long steps) {
  const auto plant = StartedFmu(fmu_path);
  const hiltwin::fmi::FmuDirectCalls fmu = plant->DirectCalls();
  (void)BareSteps(fmu, 0, steps / 10);  // warm-up
  std::array<double, 1> y0{};
  plant->Reset(y0);  // model time 0 again, as the timed steps count from 0
  const double start = ThreadCpuS();
  const bool ok = BareSteps(fmu, 0, steps);
  const double end = ThreadCpuS();
  if (!ok) throw std::runtime_error("the bare master's FMU calls failed");
  return (end - start) * 1e9 / static_cast<double>(steps);
}

std::vector<std::string> TwinArgs(const std::string& hiltwin, const char* fmu_path,
                                  const fs::path& map, double seconds) {
  return {hiltwin, "run", "--plant", std::string("fmu:") + fmu_path, "--plant-map", map.string(),
          "--clock", "virtual", "--duration", std::to_string(seconds), "--no-progress"};
}

double TwinCpuS(const std::vector<std::string>& args) {
  const double before = ChildrenCpuS();
  const auto result = hiltwin::kernel_glue::RunProcess(
      args, {.out = hiltwin::kernel_glue::OutputTarget::Discard(),
             .err = hiltwin::kernel_glue::OutputTarget::Capture()});
  if (!result.status.Success()) {
    throw std::runtime_error("hiltwin run ended with " + result.status.Describe() + ":\n" +
                             result.err);
  }
  return ChildrenCpuS() - before;
}

// Instructions per cycle of the twin, all threads, 2D against D seconds (callgrind).
double TwinInstructionsPerStep(const std::string& hiltwin, const char* fmu_path,
                               const fs::path& map, double seconds) {
  const auto count = [&](double s) {
    const fs::path out = fs::temp_directory_path() / ("hiltwin_fmi_loop_cg_" +
                                                      std::to_string(getpid()));
    std::vector<std::string> args = {"valgrind", "--tool=callgrind",
                                     "--callgrind-out-file=" + out.string()};
    const auto twin = TwinArgs(hiltwin, fmu_path, map, s);
    args.insert(args.end(), twin.begin(), twin.end());
    (void)TwinCpuS(args);
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    fs::remove(out);
    const auto counted = hiltwin::bench::CallgrindInstructions(text);
    if (!counted) throw std::runtime_error("callgrind counted nothing for hiltwin run");
    return *counted;
  };
  const auto steps = static_cast<std::uint64_t>(seconds * kRateHz);
  return hiltwin::bench::InstructionsPerItem(steps, count(seconds), 2 * steps,
                                             count(2 * seconds));
}

fs::path WriteLagMap(const fs::path& dir) {
  fs::create_directories(dir);
  fs::path map = dir / "lag_map.toml";
  std::ofstream(map) << "[[pwm]]\nchannel = 1\ninput = \"u\"\ngain = 1.0\n\n"
                        "[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"rad\"\n"
                        "counts_per_unit = 651.9\n";
  return map;
}

int Report(const std::string& hiltwin, double seconds, int rounds, const char* fmu_path,
           const char* self) {
  const fs::path dir = fs::temp_directory_path() / ("hiltwin_fmi_loop_" + std::to_string(getpid()));
  const fs::path map = WriteLagMap(dir);
  const double cycles = seconds * kRateHz;
  std::vector<double> twin_ns;
  std::vector<double> bare_ns;
  std::vector<double> ratio;
  for (int r = 0; r < rounds; ++r) {
    const double once = TwinCpuS(TwinArgs(hiltwin, fmu_path, map, seconds));
    const double twice = TwinCpuS(TwinArgs(hiltwin, fmu_path, map, 2 * seconds));
    twin_ns.push_back((twice - once) * 1e9 / cycles);
    bare_ns.push_back(BareCpuNsPerStep(fmu_path, static_cast<long>(cycles)));
    ratio.push_back(twin_ns.back() / bare_ns.back());
  }
  std::printf("fmi_loop: %s, %.0f Hz, %g s against %g s of the twin, %d rounds; median (range)\n",
              fmu_path, kRateHz, 2 * seconds, seconds, rounds);
  std::printf("  CPU per step: hiltwin run %s, bare FMI master (peer) %s, ratio %s (target <= 3)\n",
              FormatSpread(hiltwin::bench::SpreadOf(twin_ns), "ns").c_str(),
              FormatSpread(hiltwin::bench::SpreadOf(bare_ns), "ns").c_str(),
              FormatSpread(hiltwin::bench::SpreadOf(ratio), "x", 2).c_str());
  try {
    const double twin = TwinInstructionsPerStep(hiltwin, fmu_path, map, 1.0);
    const auto bare_count = [&](long steps) {
      return hiltwin::bench::CountInstructions(
          {self, "--bare-steps", std::to_string(steps), fmu_path});
    };
    const double bare = hiltwin::bench::InstructionsPerItem(4000, bare_count(4000), 8000,
                                                            bare_count(8000));
    std::printf("  instructions per step (callgrind): hiltwin run %.0f, bare FMI master (peer) "
                "%.0f, ratio %.1f\n", twin, bare, twin / bare);
  } catch (const std::exception& e) {
    std::printf("  instructions per step: not counted (%s)\n", e.what());
  }
  fs::remove_all(dir);
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc >= 3 && std::strcmp(argv[1], "--bare-steps") == 0) {
    return CountedBareSteps(std::atol(argv[2]), argc > 3 ? argv[3] : HILTWIN_BENCH_FMU);
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s HILTWIN [seconds=20] [rounds=3] [fmu]\n", argv[0]);
    return 2;
  }
  const double seconds = argc > 2 ? std::atof(argv[2]) : 20.0;
  const int rounds = argc > 3 ? std::atoi(argv[3]) : 3;
  if (!(seconds > 0.0) || rounds <= 0) {
    std::fprintf(stderr, "usage: %s HILTWIN [seconds > 0] [rounds > 0] [fmu]\n", argv[0]);
    return 2;
  }
  return Report(argv[1], seconds, rounds, argc > 4 ? argv[4] : HILTWIN_BENCH_FMU, argv[0]);
} catch (const std::exception& error) {
  std::fprintf(stderr, "hiltwin_bench_fmi_loop: %s\n", error.what());
  return 2;
}
