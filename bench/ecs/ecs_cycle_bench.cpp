// ns per ECS cycle: EcsTask::Exchange (encode, emulated SPI transfer to an icoboard image that
// decodes, sets its PWM generator and reads its quadrature readers, answer decoded and counts
// unwrapped) plus EcsTask::Step (counts -> metres, setpoint profile, one PositionPid per
// wheel, duty -> PWM, tracking statistics), closed and open loop. The peer is the PID step
// alone for both wheels (the controller without the I/O and bookkeeping around it), and a
// textbook PID (derivative on the error, unfiltered, no anti-windup) shows what the
// filter and the anti-windup cost. Thread CPU time, median of 9 runs (minimum too), so a
// loaded shared machine does not count the time this thread was preempted.
//
// Usage: hiltwin_bench_ecs [cycles_per_run=200000]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/ecs_task.h"
#include "hiltwin/relbot/relbot_params.h"

namespace {

using namespace hiltwin;

constexpr std::int64_t kPeriodNs = 1'000'000;
constexpr int kRuns = 9;

volatile double g_sink = 0.0;  // keeps results observable

double ThreadCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

struct Figure {
  double median_ns = 0.0;
  double min_ns = 0.0;
};

template <typename F>
Figure NsPerCall(F&& body, long calls) {
  std::vector<double> ns;
  for (int r = 0; r < kRuns; ++r) {
    const double start = ThreadCpuNs();
    for (long i = 0; i < calls; ++i) body(i);
    ns.push_back((ThreadCpuNs() - start) / static_cast<double>(calls));
  }
  std::sort(ns.begin(), ns.end());
  return {ns[ns.size() / 2], ns.front()};
}

scheduler::CycleContext Cycle(long i) {
  // The closedloop profile's 12 s, over and over, so the setpoint moves as in a real run.
  scheduler::CycleContext context;
  context.cycle = static_cast<std::uint64_t>(i % 12'000);
  context.period_ns = kPeriodNs;
  return context;
}

/// The ECS task on a lone emulated board (the timing clock is virtual, so reading it is free:
/// the figure is the exchange and the step, as in the io benchmark).
struct EcsRig {
  EcsRig() { driver_ok = driver.Init(kPeriodNs).ok; }
  kernel_glue::VirtualClock untimed;
  io::EmulatedFpga board{io::Image::kIcoboard};
  io::EmulatedSpiBus bus{board};
  io::IcoBoard driver{bus, &untimed};
  io::WheelGeometry geometry = app::WheelGeometryOf(app::DefaultRelbotParams());
  bool driver_ok = false;
};

/// One EcsTask cycle as the loop runs it: Exchange, then Step. `label` names it in errors.
Figure TaskCycleNs(app::EcsTask& task, const EcsRig& rig, long calls, const char* label) {
  std::uint64_t errors = rig.driver_ok ? 0 : 1;
  const Figure f = NsPerCall(
      [&](long i) {
        if (!task.Exchange(true).ok()) ++errors;
        if (task.Step(Cycle(i)).code != runtime::StepStatus::Code::kOk) ++errors;
      },
      calls);
  g_sink = g_sink + task.last().duty_next.left;
  if (errors != 0)
    std::printf("(%s: %llu errors)\n", label, static_cast<unsigned long long>(errors));
  return f;
}

Figure ClosedLoopCycleNs(long calls) {
  EcsRig rig;
  const app::SetpointProfile profile = app::ClosedLoopProfile();
  app::EcsTask task(rig.driver, profile, app::DefaultEcsGains(), rig.geometry, kPeriodNs);
  return TaskCycleNs(task, rig, calls, "closed loop");
}

Figure OpenLoopCycleNs(long calls) {
  EcsRig rig;
  const app::InputProfile profile = app::OpenLoopProfile();
  app::EcsTask task(rig.driver, profile, rig.geometry, kPeriodNs);
  return TaskCycleNs(task, rig, calls, "open loop");
}

/// The board exchange alone (what EcsTask::Exchange adds to the driver is one copy).
Figure ExchangeAloneNs(long calls) {
  EcsRig rig;
  io::EcsInputs in;
  std::uint64_t errors = rig.driver_ok ? 0 : 1;
  const Figure f = NsPerCall(
      [&](long i) {
        const auto pwm = static_cast<std::int32_t>(i % 2048);
        if (!rig.driver.Exchange({pwm, -pwm, 0, 0}, in).ok()) ++errors;
      },
      calls);
  g_sink = g_sink + static_cast<double>(in.absolute_counts[0]);
  if (errors != 0)
    std::printf("(exchange: %llu errors)\n", static_cast<unsigned long long>(errors));
  return f;
}

/// Measurements a wheel tracking its setpoint gives: the setpoint minus a few counts of noise.
std::vector<double> MeasuredSamples(const app::SetpointProfile& profile) {
  std::vector<double> samples(12'000);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    samples[k] =
        profile.At(static_cast<double>(k) * 1e-3).left_m - 1e-4 * static_cast<double>(k % 7);
  }
  return samples;
}

Figure PidAloneNs(long calls, const std::vector<double>& setpoint,
                  const std::vector<double>& measured) {
  app::PositionPid left(app::DefaultEcsGains(), 1e-3);
  app::PositionPid right(app::DefaultEcsGains(), 1e-3);
  const Figure f = NsPerCall(
      [&](long i) {
        const auto k = static_cast<std::size_t>(i % 12'000);
        g_sink =
            g_sink + left.Step(setpoint[k], measured[k]) + right.Step(setpoint[k], measured[k]);
      },
      calls);
  return f;
}

/// The textbook form: u = kp e + ki sum(e) T + kd (e - e_prev) / T, clamped; no filter, no
/// anti-windup, derivative on the error.
struct TextbookPid {
  double kp, ki_t, kd_over_t, integral = 0.0, previous_error = 0.0;
  double Step(double setpoint, double measured) noexcept {
    const double e = setpoint - measured;
    integral += ki_t * e;
    const double u = kp * e + integral + kd_over_t * (e - previous_error);
    previous_error = e;
    return std::clamp(u, -1.0, 1.0);
  }
};

Figure TextbookPidNs(long calls, const std::vector<double>& setpoint,
                     const std::vector<double>& measured) {
  const app::PidGains g = app::DefaultEcsGains();
  TextbookPid left{g.kp_duty_per_m, g.ki_duty_per_m_s * 1e-3, g.kd_duty_s_per_m / 1e-3};
  TextbookPid right = left;
  return NsPerCall(
      [&](long i) {
        const auto k = static_cast<std::size_t>(i % 12'000);
        g_sink =
            g_sink + left.Step(setpoint[k], measured[k]) + right.Step(setpoint[k], measured[k]);
      },
      calls);
}

}  // namespace

int main(int argc, char** argv) {
  const long calls = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 200'000L;
  if (calls <= 0) {
    std::fprintf(stderr, "usage: %s [cycles_per_run > 0]\n", argv[0]);
    return 2;
  }
  const app::SetpointProfile profile = app::ClosedLoopProfile();
  std::vector<double> setpoint(12'000);
  for (std::size_t k = 0; k < setpoint.size(); ++k)
    setpoint[k] = profile.At(static_cast<double>(k) * 1e-3).left_m;
  const std::vector<double> measured = MeasuredSamples(profile);

  (void)ClosedLoopCycleNs(calls / 4);  // warm-up: caches, branch predictors, CPU frequency
  const Figure closed = ClosedLoopCycleNs(calls);
  const Figure open = OpenLoopCycleNs(calls);
  const Figure exchange = ExchangeAloneNs(calls);
  const Figure pid = PidAloneNs(calls, setpoint, measured);
  const Figure textbook = TextbookPidNs(calls, setpoint, measured);

  std::printf("ecs cycle benchmark: %ld cycles x %d runs, thread CPU time, median (min) ns\n",
              calls, kRuns);
  std::printf("  ECS cycle, closed loop (exchange + step)   %7.1f  (%7.1f)\n", closed.median_ns,
              closed.min_ns);
  std::printf("  ECS cycle, open loop (exchange + step)     %7.1f  (%7.1f)\n", open.median_ns,
              open.min_ns);
  std::printf("  breakdown: IcoBoard::Exchange alone         %7.1f  (%7.1f)  step = the rest\n",
              exchange.median_ns, exchange.min_ns);
  std::printf("  peer: PositionPid::Step, both wheels       %7.1f  (%7.1f)\n", pid.median_ns,
              pid.min_ns);
  std::printf("  ratio closed-loop cycle / PID alone        %7.1f\n",
              closed.median_ns / pid.median_ns);
  std::printf(
      "  for context: textbook PID, both wheels     %7.1f  (%7.1f)  (no filter, no anti-windup)\n",
      textbook.median_ns, textbook.min_ns);
  std::printf("  share of a 1 ms ECS period                 %7.3f %%\n", closed.median_ns / 1e4);
  return 0;
}
