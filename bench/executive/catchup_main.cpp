// Catch-up cost per cycle on the real clock (issue 36, point 2): a step stalls for several
// periods, the executive then runs the releases that passed back to back, and the cost of one
// catch-up cycle is the time from one step's end to the next step's start (the executive's
// own timestamps: bookkeeping, observers, the loop and its clock reads; the steps are empty).
// Its peer is the same drain with the old path's system call put back: before issue 36 the
// loop entered clock_nanosleep for every release, passed or not, so the peer's observer sleeps
// until the next release whenever that release has already passed. Rounds alternate between
// the two, so both see the same machine; the figure is the median over rounds of each round's
// median, with the range of the round medians beside it.
// Usage: hiltwin_bench_catchup [--rounds N] [--rate HZ] [--stall-periods P] [--stalls S]
//                               [--priority FIFO_PRIORITY (0: none)]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "bench_stats.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/rt_setup.h"
#include "hiltwin/scheduler/executive.h"

namespace {

namespace sched = hiltwin::scheduler;
using hiltwin::kernel_glue::TimeNs;

constexpr std::uint64_t kCyclesPerStall = 200;  // a stall, its drain, then on-time cycles

struct Options {
  int rounds = 11;
  double rate_hz = 4000.0;
  int stall_periods = 20;
  int stalls = 5;
  int priority = 0;
};

/// Empty steps, but every kCyclesPerStall-th one spins for stall_periods and a half.
class StallingTask final : public sched::CyclicTask {
 public:
  StallingTask(hiltwin::kernel_glue::Clock& clock, TimeNs stall_ns)
      : clock_(clock), stall_ns_(stall_ns) {}
  sched::CycleAction Step(const sched::CycleContext& context) noexcept override {
    if (context.cycle % kCyclesPerStall == kCyclesPerStall / 2) clock_.SpendNs(stall_ns_);
    return sched::CycleAction::kContinue;
  }

 private:
  hiltwin::kernel_glue::Clock& clock_;
  TimeNs stall_ns_;
};

/// Records end(k) -> start(k+1) of every catch-up cycle k+1 (its release had passed when
/// cycle k ended). With `old_path`, also enters clock_nanosleep for a passed next release,
/// as the loop did before issue 36.
class DrainObserver final : public sched::CycleObserver {
 public:
  DrainObserver(hiltwin::kernel_glue::Clock& clock, TimeNs period_ns, bool old_path,
                std::size_t capacity)
      : clock_(clock), period_ns_(period_ns), old_path_(old_path) {
    gaps_ns.reserve(capacity);
  }
  sched::CycleAction OnCycle(const sched::TimingSample& s) noexcept override {
    if (has_previous_ && previous_end_ns_ > s.release_ns && gaps_ns.size() < gaps_ns.capacity()) {
      gaps_ns.push_back(static_cast<double>(s.start_ns - previous_end_ns_));
    }
    has_previous_ = true;
    previous_end_ns_ = s.end_ns;
    const TimeNs next_release_ns = s.release_ns + period_ns_;  // catch-up: the next release
    if (old_path_ && next_release_ns < s.end_ns) clock_.SleepUntilNs(next_release_ns);
    return sched::CycleAction::kContinue;
  }
  std::vector<double> gaps_ns;

 private:
  hiltwin::kernel_glue::Clock& clock_;
  TimeNs period_ns_;
  bool old_path_;
  bool has_previous_ = false;
  TimeNs previous_end_ns_ = 0;
};

/// One drain run; the median catch-up cost of its cycles, ns (0 when none caught up).
double RunDrain(const Options& o, bool old_path, std::size_t& catch_up_cycles) {
  hiltwin::kernel_glue::MonotonicClock clock;
  sched::ExecutiveConfig config;
  config.period_ns = hiltwin::kernel_glue::PeriodNsFromRateHz(o.rate_hz);
  config.max_cycles = kCyclesPerStall * static_cast<std::uint64_t>(o.stalls);
  config.overrun_policy = sched::OverrunPolicy::kCatchUp;
  sched::Executive executive(clock, config);
  const auto capacity =
      static_cast<std::size_t>(o.stalls) * static_cast<std::size_t>(o.stall_periods + 2);
  DrainObserver drain(clock, config.period_ns, old_path, capacity);
  executive.AddObserver(drain);
  StallingTask task(clock, config.period_ns * o.stall_periods + config.period_ns / 2);
  executive.Run(task);
  catch_up_cycles = drain.gaps_ns.size();
  return drain.gaps_ns.empty() ? 0.0 : hiltwin::bench::Median(drain.gaps_ns);
}

bool Parse(int argc, char** argv, Options& o) {
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--rounds") == 0) o.rounds = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--rate") == 0) o.rate_hz = std::atof(argv[i + 1]);
    else if (std::strcmp(argv[i], "--stall-periods") == 0) o.stall_periods = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--stalls") == 0) o.stalls = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--priority") == 0) o.priority = std::atoi(argv[i + 1]);
    else return false;
  }
  return argc % 2 == 1 && o.rounds > 0 && o.rate_hz >= 1.0 && o.rate_hz <= 50'000.0 &&
         o.stall_periods > 0 && o.stall_periods < static_cast<int>(kCyclesPerStall / 2) &&
         o.stalls > 0 && o.priority >= 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!Parse(argc, argv, o)) {
    std::fprintf(stderr,
                 "usage: %s [--rounds N] [--rate HZ] [--stall-periods P < %llu] [--stalls S] "
                 "[--priority FIFO (0: none)]\n",
                 argv[0], static_cast<unsigned long long>(kCyclesPerStall / 2));
    return 2;
  }
  // SCHED_FIFO with locked memory only when asked: the figure is meant outside a trace and
  // without privileges too.
  std::optional<hiltwin::kernel_glue::RtSession> session;
  if (o.priority > 0) {
    hiltwin::kernel_glue::RtSetupRequest request;
    request.fifo_priority = o.priority;
    session.emplace(hiltwin::kernel_glue::RtSession::Apply(request));
  }
  std::printf("catch-up drain: %.0f Hz, %d stalls of %d.5 periods per run, %d rounds; RT: %s\n",
              o.rate_hz, o.stalls, o.stall_periods, o.rounds,
              session ? hiltwin::kernel_glue::Summary(session->record()).c_str() : "none");
  std::vector<double> now_ns;
  std::vector<double> old_ns;
  std::size_t cycles_now = 0;
  std::size_t cycles_old = 0;
  for (int round = 0; round < o.rounds; ++round) {
    now_ns.push_back(RunDrain(o, false, cycles_now));
    old_ns.push_back(RunDrain(o, true, cycles_old));
  }
  const hiltwin::bench::Spread now = hiltwin::bench::SpreadOf(now_ns);
  const hiltwin::bench::Spread old = hiltwin::bench::SpreadOf(old_ns);
  std::printf("  catch-up cost per cycle, no sleep (now):          %s  [%zu cycles a round]\n",
              hiltwin::bench::FormatSpread(now, "ns").c_str(), cycles_now);
  std::printf("  same drain, clock_nanosleep on the passed release: %s  [%zu cycles a round]\n",
              hiltwin::bench::FormatSpread(old, "ns").c_str(), cycles_old);
  std::printf("  median ratio old/now %.1f; target <= 1000 ns per catch-up cycle: %s\n",
              now.median > 0.0 ? old.median / now.median : 0.0,
              now.median <= 1000.0 ? "met" : "NOT met");
  return 0;
}
