// What tracing costs the loop. First the hiltwin:cycle tracepoint alone, as the loop fires it:
// thread CPU time per call (CLOCK_THREAD_CPUTIME_ID) with no LTTng session ("idle": compiled
// in, one branch) and with a session recording hiltwin:* ("recording": every event written
// to the ring buffer), rounds alternating the two, printed per round and as median and range;
// then its instructions per call, counted by callgrind (load-independent: this VM has no
// hardware counters). Then the whole loop: the loop thread's CPU time from its first cycle to
// its last divided by its cycles, for the run assembly with an empty task in real time at 4
// and 20 kHz, idle against recording, alternating, with the events the tracer discarded. The
// peer figure is always the idle one of the same round. Compiled out against idle:
// bench/trace/compiled_out.sh (callgrind, two builds).
//   hiltwin_bench_trace [ROUNDS=5] [SECONDS=3]
//   hiltwin_bench_trace --calls N idle|recording   one counted run (run under callgrind)
#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/lttng_session.h"
#include "hiltwin/tracing/trace.h"

namespace {

namespace fs = std::filesystem;
using hiltwin::bench::FormatSpread;
using hiltwin::bench::Median;
using hiltwin::bench::SpreadOf;
using hiltwin::runtime::RunSession;
using hiltwin::runtime::SessionConfig;
using hiltwin::trace_capture::LttngSession;

constexpr double kTargetNs = 300.0;

class EmptyTask final : public hiltwin::runtime::RunTask {
 public:
  hiltwin::io::ExchangeStatus Exchange(bool) noexcept override { return {}; }
  hiltwin::runtime::StepStatus Step(const hiltwin::scheduler::CycleContext&) noexcept override {
    return {};
  }
  std::vector<std::string> LogColumns() const override { return {}; }
  double LogTimeS() const noexcept override { return 0.0; }
  void FillLogRow(std::span<double>) const noexcept override {}
};

double ThreadCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

/// The loop thread's CPU time between its first and last cycle.
class LoopCpu final : public hiltwin::runtime::LoopThreadHooks {
 public:
  void BeforeLoop() noexcept override { start_ns_ = ThreadCpuNs(); }
  void AfterLoop() noexcept override { cpu_ns = ThreadCpuNs() - start_ns_; }
  double cpu_ns = 0.0;

 private:
  double start_ns_ = 0.0;
};

/// Starts `session` recording hiltwin:* of this process, as `hiltwin trace` configures it for
/// a loop at `rate_hz`, when `recording`; leaves it empty otherwise.
void StartIf(std::optional<LttngSession>& session, bool recording, double rate_hz,
             const fs::path& dir, bool await_registration = false) {
  if (!recording) return;
  fs::remove_all(dir);
  session.emplace(hiltwin::trace_capture::LttngSessionConfig{
      .output_dir = dir.string(),
      .rate_hz = rate_hz,
      .only_pid = static_cast<int>(getpid()),
      .await_registration = await_registration});
}

struct RunFigures {
  double ns_per_cycle = 0.0;
  std::uint64_t discarded = 0;
};

RunFigures RunOnce(double rate_hz, double seconds, bool recording, const fs::path& dir) {
  SessionConfig config;
  config.rate_hz = rate_hz;
  config.executive.period_ns = static_cast<std::int64_t>(1e9 / rate_hz);
  config.executive.max_cycles = static_cast<std::uint64_t>(rate_hz * seconds);
  config.qos.rules = {hiltwin::qos::MakeMissRatioRule(100.0)};
  config.qos.planned_cycles = config.executive.max_cycles;
  config.rt.fifo_priority = 80;
  std::optional<LttngSession> session;
  StartIf(session, recording, rate_hz, dir);
  EmptyTask task;
  LoopCpu cpu;
  RunSession run(config, task);
  run.SetLoopThreadHooks(&cpu);
  const hiltwin::runtime::RunReport report = run.Run();
  RunFigures figures;
  if (session) figures.discarded = session->Stop().discarded_events;
  figures.ns_per_cycle = cpu.cpu_ns / static_cast<double>(report.cycles_run);
  return figures;
}

/// The cycle tracepoint as the loop fires it, `calls` times from cycle `first` on, with the
/// time stamps of a 20 kHz loop. Out of line: the timed and the counted runs run this code.
[[gnu::noinline]] void FireCycleEvents(std::uint64_t first, std::uint64_t calls) {
  for (std::uint64_t k = first; k < first + calls; ++k) {
    const auto t = static_cast<std::int64_t>(k) * 50'000;
    HILTWIN_TRACE(cycle, k, t, t + 10'000, t + 10'100, t + 10'300, std::int64_t{100},
                  std::uint32_t{0}, std::uint8_t{0}, std::uint8_t{1});
  }
}

/// Thread CPU time per call of the cycle tracepoint, in batches of 1000 calls 50 ms apart
/// (20 kHz on average, as a loop would), without or with a session.
double CycleEventNs(bool recording, const fs::path& dir) {
  std::optional<LttngSession> session;
  StartIf(session, recording, 20'000.0, dir);
  constexpr std::uint64_t kBatches = 40;
  constexpr std::uint64_t kCalls = 1000;
  double spent_ns = 0.0;
  for (std::uint64_t batch = 0; batch < kBatches; ++batch) {
    const double start_ns = ThreadCpuNs();
    FireCycleEvents(batch * kCalls, kCalls);
    spent_ns += ThreadCpuNs() - start_ns;
    const timespec pause{0, 50'000'000};
    nanosleep(&pause, nullptr);
  }
  if (session) session->Stop();
  return spent_ns / static_cast<double>(kBatches * kCalls);
}

/// `--calls N idle|recording`: N calls between two ToggleCounting() (so under callgrind only
/// they count), with a session that has set this process up before the first call. Exit 3 when
/// the tracer discarded events: the count would then be of the discard path.
int CountedCalls(const char* calls_text, const char* mode, const fs::path& dir) {
  const std::uint64_t calls = std::strtoull(calls_text, nullptr, 10);
  const bool recording = std::strcmp(mode, "recording") == 0;
  if (calls == 0 || (!recording && std::strcmp(mode, "idle") != 0)) {
    std::fprintf(stderr, "usage: hiltwin_bench_trace --calls N(>0) idle|recording\n");
    return 2;
  }
  std::optional<LttngSession> session;
  StartIf(session, recording, 20'000.0, dir, true);
  if (recording && !lttng_ust_tracepoint_enabled(hiltwin, cycle)) {
    std::fprintf(stderr, "hiltwin:cycle is not enabled although a session records it\n");
    return 3;
  }
  hiltwin::bench::ToggleCounting();
  FireCycleEvents(0, calls);
  hiltwin::bench::ToggleCounting();
  const std::uint64_t discarded = session ? session->Stop().discarded_events : 0;
  fs::remove_all(dir);
  if (discarded > 0) {
    std::fprintf(stderr, "%llu events discarded\n", static_cast<unsigned long long>(discarded));
    return 3;
  }
  return 0;
}

/// The tracepoint alone, timed: rounds alternate idle and recording.
void ReportCallTime(int rounds, const fs::path& dir) {
  std::vector<double> idle;
  std::vector<double> recording;
  std::vector<double> extra;
  for (int round = 0; round < rounds; ++round) {
    idle.push_back(CycleEventNs(false, dir));
    recording.push_back(CycleEventNs(true, dir));
    extra.push_back(recording.back() - idle.back());
    std::printf("  round %d: idle %.1f ns/call, recording %.1f ns/call, extra %.1f ns\n",
                round + 1, idle.back(), recording.back(), extra.back());
  }
  const double median_extra = Median(extra);
  std::printf(
      "  hiltwin:cycle tracepoint alone, median (range) of %d rounds: idle (peer) %s, "
      "recording %s, extra %s per call (target <= 300: %s)\n",
      rounds, FormatSpread(SpreadOf(idle), "ns").c_str(),
      FormatSpread(SpreadOf(recording), "ns").c_str(), FormatSpread(SpreadOf(extra), "ns").c_str(),
      median_extra <= kTargetNs ? "met" : "NOT met");
}

/// The tracepoint alone, counted: calls of two run lengths under callgrind, per mode.
void ReportCallInstructions(const char* self) {
  constexpr std::uint64_t kFew = 2'000;
  constexpr std::uint64_t kMany = 12'000;  // 12,000 x 80 B: well inside one CPU's 2 MiB
  double per_call[2] = {};
  for (const bool recording : {false, true}) {
    const char* mode = recording ? "recording" : "idle";
    const auto count = [&](std::uint64_t calls) {
      return hiltwin::bench::CountInstructions({self, "--calls", std::to_string(calls), mode});
    };
    per_call[recording ? 1 : 0] = hiltwin::bench::InstructionsPerItem(kFew, count(kFew), kMany,
                                                                      count(kMany));
  }
  std::printf(
      "  hiltwin:cycle instructions per call (callgrind, %llu against %llu calls): idle (peer) "
      "%.1f, recording %.1f, extra %.1f\n",
      static_cast<unsigned long long>(kMany), static_cast<unsigned long long>(kFew), per_call[0],
      per_call[1], per_call[1] - per_call[0]);
}

/// The whole loop at two rates: rounds alternate idle and recording.
void ReportLoop(int rounds, double seconds, const fs::path& dir) {
  for (const double rate_hz : {4000.0, 20000.0}) {
    std::vector<double> idle;
    std::vector<double> recording;
    std::uint64_t discarded = 0;
    for (int round = 0; round < rounds; ++round) {
      idle.push_back(RunOnce(rate_hz, seconds, false, dir).ns_per_cycle);
      const RunFigures traced = RunOnce(rate_hz, seconds, true, dir);
      recording.push_back(traced.ns_per_cycle);
      discarded += traced.discarded;
    }
    const double extra = Median(recording) - Median(idle);
    // A difference within the idle rounds' own range is the machine's noise, not tracing's.
    const hiltwin::bench::Spread idle_spread = SpreadOf(idle);
    const double noise = idle_spread.max - idle_spread.min;
    char verdict[96];
    if (std::abs(extra) < noise) {
      std::snprintf(verdict, sizeof verdict, "not resolved: within the idle rounds' %.1f ns",
                    noise);
    } else {
      std::snprintf(verdict, sizeof verdict, "target <= 300: %s",
                    extra <= kTargetNs ? "met" : "NOT met");
    }
    std::printf("  %5.0f Hz  idle (peer) %s  recording %s  extra %.1f ns/cycle (%s)  "
                "discarded events %llu\n",
                rate_hz, FormatSpread(idle_spread, "ns").c_str(),
                FormatSpread(SpreadOf(recording), "ns").c_str(), extra, verdict,
                static_cast<unsigned long long>(discarded));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path dir =
      fs::temp_directory_path() / ("hiltwin_bench_trace_" + std::to_string(getpid()));
  try {
    if (argc == 4 && std::strcmp(argv[1], "--calls") == 0) {
      return CountedCalls(argv[2], argv[3], dir);
    }
    const int rounds = argc > 1 ? std::atoi(argv[1]) : 5;
    const double seconds = argc > 2 ? std::atof(argv[2]) : 3.0;
    if (rounds <= 0 || !(seconds > 0.0)) {
      std::fprintf(stderr, "usage: %s [ROUNDS > 0] [SECONDS > 0]\n", argv[0]);
      return 2;
    }
    std::printf("tracing cost: the cycle tracepoint alone (thread CPU time, %d alternating "
                "rounds of 40 x 1000 calls 50 ms apart), then the loop (loop-thread CPU time / "
                "cycles, empty task, real time, %d alternating rounds of %.1f s)\n",
                rounds, rounds, seconds);
    ReportCallTime(rounds, dir);
    ReportCallInstructions(fs::read_symlink("/proc/self/exe").c_str());
    ReportLoop(rounds, seconds, dir);
  } catch (const hiltwin::trace_capture::CaptureError& e) {
    std::fprintf(stderr, "hiltwin_bench_trace: cannot record here: %s\n", e.what());
    return 5;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hiltwin_bench_trace: %s\n", e.what());
    return 1;
  }
  fs::remove_all(dir);
  return 0;
}
