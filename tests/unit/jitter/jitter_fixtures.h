#pragma once
// Synthesized inputs for the jitter tests: a run's cycles as the executive (skip policy) would
// have timed them, and the kernel's events around them, with known answers.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>

#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace hiltwin::analysis::testing {

inline constexpr int kLoopPid = 999;
inline constexpr int kLoopTid = 1000;
inline constexpr int kLoopCpu = 1;
inline constexpr int kLoopKernelPrio = 19;  // SCHED_FIFO 80
inline constexpr std::int64_t kWakeToStartNs = 100;

/// One cycle's figures where the test wants them other than the run's pattern.
struct CycleOverride {
  std::int64_t latency_ns = 0;
  std::int64_t compute_ns = 0;
};

struct RunSpec {
  std::uint64_t releases = 10'000;
  std::int64_t period_ns = 50'000;
  std::int64_t deadline_ns = 50'000;
  std::int64_t t0_ns = 1'000'000'000;
  std::int64_t io_ns = 0;
  std::function<std::int64_t(std::uint64_t)> latency_ns = [](std::uint64_t) { return 3'000; };
  std::function<std::int64_t(std::uint64_t)> compute_ns = [](std::uint64_t) { return 20'000; };
  std::map<std::uint64_t, CycleOverride> overrides;
  std::set<std::uint64_t> unjudged;  ///< releases the QoS ledger did not count (paused)
  /// The catch-up policy instead of skip: every release runs; one that passed while its
  /// predecessor still ran wakes kCatchUpWakeNs after the predecessor's end (the sleep returns
  /// at once), whatever its latency says.
  bool catch_up = false;
};

inline constexpr std::int64_t kCatchUpWakeNs = 300;

/// The cycles the executive would have run under the skip policy (or catch-up, see RunSpec):
/// release on the grid, wake after the latency, start 100 ns later, end after compute + io;
/// releases passed during a long cycle are skipped.
TimingTrace MakeTrace(const RunSpec& spec);

/// Builds a KernelTrace event by event (sorted by time when finished).
class KernelScript {
 public:
  void Switch(std::int64_t t, int cpu, int prev_pid, const std::string& prev_comm, int prev_prio,
              std::int64_t prev_state, int next_pid, const std::string& next_comm, int next_prio);
  void Wakeup(std::int64_t t, int pid, const std::string& comm, int prio, int target_cpu);
  void Irq(std::int64_t begin, std::int64_t end, int cpu, int irq, const std::string& name);
  void LocalTimer(std::int64_t begin, std::int64_t end, int cpu);
  void Softirq(std::int64_t begin, std::int64_t end, int cpu, int vector, const std::string& name);
  void Fault(std::int64_t t, int cpu, int pid, std::uint64_t address);
  void Task(int pid, const std::string& comm, const std::string& policy, int rt_priority);

  // The loop thread's usual moves on its CPU.
  void LoopIn(std::int64_t t, int from_pid = 0, const std::string& from_comm = "swapper/1",
              int from_prio = 120, std::int64_t from_state = 0);
  void LoopOutToIdle(std::int64_t t);
  void LoopWakeup(std::int64_t t);

  [[nodiscard]] KernelTrace Finish();

 private:
  KernelEvent& Add(std::int64_t t, int cpu, KernelEventKind kind);
  KernelTrace trace_;
};

/// What the kernel does in an ordinary cycle: the timer interrupt, the wake-up, the switch in
/// from idle before `wake` (ArriveFromIdle), the switch out to idle after `end`.
void NormalCycle(KernelScript& script, const scheduler::TimingSample& s);
void ArriveFromIdle(KernelScript& script, const scheduler::TimingSample& s);

using SpecialCycle = std::function<void(KernelScript&, const scheduler::TimingSample&)>;

/// Kernel events for every cycle of `trace`: NormalCycle, or the special one given for its k.
/// Catch-up cycles (released before their predecessor's end) add no event: the loop runs on;
/// a cycle followed by one does not switch out to idle.
KernelTrace MakeKernel(const TimingTrace& trace, const std::map<std::uint64_t, SpecialCycle>& special);

/// A run with a known answer for every output: 4000 releases at 50 µs, two misses (k = 1000:
/// response 63.1 µs, an interrupt "eth0" held the CPU 40 µs; k = 3000: response 52.1 µs with
/// compute 49 µs, each skipping a release), one late wake-up (k = 2000, 25 µs, met); the
/// kernel recorded; an (3,4)-firm rule.
struct TracedRun {
  TimingTrace trace;
  KernelTrace kernel;
};
TracedRun MakeTracedRun();

/// A fresh directory under the system's temporary one, removed with its contents at the end.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

/// The whole file ("" when it cannot be read).
std::string ReadFile(const std::string& path);

/// `program`'s path as execvp finds it on PATH, or "" when it is not there.
std::string FindOnPath(const std::string& program);

}  // namespace hiltwin::analysis::testing
