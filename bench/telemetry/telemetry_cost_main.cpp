// The loop's per-cycle cost with telemetry on against off: the same RunSession on the virtual
// clock (so only the loop's own work is timed, no sleeping), with a task that fills the
// RELbot twin's telemetry (pose and two wheels) and a sink that drops every record. "On" adds
// exactly what the loop pays for telemetry: filling the snapshot, publishing it through the
// mailbox (one atomic exchange) and pushing the cycle's latency into the ring; the telemetry
// thread runs meanwhile at 50 Hz on the other CPU. Rounds alternate off/on; the figure is the
// median per-cycle difference. Usage:
//   hiltwin_bench_telemetry [--cycles 2000000] [--rounds 7]
// Target (issue 13): under 100 ns per cycle.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hiltwin/runtime/run_session.h"

namespace {

namespace rt = hiltwin::runtime;

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

class NullSink final : public rt::TelemetrySink {
 public:
  void Open(const rt::TelemetryShape&, const std::string&) override {}
  void Publish(const rt::TelemetryRecord& record) noexcept override { cycles_seen_ = record.cycle; }
  std::string Describe() const override { return "null"; }

 private:
  std::uint64_t cycles_seen_ = 0;
};

/// Nanoseconds per cycle of one virtual run.
double NsPerCycle(std::uint64_t cycles, bool telemetry) {
  PoseTask task;
  rt::SessionConfig config;
  config.clock = rt::ClockKind::kVirtual;
  config.rate_hz = 4000.0;
  config.executive.period_ns = 250'000;
  config.executive.max_cycles = cycles;
  config.qos.rules = {hiltwin::qos::MakeMissRatioRule(1.0), hiltwin::qos::MakeMkRule(1, 2)};
  config.qos.planned_cycles = cycles;
  if (telemetry) {
    config.telemetry.ns = "bench";
    config.telemetry.sinks = {std::make_shared<NullSink>()};
  }
  rt::RunSession session(std::move(config), task);
  const auto start = std::chrono::steady_clock::now();
  const rt::RunReport report = session.Run();
  const auto elapsed = std::chrono::steady_clock::now() - start;
  return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count()) /
         static_cast<double>(report.cycles_run);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t cycles = 2'000'000;
  int rounds = 7;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--cycles") == 0) cycles = std::strtoull(argv[i + 1], nullptr, 10);
    if (std::strcmp(argv[i], "--rounds") == 0) rounds = std::atoi(argv[i + 1]);
  }
  static_cast<void>(NsPerCycle(cycles / 4, true));  // warm-up: page faults, caches, CPU clock
  std::vector<double> off, on, diff;
  for (int r = 0; r < rounds; ++r) {
    off.push_back(NsPerCycle(cycles, false));
    on.push_back(NsPerCycle(cycles, true));
    diff.push_back(on.back() - off.back());
    std::printf("round %d: off %.1f ns/cycle, on %.1f ns/cycle, difference %+.1f ns\n", r + 1,
                off.back(), on.back(), diff.back());
  }
  const double d = Median(diff);
  std::printf("telemetry off (peer): %.1f ns/cycle (median of %d runs of %llu cycles)\n",
              Median(off), rounds, static_cast<unsigned long long>(cycles));
  std::printf("telemetry on:         %.1f ns/cycle; ratio on/off %.3f\n", Median(on),
              Median(on) / Median(off));
  std::printf("difference: %+.1f ns/cycle (median of the rounds' differences); target < 100 ns: %s\n",
              d, d < 100.0 ? "met" : "NOT met");
  return 0;
}
