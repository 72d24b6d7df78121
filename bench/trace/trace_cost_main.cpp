// What tracing costs the loop, per cycle: the loop thread's CPU time (CLOCK_THREAD_CPUTIME_ID,
// from the first cycle to the last) divided by its cycles, for the run assembly with an empty
// task in real time at 4 and 20 kHz, with no LTTng session ("idle": the tracepoints are
// compiled in, each costs a branch) and with an LTTng session recording hiltwin:* ("recording":
// every event written to the ring buffer). Rounds alternate the two; medians are printed, with
// the difference and the events the tracer discarded. The peer figure is the idle run of the
// same round. Compiled out against idle: bench/trace/compiled_out.sh (callgrind, two builds).
//   hiltwin_bench_trace [ROUNDS=5] [SECONDS=3]
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "hiltwin/qos/rules.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/lttng_session.h"
#include "hiltwin/tracing/trace.h"

namespace {

namespace fs = std::filesystem;
using hiltwin::runtime::RunSession;
using hiltwin::runtime::SessionConfig;

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

struct RunFigures {
  double ns_per_cycle = 0.0;
  std::uint64_t misses = 0;
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
  std::optional<hiltwin::trace_capture::LttngSession> session;
  if (recording) {
    fs::remove_all(dir);
    session.emplace(hiltwin::trace_capture::LttngSessionConfig{dir.string(), rate_hz, true});
  }
  EmptyTask task;
  LoopCpu cpu;
  RunSession run(config, task);
  run.SetLoopThreadHooks(&cpu);
  const hiltwin::runtime::RunReport report = run.Run();
  RunFigures figures;
  if (session) figures.discarded = session->Stop().discarded_events;
  figures.ns_per_cycle = cpu.cpu_ns / static_cast<double>(report.cycles_run);
  figures.misses = report.misses.deadline_misses;
  return figures;
}

/// The cycle tracepoint alone, as the loop fires it: thread CPU time per call, in batches of
/// 1000 calls 50 ms apart (20 kHz on average, as a loop would), without and with a session.
double CycleEventNs(bool recording, const fs::path& dir) {
  std::optional<hiltwin::trace_capture::LttngSession> session;
  if (recording) {
    fs::remove_all(dir);
    session.emplace(hiltwin::trace_capture::LttngSessionConfig{
        .output_dir = dir.string(), .rate_hz = 20'000.0, .only_pid = static_cast<int>(getpid())});
  }
  constexpr int kBatches = 40;
  constexpr int kCalls = 1000;
  double spent_ns = 0.0;
  for (int batch = 0; batch < kBatches; ++batch) {
    const double start_ns = ThreadCpuNs();
    for (int i = 0; i < kCalls; ++i) {
      const auto k = static_cast<std::uint64_t>(batch * kCalls + i);
      const auto t = static_cast<std::int64_t>(k) * 50'000;
      HILTWIN_TRACE(cycle, k, t, t + 10'000, t + 10'100, t + 10'300, std::int64_t{100},
                    std::uint32_t{0}, std::uint8_t{0}, std::uint8_t{1});
    }
    spent_ns += ThreadCpuNs() - start_ns;
    const timespec pause{0, 50'000'000};
    nanosleep(&pause, nullptr);
  }
  if (session) session->Stop();
  return spent_ns / (kBatches * kCalls);
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 5;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 3.0;
  const fs::path dir =
      fs::temp_directory_path() / ("hiltwin_bench_trace_" + std::to_string(getpid()));
  std::printf(
      "tracing cost per loop cycle: loop-thread CPU time / cycles, empty task, real time, "
      "%d alternating rounds of %.1f s, median\n",
      rounds, seconds);
  try {
    const double idle_call = CycleEventNs(false, dir);
    const double recorded_call = CycleEventNs(true, dir);
    std::printf(
        "  hiltwin:cycle tracepoint alone: idle (peer) %.1f ns/call, recording %.1f ns/call, "
        "extra %.1f ns (target <= 300: %s)\n",
        idle_call, recorded_call, recorded_call - idle_call,
        recorded_call - idle_call <= 300.0 ? "met" : "NOT met");
    for (const double rate_hz : {4000.0, 20000.0}) {
      std::vector<double> idle, recording;
      std::uint64_t discarded = 0;
      for (int round = 0; round < rounds; ++round) {
        idle.push_back(RunOnce(rate_hz, seconds, false, dir).ns_per_cycle);
        const RunFigures traced = RunOnce(rate_hz, seconds, true, dir);
        recording.push_back(traced.ns_per_cycle);
        discarded += traced.discarded;
      }
      const double extra = Median(recording) - Median(idle);
      std::printf(
          "  %5.0f Hz  idle (peer) %7.1f ns  recording %7.1f ns  extra %6.1f ns/cycle "
          "(target <= 300: %s)  discarded events %llu\n",
          rate_hz, Median(idle), Median(recording), extra, extra <= 300.0 ? "met" : "NOT met",
          static_cast<unsigned long long>(discarded));
    }
  } catch (const hiltwin::trace_capture::CaptureError& e) {
    std::fprintf(stderr, "hiltwin_bench_trace: cannot record here: %s\n", e.what());
    return 5;
  }
  fs::remove_all(dir);
  return 0;
}
