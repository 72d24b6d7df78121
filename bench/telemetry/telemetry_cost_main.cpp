// The loop's per-cycle cost with telemetry off against on, for each way telemetry leaves a
// task: the same RunSession on the virtual clock (so only the loop's own work is measured, no
// sleeping), with a task that fills the RELbot twin's telemetry (pose and two wheels), through
// the real sinks: PlotJuggler's UDP stream (to a port nobody reads), DDS (domain 78, nobody
// subscribed) and the web page (a free port, no page open). "On" adds exactly what the loop
// pays for telemetry: filling the snapshot, publishing it through the mailbox (one atomic
// exchange) and pushing the cycle's latency into the ring; the telemetry thread runs meanwhile
// at 50 Hz on the other CPU, and what a sink does there is not the loop's cost.
// Two figures per way: wall-clock time per cycle, rounds alternating off and the sinks (median
// and range of the per-round differences), and the loop thread's instructions per cycle,
// counted by callgrind (load-independent; this VM has no hardware counters). Usage:
//   hiltwin_bench_telemetry [--cycles 2000000] [--rounds 7]
//   hiltwin_bench_telemetry --count off|udp|dds|web N   one counted run (run under callgrind)
// Target (issue 13): under 100 ns per cycle.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/telemetry/sinks.h"

namespace {

namespace rt = hiltwin::runtime;
using hiltwin::bench::FormatSpread;
using hiltwin::bench::Median;
using hiltwin::bench::SpreadOf;

/// The ways telemetry leaves a task; kOff is the peer.
enum class Way { kOff, kUdp, kDds, kWeb };
constexpr std::array<Way, 4> kWays = {Way::kOff, Way::kUdp, Way::kDds, Way::kWeb};
constexpr std::uint32_t kDomain = 78;  // dds_miss_ratio.sh uses 77; no test uses either

const char* NameOf(Way way) {
  switch (way) {
    case Way::kOff: return "off";
    case Way::kUdp: return "udp";
    case Way::kDds: return "dds";
    case Way::kWeb: return "web";
  }
  return "?";
}

std::optional<Way> WayNamed(const char* name) {
  for (const Way way : kWays) {
    if (std::strcmp(name, NameOf(way)) == 0) return way;
  }
  return std::nullopt;
}

std::vector<std::shared_ptr<rt::TelemetrySink>> SinksFor(Way way) {
  namespace tm = hiltwin::telemetry;
  switch (way) {
    case Way::kOff: return {};
    case Way::kUdp: return {tm::MakeUdpSink({.host = "127.0.0.1", .port = 9})};  // discard port
    case Way::kDds: return {tm::MakeDdsSink({.domain = kDomain})};
    case Way::kWeb: return {tm::MakeWebSink({.address = "127.0.0.1", .port = 0})};
  }
  return {};
}

/// The twin's telemetry without its model: what FillTelemetry copies per cycle.
class PoseTask final : public rt::RunTask {
 public:
  hiltwin::io::ExchangeStatus Exchange(bool) noexcept override { return {.board_answered = true}; }
  rt::StepStatus Step(const hiltwin::scheduler::CycleContext& c) noexcept override {
    x_m_ = static_cast<double>(c.cycle) * 1e-6;
    return rt::StepStatus::Ok();
  }
  std::vector<std::string> LogColumns() const override { return {"x_m"}; }
  double LogTimeS() const noexcept override { return x_m_; }
  void FillLogRow(std::span<double> values) const noexcept override { values[0] = x_m_; }
  rt::TelemetryShape TelemetryShapeOf() const override {
    return {"twin", true, {"wheel_left_joint", "wheel_right_joint"}};
  }
  void FillTelemetry(rt::TaskTelemetry& out) const noexcept override {
    out.has_pose = true;
    out.x_m = x_m_;
    out.y_m = x_m_ * 0.5;
    out.theta_rad = x_m_ * 0.1;
    out.joint_count = 2;
    out.joint_position_m[0] = out.joint_position_m[1] = x_m_;
    out.joint_position_rad[0] = out.joint_position_rad[1] = x_m_ * 20.0;
  }

 private:
  double x_m_ = 0.0;
};

/// Callgrind counts the loop thread only, from its first cycle to its last.
class CountLoop final : public rt::LoopThreadHooks {
 public:
  void BeforeLoop() noexcept override { hiltwin::bench::ToggleCounting(); }
  void AfterLoop() noexcept override { hiltwin::bench::ToggleCounting(); }
};

/// One virtual run of `cycles`; returns its cycles run. `hooks` may be null.
std::uint64_t RunVirtual(std::uint64_t cycles, Way way, rt::LoopThreadHooks* hooks) {
  PoseTask task;
  rt::SessionConfig config;
  config.clock = rt::ClockKind::kVirtual;
  config.rate_hz = 4000.0;
  config.executive.period_ns = 250'000;
  config.executive.max_cycles = cycles;
  config.qos.rules = {hiltwin::qos::MakeMissRatioRule(1.0), hiltwin::qos::MakeMkRule(1, 2)};
  config.qos.planned_cycles = cycles;
  if (way != Way::kOff) {
    config.telemetry.ns = "bench_cost";
    config.telemetry.sinks = SinksFor(way);
  }
  rt::RunSession session(std::move(config), task);
  if (hooks != nullptr) session.SetLoopThreadHooks(hooks);
  return session.Run().cycles_run;
}

/// Wall-clock nanoseconds per cycle of one virtual run (the sinks are opened before the clock
/// starts and closed after it stops).
double NsPerCycle(std::uint64_t cycles, Way way) {
  struct Clocked final : rt::LoopThreadHooks {
    void BeforeLoop() noexcept override { start = std::chrono::steady_clock::now(); }
    void AfterLoop() noexcept override { end = std::chrono::steady_clock::now(); }
    std::chrono::steady_clock::time_point start, end;
  } clocked;
  const std::uint64_t run = RunVirtual(cycles, way, &clocked);
  return hiltwin::bench::NsPer(clocked.start, clocked.end, static_cast<long>(run));
}

/// Time: rounds alternate every way; per way the median and range of its per-round
/// difference to off.
void ReportTime(std::uint64_t cycles, int rounds) {
  static_cast<void>(NsPerCycle(cycles / 4, Way::kUdp));  // warm-up: page faults, caches, clock
  std::array<std::vector<double>, kWays.size()> ns;
  std::array<std::vector<double>, kWays.size()> diff;
  for (int r = 0; r < rounds; ++r) {
    std::printf("round %d:", r + 1);
    for (std::size_t w = 0; w < kWays.size(); ++w) {
      ns[w].push_back(NsPerCycle(cycles, kWays[w]));
      diff[w].push_back(ns[w].back() - ns[0].back());
      std::printf(" %s %.1f ns/cycle%s", NameOf(kWays[w]), ns[w].back(),
                  w + 1 < kWays.size() ? "," : "\n");
    }
  }
  std::printf("time per cycle, median (range) of %d alternating rounds of %llu cycles:\n", rounds,
              static_cast<unsigned long long>(cycles));
  std::printf("  off (peer): %s\n", FormatSpread(SpreadOf(ns[0]), "ns").c_str());
  for (std::size_t w = 1; w < kWays.size(); ++w) {
    const double d = Median(diff[w]);
    std::printf("  %-3s: %s, difference %s (target < 100 ns: %s)\n", NameOf(kWays[w]),
                FormatSpread(SpreadOf(ns[w]), "ns").c_str(),
                FormatSpread(SpreadOf(diff[w]), "ns").c_str(), d < 100.0 ? "met" : "NOT met");
  }
}

/// Instructions: each way counted under callgrind in runs of two lengths.
void ReportInstructions() {
  constexpr std::uint64_t kFew = 20'000;
  constexpr std::uint64_t kMany = 60'000;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::array<double, kWays.size()> per_cycle{};
  for (std::size_t w = 0; w < kWays.size(); ++w) {
    const auto count = [&](std::uint64_t cycles) {
      return hiltwin::bench::CountInstructions(
          {self, "--count", NameOf(kWays[w]), std::to_string(cycles)});
    };
    per_cycle[w] = hiltwin::bench::InstructionsPerItem(kFew, count(kFew), kMany, count(kMany));
  }
  std::printf("loop-thread instructions per cycle (callgrind, %llu against %llu cycles):\n",
              static_cast<unsigned long long>(kMany), static_cast<unsigned long long>(kFew));
  std::printf("  off (peer): %.1f\n", per_cycle[0]);
  for (std::size_t w = 1; w < kWays.size(); ++w) {
    std::printf("  %-3s: %.1f, difference %+.1f\n", NameOf(kWays[w]), per_cycle[w],
                per_cycle[w] - per_cycle[0]);
  }
}

/// `--count WAY N`: one run whose loop thread callgrind counts (CountLoop).
int CountedRun(const char* way_name, const char* cycles_text) {
  const std::optional<Way> way = WayNamed(way_name);
  const std::uint64_t cycles = std::strtoull(cycles_text, nullptr, 10);
  if (!way || cycles == 0) {
    std::fprintf(stderr, "usage: hiltwin_bench_telemetry --count off|udp|dds|web CYCLES(>0)\n");
    return 2;
  }
  CountLoop hooks;
  return RunVirtual(cycles, *way, &hooks) == cycles ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 4 && std::strcmp(argv[1], "--count") == 0) return CountedRun(argv[2], argv[3]);
    std::uint64_t cycles = 2'000'000;
    int rounds = 7;
    for (int i = 1; i < argc; i += 2) {
      const bool known = i + 1 < argc && (std::strcmp(argv[i], "--cycles") == 0 ||
                                          std::strcmp(argv[i], "--rounds") == 0);
      if (!known) {
        std::fprintf(stderr, "usage: %s [--cycles N] [--rounds N]\n", argv[0]);
        return 2;
      }
      if (std::strcmp(argv[i], "--cycles") == 0) cycles = std::strtoull(argv[i + 1], nullptr, 10);
      if (std::strcmp(argv[i], "--rounds") == 0) rounds = std::atoi(argv[i + 1]);
    }
    if (cycles == 0 || rounds <= 0) {
      std::fprintf(stderr, "%s: --cycles and --rounds take numbers > 0\n", argv[0]);
      return 2;
    }
    ReportTime(cycles, rounds);
    ReportInstructions();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hiltwin_bench_telemetry: %s\n", e.what());
    return 1;
  }
  return 0;
}
