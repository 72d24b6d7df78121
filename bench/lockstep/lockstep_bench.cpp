// Lockstep speed (issue: lockstep). Three figures, each the median and range over rounds:
//
// 1. The whole `hiltwin hil --clock virtual --no-progress` command, the 12 s closed loop (48,000
//    twin and 12,000 ECS cycles in two processes on one virtual time base shared through the
//    wire): wall time from the start of the command to its exit, the speed-up against real time
//    (12 s / wall), the part of it that is the loop (the twin's run report, wall_time_s: from
//    the start of its loop to its end; the rest is start-up and shut-down), the CPU time and
//    the voluntary context switches of the three processes (in lockstep nearly all of them futex
//    sleeps). As it comes, and with all three processes on one CPU (what a loaded machine makes
//    of it when the scheduler puts both sides on the same CPU). With --openloop N, N rounds of
//    the 600 s open loop as well.
// 2. The peer: the same loop in one process on one virtual timeline (tests/unit/app/
//    in_process_hil.h: both emulated boards joined in memory, the twin and the ECS stepped by
//    hand, no session, no wire), and the ratio lockstep / in-process. Rounds run every variant
//    and the peer in turn, so all see the same machine.
// 3. The cost of one lockstep hand-over: two processes (this one, the twin, and a forked child,
//    the ECS), each owning one side of a fresh wire, each waiting on its lockstep clock for
//    interleaved times (ECS at odd ns, twin at even ns), so that every wait hands the turn to
//    the other side: wall / hand-overs, and how many hand-overs went to the futex. Not pinned,
//    pinned apart (the spin path: the waiting side spins on its own CPU and sees the turn
//    come), and both on one CPU (the futex path: the waiting side spins out its 20 µs while the
//    other cannot run, then sleeps).
//
// Usage: hiltwin_bench_lockstep [--rounds N=5] [--handovers N=20000] [--cpu C=0]
//                               [--openloop N=0] [--part all|command|handover]
//   --handovers: timed waits per side and round (after 1,000 untimed ones)
//   --cpu: the CPU of the pinned variants (pinned apart: C and C + 1)
//   --openloop N: N rounds of the 600 s open loop too, not pinned (~10 s each on an idle
//                 machine; off by default)
//   --part: the commands (and the peer) only, or the hand-over only
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
/// Hand-over loop: a heartbeat every this many waits (at most ~60 ms apart on one CPU, well
/// inside the wire's 250 ms heartbeat timeout).
constexpr long kPollEvery = 1'000;

struct Options {
  int rounds = 5;
  long handovers = 20'000;
  int cpu = 0;
  int openloop_rounds = 0;
  bool command = true;   ///< --part command|handover|all
  bool handover = true;
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
    } else if (flag == "--cpu" && value >= 0) {
      o.cpu = static_cast<int>(value);
    } else if (flag == "--openloop" && value >= 0) {
      o.openloop_rounds = static_cast<int>(value);
    } else if (flag == "--part" && (std::string(argv[i]) == "command" ||
                                    std::string(argv[i]) == "handover" ||
                                    std::string(argv[i]) == "all")) {
      o.command = std::string(argv[i]) != "handover";
      o.handover = std::string(argv[i]) != "command";
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

/// This process (and the children it starts from now on) on `cpu` alone.
bool PinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

// ---------------------------------------------------------------------------------------------
// 1. The whole command

struct CommandRun {
  double wall_s = 0.0;       ///< start of the command to its exit
  double cpu_s = 0.0;        ///< user + system time of hil and its two sides
  long sleeps = 0;           ///< their voluntary context switches
  double twin_loop_s = 0.0;  ///< the twin's run report: wall_time_s
  double ecs_loop_s = 0.0;
  double max_error_m = 0.0;  ///< closed loop: the larger wheel's max |tracking error|
};

/// What the children waited for so far used (hil waits for its two sides).
struct ChildrenUsage {
  double cpu_s = 0.0;          ///< user + system
  long voluntary_switches = 0;  ///< sleeps: in lockstep, almost all of them on the futex
};

ChildrenUsage ChildrenUsageNow() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  const auto s = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return {s(usage.ru_utime) + s(usage.ru_stime), usage.ru_nvcsw};
}

/// Runs `hiltwin hil --clock virtual --no-progress` + `extra`; exits the benchmark when the
/// command fails or its sides did not run the planned cycles.
CommandRun RunCommand(const std::vector<std::string>& extra, double length_s,
                      std::optional<int> cpu) {
  const std::filesystem::path report =
      std::filesystem::temp_directory_path() /
      ("hiltwin-bench-lockstep-" + std::to_string(::getpid()) + ".json");
  std::vector<std::string> argv = {HILTWIN_BINARY, "hil",      "--clock", "virtual",
                                   "--no-progress", "--report", report.string()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  kernel_glue::ProcessOptions streams;
  streams.out = kernel_glue::OutputTarget::Capture();
  streams.err = kernel_glue::OutputTarget::Capture();
  cpu_set_t own{};
  sched_getaffinity(0, sizeof own, &own);
  if (cpu && !PinTo(*cpu)) {
    std::fprintf(stderr, "cannot pin to CPU %d: %s\n", *cpu, std::strerror(errno));
    std::exit(1);
  }
  const ChildrenUsage before = ChildrenUsageNow();
  const BenchClock::time_point start = BenchClock::now();
  const kernel_glue::ProcessResult run = kernel_glue::RunProcess(argv, streams);
  const BenchClock::time_point end = BenchClock::now();
  const ChildrenUsage after = ChildrenUsageNow();
  sched_setaffinity(0, sizeof own, &own);
  if (!run.status.Success()) {
    std::filesystem::remove(report);
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
  const std::uint64_t want_twin = 4 * want_ecs;  // hil's defaults: twin 4 kHz, ECS 1 kHz
  if (ecs_cycles != want_ecs || twin_cycles != want_twin) {
    std::fprintf(stderr, "hiltwin hil ran %llu twin and %llu ECS cycles, not %llu and %llu\n",
                 static_cast<unsigned long long>(twin_cycles),
                 static_cast<unsigned long long>(ecs_cycles),
                 static_cast<unsigned long long>(want_twin),
                 static_cast<unsigned long long>(want_ecs));
    std::exit(1);
  }
  CommandRun r;
  r.wall_s = Seconds(start, end);
  r.cpu_s = after.cpu_s - before.cpu_s;
  r.sleeps = after.voluntary_switches - before.voluntary_switches;
  r.twin_loop_s = json["twin"]["wall_time_s"].get<double>();
  r.ecs_loop_s = json["ecs"]["wall_time_s"].get<double>();
  if (json.contains("tracking_error_max_m") && json["tracking_error_max_m"].is_object()) {
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
  int cpu_at_end = -1;          ///< the CPU it ran on after its last wait
  long involuntary_switches = 0;  ///< over the timed waits: preempted while it spun or ran
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
    for (; i < kWarmupWaits; ++i) {
      clock.SleepUntilNs(2 * i + offset);
      if (i % kPollEvery == 0) static_cast<void>(bus.Poll());
    }
    const io::LockstepCounts before = bus.lockstep_counts();
    rusage usage_before{};
    getrusage(RUSAGE_SELF, &usage_before);
    const BenchClock::time_point start = BenchClock::now();
    for (; i < kWarmupWaits + n; ++i) {
      clock.SleepUntilNs(2 * i + offset);
      // Waits alone do not beat: keep this side's heartbeat fresh for the peer's checks, as an
      // exchange every cycle does in a run (one Poll, ~1 us, per kPollEvery waits).
      if (i % kPollEvery == 0) {
        const io::BusStatus status = bus.Poll();
        if (status.result != io::BusResult::kOk) {
          std::snprintf(r.error, sizeof r.error, "the lockstep broke: %s", status.reason);
          return r;
        }
      }
    }
    const BenchClock::time_point end = BenchClock::now();
    const io::LockstepCounts after = bus.lockstep_counts();
    rusage usage_after{};
    getrusage(RUSAGE_SELF, &usage_after);
    r.cpu_at_end = sched_getcpu();
    r.involuntary_switches = usage_after.ru_nivcsw - usage_before.ru_nivcsw;
    // A broken lockstep returns every wait at once: a fast figure that measured nothing.
    const io::BusStatus status = bus.Poll();
    if (status.result != io::BusResult::kOk && status.result != io::BusResult::kPeerStopped) {
      std::snprintf(r.error, sizeof r.error, "the lockstep broke: %s", status.reason);
    }
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

/// Forks the ECS side, runs the twin side here; each pinned to its CPU when given.
HandoverRun RunHandovers(long n, std::optional<int> twin_cpu, std::optional<int> ecs_cpu) {
  const std::string wire = "bench-lockstep-" + std::to_string(::getpid());
  io::WireBus::Unlink(wire);
  cpu_set_t own{};
  sched_getaffinity(0, sizeof own, &own);
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
  if (child == 0) {  // the ECS
    close(fds[0]);
    SideResult r;
    if (ecs_cpu && !PinTo(*ecs_cpu)) {
      std::snprintf(r.error, sizeof r.error, "cannot pin to CPU %d: %s", *ecs_cpu,
                    std::strerror(errno));
    } else {
      r = RunSide(wire, true, n);
    }
    const ssize_t written = write(fds[1], &r, sizeof r);
    _exit(written == static_cast<ssize_t>(sizeof r) ? 0 : 1);
  }
  close(fds[1]);
  HandoverRun run;
  if (twin_cpu && !PinTo(*twin_cpu)) {
    std::snprintf(run.twin.error, sizeof run.twin.error, "cannot pin to CPU %d: %s", *twin_cpu,
                  std::strerror(errno));
  } else {
    run.twin = RunSide(wire, false, n);
  }
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

/// Prints the command's figures; returns the median wall time of the whole command.
double PrintCommand(const char* label, const std::vector<CommandRun>& runs, double length_s) {
  std::vector<double> wall;
  std::vector<double> loop;
  std::vector<double> rest;
  std::vector<double> cpu;
  std::vector<double> sleeps;
  for (const CommandRun& r : runs) {
    sleeps.push_back(static_cast<double>(r.sleeps));
    wall.push_back(r.wall_s);
    loop.push_back(r.twin_loop_s);
    rest.push_back(r.wall_s - r.twin_loop_s);
    cpu.push_back(r.cpu_s);
  }
  const Spread w = SpreadOf(wall);
  const Spread l = SpreadOf(loop);
  const Spread s = SpreadOf(rest);
  const Spread c = SpreadOf(cpu);
  const Spread z = SpreadOf(sleeps);
  std::printf("  %-40s %8.3f s  (%.3f .. %.3f)  %.0fx real time (%.0f .. %.0f)\n", label,
              w.median, w.min, w.max, length_s / w.median, length_s / w.max, length_s / w.min);
  std::printf("    loop (twin's report)        %8.3f s  (%.3f .. %.3f)  %.1f us per ECS cycle\n",
              l.median, l.min, l.max, l.median * 1e6 / (length_s * 1000.0));
  std::printf("    start-up + shut-down        %8.3f s  (%.3f .. %.3f)\n", s.median, s.min, s.max);
  std::printf("    CPU time, 3 processes       %8.3f s  (%.3f .. %.3f)  user + sys\n", c.median,
              c.min, c.max);
  std::printf("    sleeps, 3 processes         %8.0f    (%.0f .. %.0f)  "
              "voluntary context switches, %.2f per ECS cycle\n",
              z.median, z.min, z.max, z.median / (length_s * 1000.0));
  std::printf("    rounds, whole command, s   ");
  for (const double v : wall) std::printf(" %.3f", v);
  std::printf("\n");
  return w.median;
}

/// Prints the peer's figures; returns its median wall time.
double PrintInProcess(const std::vector<InProcessRun>& runs, double length_s) {
  std::vector<double> wall;
  for (const InProcessRun& r : runs) wall.push_back(r.wall_s);
  const Spread w = SpreadOf(wall);
  std::printf("  %-40s %8.3f s  (%.3f .. %.3f)  %.0fx real time; %.1f us per ECS cycle\n",
              "peer: in-process loop (RunInProcess)", w.median, w.min, w.max,
              length_s / w.median, w.median * 1e6 / (length_s * 1000.0));
  return w.median;
}

/// The median and range of ns per hand-over, then every round: ns, the share of hand-overs
/// that went to the futex, the CPUs the sides ended on and how often they were preempted.
double PrintHandovers(const char* label, const std::vector<HandoverRun>& runs, long n) {
  std::vector<double> ns;
  for (const HandoverRun& r : runs) ns.push_back(r.ns_per_handover);
  const Spread s = SpreadOf(ns);
  std::printf("  %-40s %8.0f ns  (%.0f .. %.0f)  %ld waits per side and round\n", label,
              s.median, s.min, s.max, n);
  std::printf("    rounds: ns (futex sleeps / hand-overs; CPU twin/ECS "
              "at the end; preempted twin/ECS)\n     ");
  for (const HandoverRun& r : runs) {
    const std::uint64_t handovers = r.twin.counts.handovers + r.ecs.counts.handovers;
    const std::uint64_t sleeps = r.twin.counts.sleeps + r.ecs.counts.sleeps;
    std::printf(" %.0f (%.2f; %d/%d; %ld/%ld)", r.ns_per_handover,
                handovers == 0 ? 0.0 : static_cast<double>(sleeps) / static_cast<double>(handovers),
                r.twin.cpu_at_end, r.ecs.cpu_at_end, r.twin.involuntary_switches,
                r.ecs.involuntary_switches);
  }
  std::printf("\n");
  return s.median;
}

/// One way to run the command: as it comes, or with all three processes on one CPU (as
/// `taskset -c C`: the children inherit this process's affinity; every hand-over then goes
/// through the futex, as on a loaded machine when the scheduler puts both sides on the same
/// CPU). The sides' own --cpu does not pin the loop on the virtual clock (no real-time set-up
/// there), hence the affinity.
struct Variant {
  std::string label;
  std::optional<int> cpu;  ///< the CPU of all three processes, or the scheduler's choice
};

/// Rounds of the first `variant_count` variants of the command and the in-process peer, in
/// turn; prints them and returns the peer's median wall time.
double CompareWithPeer(const char* what, const std::vector<std::string>& mode, double length_s,
                       bool closed_loop, int rounds, const std::vector<Variant>& variants,
                       std::size_t variant_count) {
  std::vector<std::vector<CommandRun>> runs(variant_count);
  std::vector<InProcessRun> peer;
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t v = 0; v < variant_count; ++v) {
      runs[v].push_back(RunCommand(mode, length_s, variants[v].cpu));
    }
    peer.push_back(RunInProcessLoop(closed_loop, length_s));
  }
  std::printf("%s, %d rounds\n", what, rounds);
  std::vector<double> medians;
  for (std::size_t v = 0; v < variant_count; ++v) {
    medians.push_back(PrintCommand(variants[v].label.c_str(), runs[v], length_s));
  }
  const double peer_s = PrintInProcess(peer, length_s);
  std::printf("  ratio lockstep / in-process (whole "
              "command): %.1f not pinned", medians[0] / peer_s);
  if (variant_count > 1) std::printf(", %.1f on one CPU", medians[1] / peer_s);
  std::printf("\n");
  if (closed_loop) {
    std::printf("  same result: max |tracking error| lockstep %.6f mm, in-process %.6f mm\n",
                runs[0].front().max_error_m * 1e3, peer.front().max_error_m * 1e3);
  }
  return peer_s;
}

/// Rounds of the hand-over loop not pinned, pinned apart and on one CPU, in turn; prints them
/// beside the in-process loop's cost per ECS cycle (`peer_s`, 0: not measured).
void CompareHandovers(const Options& o, int other_cpu, double peer_s) {
  std::vector<HandoverRun> free_runs;
  std::vector<HandoverRun> apart_runs;
  std::vector<HandoverRun> same_runs;
  for (int r = 0; r < o.rounds; ++r) {
    free_runs.push_back(RunHandovers(o.handovers, std::nullopt, std::nullopt));
    apart_runs.push_back(RunHandovers(o.handovers, o.cpu, other_cpu));
    same_runs.push_back(RunHandovers(o.handovers, o.cpu, o.cpu));
  }
  std::printf("one lockstep hand-over: two processes, interleaved "
              "waits (every wait hands the turn over)\n");
  char label[64];
  const double free_ns = PrintHandovers("not pinned", free_runs, o.handovers);
  std::snprintf(label, sizeof label, "pinned apart, CPUs %d and %d", o.cpu, other_cpu);
  const double apart_ns = PrintHandovers(label, apart_runs, o.handovers);
  std::snprintf(label, sizeof label, "both on CPU %d", o.cpu);
  const double same_ns = PrintHandovers(label, same_runs, o.handovers);
  std::printf("  the 12 s closed loop hands the turn over twice per "
              "ECS cycle, 24,000 times: %.0f ms "
              "not pinned, %.0f ms apart, %.0f ms on one CPU\n",
              24'000.0 * free_ns * 1e-6, 24'000.0 * apart_ns * 1e-6, 24'000.0 * same_ns * 1e-6);
  if (peer_s > 0.0) {
    std::printf("  for scale: the in-process closed loop spends %.0f "
                "ns per ECS cycle on all of its work\n",
                peer_s * 1e9 / (kClosedLoopS * 1000.0));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> parsed = ParseOptions(argc, argv);
  if (!parsed) {
    std::fprintf(stderr,
                 "usage: %s [--rounds N>0] [--handovers N>0] [--cpu C] "
                 "[--openloop N] [--part all|command|handover]\n",
                 argv[0]);
    return 2;
  }
  const Options& o = *parsed;
  std::printf("lockstep benchmark: %d rounds, each runs every variant, "
              "then the peer; median (min .. max)\n",
              o.rounds);
  const int other_cpu =
      (o.cpu + 1) % std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  const std::vector<Variant> variants = {
      {"lockstep, not pinned", std::nullopt},
      {"lockstep, all on CPU " + std::to_string(o.cpu) + " (taskset)", o.cpu}};
  double closed_peer_s = 0.0;
  if (o.command) {
    closed_peer_s = CompareWithPeer(
        "closed loop, 12 s (48,000 twin + 12,000 ECS cycles): `hiltwin hil --clock virtual "
        "--no-progress`",
        {}, kClosedLoopS, true, o.rounds, variants, variants.size());
  }
  if (o.openloop_rounds > 0) {
    // Not pinned only: on one CPU it would hold a CPU for ~40 s per round.
    CompareWithPeer("open loop, 600 s (2,400,000 twin + 600,000 ECS cycles): `... --mode openloop "
                    "--duration 600`",
                    {"--mode", "openloop", "--duration", "600"}, kOpenLoopS, false,
                    o.openloop_rounds, variants, 1);
  }
  if (o.handover) CompareHandovers(o, other_cpu, closed_peer_s);
  return 0;
}
