// Lockstep speed (issue: lockstep). Three figures, each the median and range over rounds:
//
// 1. The whole `hiltwin hil --clock virtual --no-progress` command, the 12 s closed loop (48,000
//    twin and 12,000 ECS cycles in two processes on one virtual time base shared through the
//    wire): wall time from the start of the command to its exit, the speed-up against real time
//    (12 s / wall), and the part of it that is the loop (each side's run report, wall_time_s:
//    from the start of its loop to its end), the rest being start-up and shut-down. With
//    --openloop N, N rounds of the 600 s open loop as well (`--mode openloop --duration 600`).
// 2. The peer: the same closed loop in one process on one virtual timeline (tests/unit/app/
//    in_process_hil.h: both emulated boards joined in memory, the twin and the ECS stepped by
//    hand, no session, no wire), and the ratio lockstep / in-process. Rounds alternate between
//    the command and the peer, so both see the same machine.
// 3. The cost of one lockstep hand-over: two processes (this one, the twin, and a forked child,
//    the ECS), each owning one side of a fresh wire, each waiting on its lockstep clock for
//    interleaved times (ECS at odd ns, twin at even ns), so that every wait hands the turn to
//    the other side: wall / hand-overs, and how many waits went to the futex. Once on whatever
//    CPUs the scheduler gives (the spin path: each side spins up to 20 µs on its own CPU), once
//    with both processes pinned to one CPU (the futex path: the waiting side spins out its 20 µs,
//    then sleeps, and only then can the other run).
//
// Usage: hiltwin_bench_lockstep [--rounds N=5] [--handovers N=200000] [--pinned-handovers
//        N=20000] [--cpu C=0] [--openloop N=0]
//   --handovers / --pinned-handovers: timed waits per side (after 1,000 untimed ones)
//   --openloop N: N rounds of the 600 s open loop too (each ~15-30 s; off by default)
#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_stats.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "in_process_hil.h"

namespace {

using namespace hiltwin;
using bench::BenchClock;

constexpr double kClosedLoopS = 12.0;
constexpr double kOpenLoopS = 600.0;
constexpr long kWarmupWaits = 1'000;

struct Options {
  int rounds = 5;
  long handovers = 200'000;
  long pinned_handovers = 20'000;
  int cpu = 0;
  int openloop_rounds = 0;
};

std::optional<Options> ParseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 >= argc) break;
    const long value = std::strtol(argv[++i], nullptr, 10);
    if (flag == "--rounds" && value > 0) {
      o.rounds = static_cast<int>(value);
    } else if (flag == "--handovers" && value > 0) {
      o.handovers = value;
    } else if (flag == "--pinned-handovers" && value > 0) {
      o.pinned_handovers = value;
    } else if (flag == "--cpu" && value >= 0) {
      o.cpu = static_cast<int>(value);
    } else if (flag == "--openloop" && value >= 0) {
      o.openloop_rounds = static_cast<int>(value);
    } else {
      return std::nullopt;
    }
  }
  if (argc % 2 == 0) return std::nullopt;  // a flag without its value
  return o;
}

double Seconds(BenchClock::time_point start, BenchClock::time_point end) {
  return std::chrono::duration<double>(end - start).count();
}

/// Median and range of a figure over rounds.
struct Spread {
  double median = 0.0;
  double min = 0.0;
  double max = 0.0;
};

Spread SpreadOf(const std::vector<double>& values) {
  return {bench::Median(values), bench::MinOf(values),
          *std::max_element(values.begin(), values.end())};
}

// ---------------------------------------------------------------------------------------------
// 1. The whole command

struct CommandRun {
  double wall_s = 0.0;       ///< start of the command to its exit
  double cpu_s = 0.0;        ///< user + system time of hil and its two sides
  double twin_loop_s = 0.0;  ///< the twin's run report: wall_time_s
  double ecs_loop_s = 0.0;
  double max_error_m = 0.0;  ///< closed loop: the larger wheel's max |tracking error|
};

/// User + system time of the children waited for so far (hil waits for its two sides).
double ChildrenCpuS() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  const auto s = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return s(usage.ru_utime) + s(usage.ru_stime);
}

/// Runs `hiltwin hil --clock virtual --no-progress` + `extra`; exits the benchmark when the
/// command fails or its sides did not run the planned cycles.
CommandRun RunCommand(const std::vector<std::string>& extra, double length_s) {
  const std::filesystem::path report =
      std::filesystem::temp_directory_path() /
      ("hiltwin-bench-lockstep-" + std::to_string(::getpid()) + ".json");
  std::vector<std::string> argv = {HILTWIN_BINARY, "hil",      "--clock", "virtual",
                                   "--no-progress", "--report", report.string()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  kernel_glue::ProcessOptions streams;
  streams.out = kernel_glue::OutputTarget::Capture();
  streams.err = kernel_glue::OutputTarget::Capture();
  const double cpu_before_s = ChildrenCpuS();
  const BenchClock::time_point start = BenchClock::now();
  const kernel_glue::ProcessResult run = kernel_glue::RunProcess(argv, streams);
  const BenchClock::time_point end = BenchClock::now();
  const double cpu_s = ChildrenCpuS() - cpu_before_s;
  if (!run.status.Success()) {
    std::fprintf(stderr, "hiltwin hil failed (%s):\n%s%s", run.status.Describe().c_str(),
                 run.out.c_str(), run.err.c_str());
    std::exit(1);
  }
  std::ifstream in(report);
  const nlohmann::json json = nlohmann::json::parse(in);
  in.close();
  std::filesystem::remove(report);
  const auto twin_cycles = json["twin"]["cycles_run"].get<std::uint64_t>();
  const auto ecs_cycles = json["ecs"]["cycles_run"].get<std::uint64_t>();
  const auto want_ecs = static_cast<std::uint64_t>(length_s * 1000.0);
  if (ecs_cycles != want_ecs || twin_cycles != 4 * want_ecs) {
    std::fprintf(stderr, "hiltwin hil ran %llu twin and %llu ECS cycles, not %llu and %llu\n",
                 static_cast<unsigned long long>(twin_cycles),
                 static_cast<unsigned long long>(ecs_cycles),
                 static_cast<unsigned long long>(4 * want_ecs),
                 static_cast<unsigned long long>(want_ecs));
    std::exit(1);
  }
  CommandRun r;
  r.wall_s = Seconds(start, end);
  r.cpu_s = cpu_s;
  r.twin_loop_s = json["twin"]["wall_time_s"].get<double>();
  r.ecs_loop_s = json["ecs"]["wall_time_s"].get<double>();
  if (json.contains("tracking_error_max_m")) {
    r.max_error_m = std::max(json["tracking_error_max_m"]["left"].get<double>(),
                             json["tracking_error_max_m"]["right"].get<double>());
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// 2. The peer: the in-process loop

struct InProcessRun {
  double wall_s = 0.0;
  double max_error_m = 0.0;
};

InProcessRun RunInProcessLoop(bool closed_loop, double length_s) {
  static const app::SetpointProfile setpoints = app::ClosedLoopProfile();
  static const app::InputProfile duties = app::OpenLoopProfile();
  app::test::HilConfig config;  // ECS 1 kHz, twin 4 kHz: hil's defaults
  if (closed_loop) {
    config.gains = app::DefaultEcsGains();
    config.setpoints = &setpoints;
  } else {
    config.duty_profile = &duties;
  }
  config.duration_s = length_s;
  app::test::InProcessHil rig(config);
  const BenchClock::time_point start = BenchClock::now();
  app::test::RunInProcess(rig);
  const BenchClock::time_point end = BenchClock::now();
  const app::test::HilObservations seen = rig.observations();
  const auto want_ecs = static_cast<std::uint64_t>(length_s * 1000.0);
  if (seen.ecs_cycles != want_ecs || seen.twin_cycles != 4 * want_ecs || seen.link_errors != 0) {
    std::fprintf(stderr, "in-process loop: %llu twin and %llu ECS cycles, %llu link errors\n",
                 static_cast<unsigned long long>(seen.twin_cycles),
                 static_cast<unsigned long long>(seen.ecs_cycles),
                 static_cast<unsigned long long>(seen.link_errors));
    std::exit(1);
  }
  InProcessRun r;
  r.wall_s = Seconds(start, end);
  r.max_error_m = std::max(rig.ecs().tracking().max_abs_error_left_m,
                           rig.ecs().tracking().max_abs_error_right_m);
  return r;
}

// ---------------------------------------------------------------------------------------------
// 3. One hand-over

/// What one side measured over its timed waits (passed from the child through a pipe).
struct SideResult {
  double wall_ns = 0.0;  ///< from the end of its last untimed wait to the end of its last wait
  io::LockstepCounts counts{};  ///< over the timed waits
  char error[256] = {};
};

/// One side of the hand-over loop: attach, wait until the peer is up, then `n` timed waits
/// (after kWarmupWaits untimed) at interleaved times: the ECS at odd, the twin at even ns.
SideResult RunSide(const std::string& wire, bool ecs, long n) {
  SideResult r;
  try {
    io::WireBus bus(wire, ecs ? io::Image::kIcoboard : io::Image::kIcoboardInverse, {},
                    io::WireClock::kLockstep);
    const BenchClock::time_point give_up = BenchClock::now() + std::chrono::seconds(5);
    for (;;) {
      const io::BusStatus status = bus.Poll();
      if (status.result == io::BusResult::kOk) break;
      if (BenchClock::now() > give_up) {
        std::snprintf(r.error, sizeof r.error, "the peer never came up: %s", status.reason);
        return r;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    kernel_glue::Clock& clock = *bus.lockstep_clock();
    const std::int64_t offset = ecs ? 1 : 2;
    long i = 0;
    for (; i < kWarmupWaits; ++i) clock.SleepUntilNs(2 * i + offset);
    const io::LockstepCounts before = bus.lockstep_counts();
    const BenchClock::time_point start = BenchClock::now();
    for (; i < kWarmupWaits + n; ++i) clock.SleepUntilNs(2 * i + offset);
    const BenchClock::time_point end = BenchClock::now();
    const io::LockstepCounts after = bus.lockstep_counts();
    bus.AnnounceStop(io::StopCause::kFinished);  // releases the peer's last wait
    r.wall_ns = std::chrono::duration<double, std::nano>(end - start).count();
    r.counts.waits = after.waits - before.waits;
    r.counts.handovers = after.handovers - before.handovers;
    r.counts.sleeps = after.sleeps - before.sleeps;
  } catch (const std::exception& e) {
    std::snprintf(r.error, sizeof r.error, "%s", e.what());
  }
  return r;
}

struct HandoverRun {
  double ns_per_handover = 0.0;
  SideResult twin;
  SideResult ecs;
};

bool PinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

/// Forks the ECS side, runs the twin side here; both pinned to `cpu` when given.
HandoverRun RunHandovers(long n, std::optional<int> cpu) {
  const std::string wire = "bench-lockstep-" + std::to_string(::getpid());
  io::WireBus::Unlink(wire);
  cpu_set_t own{};
  sched_getaffinity(0, sizeof own, &own);
  if (cpu && !PinTo(*cpu)) {
    std::fprintf(stderr, "cannot pin to CPU %d: %s\n", *cpu, std::strerror(errno));
    std::exit(1);
  }
  int fds[2];
  if (pipe(fds) != 0) {
    std::perror("pipe");
    std::exit(1);
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child < 0) {
    std::perror("fork");
    std::exit(1);
  }
  if (child == 0) {  // the ECS: inherits the pinning
    close(fds[0]);
    const SideResult r = RunSide(wire, true, n);
    const ssize_t written = write(fds[1], &r, sizeof r);
    _exit(written == static_cast<ssize_t>(sizeof r) ? 0 : 1);
  }
  close(fds[1]);
  HandoverRun run;
  run.twin = RunSide(wire, false, n);
  std::size_t got = 0;
  auto* bytes = reinterpret_cast<char*>(&run.ecs);
  while (got < sizeof run.ecs) {
    const ssize_t r = read(fds[0], bytes + got, sizeof run.ecs - got);
    if (r <= 0) break;
    got += static_cast<std::size_t>(r);
  }
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  io::WireBus::Unlink(wire);
  sched_setaffinity(0, sizeof own, &own);
  if (got != sizeof run.ecs) std::snprintf(run.ecs.error, sizeof run.ecs.error, "no result");
  for (const SideResult* side : {&run.twin, &run.ecs}) {
    if (side->error[0] != '\0') {
      std::fprintf(stderr, "hand-over loop, %s side: %s\n", side == &run.twin ? "twin" : "ECS",
                   side->error);
      std::exit(1);
    }
  }
  // The twin's window runs from its wait at 2·W (ECS then twin take n turns each) to its wait
  // at 2·(W + n): 2·n hand-overs.
  run.ns_per_handover = run.twin.wall_ns / static_cast<double>(2 * n);
  return run;
}

// ---------------------------------------------------------------------------------------------

void PrintCommand(const char* label, const std::vector<CommandRun>& runs, double length_s) {
  std::vector<double> wall;
  std::vector<double> loop;
  std::vector<double> rest;
  std::vector<double> ecs_loop;
  std::vector<double> cpu;
  for (const CommandRun& r : runs) {
    cpu.push_back(r.cpu_s);
    wall.push_back(r.wall_s);
    loop.push_back(r.twin_loop_s);
    ecs_loop.push_back(r.ecs_loop_s);
    rest.push_back(r.wall_s - r.twin_loop_s);
  }
  const Spread w = SpreadOf(wall);
  const Spread l = SpreadOf(loop);
  const Spread e = SpreadOf(ecs_loop);
  const Spread s = SpreadOf(rest);
  const Spread c = SpreadOf(cpu);
  std::printf("  %s, whole command %8.3f s  (%.3f .. %.3f)  speed-up %.0fx real time (%.0f .. %.0f)\n",
              label, w.median, w.min, w.max, length_s / w.median, length_s / w.max,
              length_s / w.min);
  std::printf("    of it, the loop (twin report)   %8.3f s  (%.3f .. %.3f)  %.0f ns per ECS cycle; ECS report %.3f s\n",
              l.median, l.min, l.max, l.median * 1e9 / (length_s * 1000.0), e.median);
  std::printf("    start-up + shut-down            %8.3f s  (%.3f .. %.3f)\n", s.median, s.min,
              s.max);
  std::printf("    CPU time, user + sys, 3 processes %6.3f s  (%.3f .. %.3f)\n", c.median, c.min,
              c.max);
}

double PrintInProcess(const char* label, const std::vector<InProcessRun>& runs, double length_s) {
  std::vector<double> wall;
  for (const InProcessRun& r : runs) wall.push_back(r.wall_s);
  const Spread w = SpreadOf(wall);
  std::printf("  peer: %s, in-process %8.3f s  (%.3f .. %.3f)  speed-up %.0fx real time; %.0f ns per ECS cycle\n",
              label, w.median, w.min, w.max, length_s / w.median,
              w.median * 1e9 / (length_s * 1000.0));
  return w.median;
}

void PrintHandovers(const char* label, const std::vector<HandoverRun>& runs, long n) {
  std::vector<double> ns;
  for (const HandoverRun& r : runs) ns.push_back(r.ns_per_handover);
  const Spread s = SpreadOf(ns);
  // The counts of the median round.
  const auto median_run = std::find_if(runs.begin(), runs.end(), [&](const HandoverRun& r) {
    return r.ns_per_handover == s.median;
  });
  const HandoverRun& m = *median_run;
  std::printf("  %s %8.0f ns  (%.0f .. %.0f)\n", label, s.median, s.min, s.max);
  std::printf("    median round: %ld waits per side; hand-overs twin %llu, ECS %llu; futex sleeps twin %llu, ECS %llu\n",
              n, static_cast<unsigned long long>(m.twin.counts.handovers),
              static_cast<unsigned long long>(m.ecs.counts.handovers),
              static_cast<unsigned long long>(m.twin.counts.sleeps),
              static_cast<unsigned long long>(m.ecs.counts.sleeps));
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> parsed = ParseOptions(argc, argv);
  if (!parsed) {
    std::fprintf(stderr,
                 "usage: %s [--rounds N>0] [--handovers N>0] [--pinned-handovers N>0] [--cpu C] "
                 "[--openloop N]\n",
                 argv[0]);
    return 2;
  }
  const Options& o = *parsed;
  std::printf("lockstep benchmark: %d rounds, each the command then its peer; median (min .. max)\n",
              o.rounds);

  std::vector<CommandRun> closed;
  std::vector<InProcessRun> closed_peer;
  for (int r = 0; r < o.rounds; ++r) {
    closed.push_back(RunCommand({}, kClosedLoopS));
    closed_peer.push_back(RunInProcessLoop(true, kClosedLoopS));
  }
  std::printf("closed loop, 12 s (48,000 twin + 12,000 ECS cycles), `hiltwin hil --clock virtual --no-progress`\n");
  PrintCommand("lockstep", closed, kClosedLoopS);
  const double peer_s = PrintInProcess("closed loop", closed_peer, kClosedLoopS);
  std::vector<double> wall;
  std::vector<double> loop;
  for (const CommandRun& r : closed) {
    wall.push_back(r.wall_s);
    loop.push_back(r.twin_loop_s);
  }
  std::printf("  ratio lockstep / in-process: whole command %.1f, loop alone %.1f\n",
              bench::Median(wall) / peer_s, bench::Median(loop) / peer_s);
  std::printf("  same result: max |tracking error| lockstep %.6f mm, in-process %.6f mm\n",
              closed.front().max_error_m * 1e3, closed_peer.front().max_error_m * 1e3);

  if (o.openloop_rounds > 0) {
    std::vector<CommandRun> open;
    std::vector<InProcessRun> open_peer;
    for (int r = 0; r < o.openloop_rounds; ++r) {
      open.push_back(RunCommand({"--mode", "openloop", "--duration", "600"}, kOpenLoopS));
      open_peer.push_back(RunInProcessLoop(false, kOpenLoopS));
    }
    std::printf("open loop, 600 s (2,400,000 twin + 600,000 ECS cycles), `... --mode openloop --duration 600`, %d rounds\n",
                o.openloop_rounds);
    PrintCommand("lockstep", open, kOpenLoopS);
    const double open_peer_s = PrintInProcess("open loop", open_peer, kOpenLoopS);
    std::vector<double> open_wall;
    for (const CommandRun& r : open) open_wall.push_back(r.wall_s);
    std::printf("  ratio lockstep / in-process: whole command %.1f\n",
                bench::Median(open_wall) / open_peer_s);
  }

  std::vector<HandoverRun> free_runs;
  std::vector<HandoverRun> pinned_runs;
  for (int r = 0; r < o.rounds; ++r) {
    free_runs.push_back(RunHandovers(o.handovers, std::nullopt));
    pinned_runs.push_back(RunHandovers(o.pinned_handovers, o.cpu));
  }
  std::printf("one lockstep hand-over (two processes, interleaved waits: every wait hands the turn over)\n");
  PrintHandovers("not pinned (spin path)        ", free_runs, o.handovers);
  char pinned_label[64];
  std::snprintf(pinned_label, sizeof pinned_label, "both on CPU %d (futex path)     ", o.cpu);
  PrintHandovers(pinned_label, pinned_runs, o.pinned_handovers);
  std::printf("  the 12 s closed loop hands over twice per ECS cycle: 24,000 hand-overs, %.1f ms at the spin path's median\n",
              24'000.0 * bench::Median([&] {
                std::vector<double> ns;
                for (const HandoverRun& r : free_runs) ns.push_back(r.ns_per_handover);
                return ns;
              }()) * 1e-6);
  return 0;
}
