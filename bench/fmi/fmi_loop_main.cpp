// An FMU plant's whole loop against a bare FMI 2.0 master stepping the same FMU (issue 36:
// "within 3x of a bare FMI master by CPU time"), for two FMUs of tests/fmus, since the ratio is
// (loop + FMU) / FMU and so depends on what the FMU's step costs:
//   lag     lag.fmu, a first-order lag: one exp() a step (~150 instructions), a trivial model;
//   relbot  relbot.fmu, the RELbot's 12-state model with RK4 (relbot/src/relbot_model.cpp in C):
//           a plant-sized step, driven straight (duties 0.5, 0.5), as the built-in model is in
//           the cycle benchmark's window;
//   relbot_turning  the same FMU turning (duties 0.5, 0.25): a sincos in each RK4 stage.
// For each:
//   (a) `hiltwin run --plant fmu:<fmu> --plant-map <map> --input <held duties> --clock virtual`:
//       the twin at 4 kHz, as fast as it runs: the loop, the mock board's exchange, QoS,
//       statistics and the FMU's SetReal/DoStep/GetReal per cycle, the duties held.
//   (b) the bare master: the FMU opened and started (fmi2Instantiate, fmi2SetupExperiment,
//       initialisation), then per step fmi2SetReal (the same held inputs), fmi2DoStep,
//       fmi2GetReal (all outputs) through the FMU's own function pointers, nothing else.
// CPU time per step: (a) the child's user + system time for 2D s minus that for D s, over the
// 4000 D cycles between (start-up and the FMU's unpacking cancel); (b) the thread's CPU time
// over the steps. Instructions per step (callgrind, load-independent): (a) all threads, 2D
// against D seconds; (b) a ToggleCounting bracket around 2N against N steps. Their difference
// is what the twin's loop costs beyond the FMU.
//
// Virtual time runs ~1,000x faster than real time, so D must be long for the CPU difference to
// stand above the start-up's spread (the FMU's unpacking, the map): 120 s of the twin is ~0.3 s.
//
// Usage: hiltwin_bench_fmi_loop HILTWIN [seconds=120] [rounds=3] [CASE (default all)]
//        hiltwin_bench_fmi_loop --bare-steps N CASE   (one bracket, for callgrind)
// CASE: lag, relbot or relbot_turning.
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
#include <string_view>
#include <vector>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "hiltwin/fmi/fmu_plant.h"
#include "hiltwin/kernel_glue/process.h"

namespace {

namespace fs = std::filesystem;
constexpr double kRateHz = 4000.0;
constexpr double kStepS = 1.0 / kRateHz;
// The duties the twin's input profile holds, left and right (exact in the board's n/2048 PWM
// steps): equal ones drive the RELbot straight, unequal ones turn it.
constexpr std::array<double, 2> kStraight{0.5, 0.5};
constexpr std::array<double, 2> kTurning{0.5, 0.25};

volatile double g_sink = 0.0;

// One FMU of the comparison: its file, its plant map (board channels to its ports), the duties
// the twin's input profile holds, and the inputs the bare master holds: what the map makes of
// those duties, in the FMU's input order.
struct Case {
  const char* name;
  const char* fmu;
  std::string map;  ///< the map's text, or empty when map_path names the file
  const char* map_path;
  std::array<double, 2> duties;
  std::vector<double> inputs;
  bool builtin_peer = false;  ///< also count the built-in RELbot's twin with the same duties
};

std::vector<Case> Cases() {
  const std::string lag_map =
      "[[pwm]]\nchannel = 1\ninput = \"u\"\ngain = 1.0\n\n"
      "[[encoder]]\nchannel = 1\noutput = \"y\"\nunit = \"rad\"\ncounts_per_unit = 651.9\n";
  const char* relbot = HILTWIN_BENCH_FMU_DIR "/relbot.fmu";
  // The RELbot's own map: PWM 2 -> duty_left, PWM 1 (the profile's right) -> duty_right.
  return {
      {"lag", HILTWIN_BENCH_FMU_DIR "/lag.fmu", lag_map, nullptr, kTurning, {kTurning[1]}},
      {"relbot", relbot, "", HILTWIN_RELBOT_MAP, kStraight, {kStraight[0], kStraight[1]}, true},
      {"relbot_turning", relbot, "", HILTWIN_RELBOT_MAP, kTurning, {kTurning[0], kTurning[1]},
       true},
  };
}

const Case& CaseNamed(const std::vector<Case>& cases, std::string_view name) {
  for (const Case& c : cases) {
    if (name == c.name) return c;
  }
  throw std::runtime_error("no FMU case '" + std::string(name) + "' (lag, relbot, relbot_turning)");
}

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

// The bare master's steps: the held inputs set, the step, every output read, as the twin does.
// Returns false when a call did not return fmi2OK.
bool BareSteps(const hiltwin::fmi::FmuDirectCalls& fmu, const std::vector<double>& u,
               std::vector<double>& y, long steps) {
  bool ok = true;
  for (long k = 0; k < steps; ++k) {
    ok = fmu.set_real(fmu.component, fmu.input_refs.data(), u.size(), u.data()) == fmi2OK && ok;
    ok = fmu.do_step(fmu.component, static_cast<double>(k) * kStepS, kStepS, fmi2True) ==
             fmi2OK && ok;
    ok = fmu.get_real(fmu.component, fmu.output_refs.data(), y.size(), y.data()) == fmi2OK &&
         ok;
  }
  g_sink = g_sink + y[0];
  return ok;
}

std::unique_ptr<hiltwin::fmi::FmuPlant> StartedFmu(const Case& c, std::vector<double>& y) {
  auto plant = hiltwin::fmi::OpenFmu(c.fmu);
  if (plant->Info().inputs.size() != c.inputs.size() || plant->Info().outputs.empty()) {
    throw std::runtime_error(std::string(c.fmu) + ": not the ports this benchmark drives");
  }
  y.assign(plant->Info().outputs.size(), 0.0);
  plant->Start(kStepS, y);
  return plant;
}

// `--bare-steps N CASE`: N bare steps between two ToggleCounting() calls.
int CountedBareSteps(long steps, const Case& c) {
  std::vector<double> y;
  const auto plant = StartedFmu(c, y);
  const hiltwin::fmi::FmuDirectCalls fmu = plant->DirectCalls();
  hiltwin::bench::ToggleCounting();
  const bool ok = BareSteps(fmu, c.inputs, y, steps);
  hiltwin::bench::ToggleCounting();
  return ok ? 0 : 3;
}

double BareCpuNsPerStep(const Case& c, long steps) {
  std::vector<double> y;
  const auto plant = StartedFmu(c, y);
  const hiltwin::fmi::FmuDirectCalls fmu = plant->DirectCalls();
  (void)BareSteps(fmu, c.inputs, y, steps / 10);  // warm-up
  plant->Reset(y);  // model time 0 again, as the timed steps count from 0
  const double start = ThreadCpuS();
  const bool ok = BareSteps(fmu, c.inputs, y, steps);
  const double end = ThreadCpuS();
  if (!ok) throw std::runtime_error("the bare master's FMU calls failed");
  return (end - start) * 1e9 / static_cast<double>(steps);
}

// The files the twin runs with: the map and the held duties' input profile.
struct TwinFiles {
  fs::path map;
  fs::path input;
};

TwinFiles WriteTwinFiles(const Case& c, const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path own_map = dir / (std::string(c.name) + "_map.toml");
  TwinFiles files{c.map_path != nullptr ? fs::path(c.map_path) : own_map,
                  dir / (std::string(c.name) + "_duties.csv")};
  if (c.map_path == nullptr) std::ofstream(files.map) << c.map;
  std::ofstream(files.input) << "time,left,right\n0," << c.duties[0] << ',' << c.duties[1]
                             << "\n100000," << c.duties[0] << ',' << c.duties[1] << '\n';
  return files;
}

// The twin with the case's FMU, or (builtin) the built-in RELbot with its own map.
std::vector<std::string> TwinArgs(const std::string& hiltwin, const Case& c,
                                  const TwinFiles& files, double seconds, bool builtin = false) {
  std::vector<std::string> args = {hiltwin, "run", "--input", files.input.string(), "--clock",
                                   "virtual", "--duration", std::to_string(seconds),
                                   "--no-progress"};
  if (!builtin) {
    const std::vector<std::string> plant = {"--plant", std::string("fmu:") + c.fmu,
                                            "--plant-map", files.map.string()};
    args.insert(args.begin() + 2, plant.begin(), plant.end());
  }
  return args;
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
double TwinInstructionsPerStep(const std::string& hiltwin, const Case& c, const TwinFiles& files,
                               double seconds, bool builtin = false) {
  const auto count = [&](double s) {
    const fs::path out = fs::temp_directory_path() / ("hiltwin_fmi_loop_cg_" +
                                                      std::to_string(getpid()));
    std::vector<std::string> args = {"valgrind", "--tool=callgrind",
                                     "--callgrind-out-file=" + out.string()};
    const auto twin = TwinArgs(hiltwin, c, files, s, builtin);
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

// A ratio at or below 0 means the twin's CPU difference drowned in start-up noise.
const char* Verdict(double ratio) {
  return ratio <= 0.0 ? "not measured: raise the seconds" : ratio <= 3.0 ? "met" : "NOT met";
}

void ReportInstructions(const std::string& hiltwin, const Case& c, const TwinFiles& files,
                        const char* self) {
  try {
    const double twin = TwinInstructionsPerStep(hiltwin, c, files, 1.0);
    const auto bare_count = [&](long steps) {
      return hiltwin::bench::CountInstructions({self, "--bare-steps", std::to_string(steps),
                                                c.name});
    };
    const double bare = hiltwin::bench::InstructionsPerItem(4000, bare_count(4000), 8000,
                                                            bare_count(8000));
    std::printf("  instructions per step (callgrind): hiltwin run %.0f, bare FMI master (peer) "
                "%.0f, ratio %.2f (target <= 3: %s); the loop beyond the FMU %.0f\n",
                twin, bare, twin / bare, Verdict(twin / bare), twin - bare);
    if (c.builtin_peer) {
      const double builtin = TwinInstructionsPerStep(hiltwin, c, files, 1.0, true);
      std::printf("  the built-in RELbot's twin, same duties: %.0f instructions per step; the FMU "
                  "twin costs %+.0f more (its FMU against the built-in model)\n", builtin,
                  twin - builtin);
    }
  } catch (const std::exception& e) {
    std::printf("  instructions per step: not counted (%s)\n", e.what());
  }
}

void ReportCase(const std::string& hiltwin, double seconds, int rounds, const Case& c,
                const char* self) {
  const fs::path dir = fs::temp_directory_path() / ("hiltwin_fmi_loop_" + std::to_string(getpid()));
  const TwinFiles files = WriteTwinFiles(c, dir);
  const double cycles = seconds * kRateHz;
  std::vector<double> twin_ns;
  std::vector<double> bare_ns;
  std::vector<double> ratio;
  std::vector<double> beyond_ns;
  for (int r = 0; r < rounds; ++r) {
    const double once = TwinCpuS(TwinArgs(hiltwin, c, files, seconds));
    const double twice = TwinCpuS(TwinArgs(hiltwin, c, files, 2 * seconds));
    twin_ns.push_back((twice - once) * 1e9 / cycles);
    bare_ns.push_back(BareCpuNsPerStep(c, static_cast<long>(cycles)));
    ratio.push_back(twin_ns.back() / bare_ns.back());
    beyond_ns.push_back(twin_ns.back() - bare_ns.back());
  }
  const auto ratio_spread = hiltwin::bench::SpreadOf(ratio);
  std::printf("fmi_loop %s: %s, %.0f Hz, %g s against %g s of the twin, %d rounds; median "
              "(range)\n", c.name, c.fmu, kRateHz, 2 * seconds, seconds, rounds);
  std::printf("  CPU per step: hiltwin run %s, bare FMI master (peer) %s, ratio %s (target <= 3: "
              "%s); the loop beyond the FMU %s\n",
              FormatSpread(hiltwin::bench::SpreadOf(twin_ns), "ns").c_str(),
              FormatSpread(hiltwin::bench::SpreadOf(bare_ns), "ns").c_str(),
              FormatSpread(ratio_spread, "x", 2).c_str(), Verdict(ratio_spread.median),
              FormatSpread(hiltwin::bench::SpreadOf(beyond_ns), "ns").c_str());
  ReportInstructions(hiltwin, c, files, self);
  fs::remove_all(dir);
}

}  // namespace

int main(int argc, char** argv) try {
  const std::vector<Case> cases = Cases();
  if (argc >= 4 && std::strcmp(argv[1], "--bare-steps") == 0) {
    return CountedBareSteps(std::atol(argv[2]), CaseNamed(cases, argv[3]));
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s HILTWIN [seconds=120] [rounds=3] [CASE]\n", argv[0]);
    return 2;
  }
  const double seconds = argc > 2 ? std::atof(argv[2]) : 120.0;
  const int rounds = argc > 3 ? std::atoi(argv[3]) : 3;
  if (!(seconds > 0.0) || rounds <= 0) {
    std::fprintf(stderr, "usage: %s HILTWIN [seconds > 0] [rounds > 0] [CASE]\n", argv[0]);
    return 2;
  }
  for (const Case& c : cases) {
    if (argc > 4 && argv[4] != std::string_view(c.name)) continue;
    ReportCase(argv[1], seconds, rounds, c, argv[0]);
  }
  return 0;
} catch (const std::exception& error) {
  std::fprintf(stderr, "hiltwin_bench_fmi_loop: %s\n", error.what());
  return 2;
}
