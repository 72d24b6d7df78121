#include "jitter_fixtures.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "hiltwin/qos/rules.h"

namespace hiltwin::analysis::testing {

TimingTrace MakeTrace(const RunSpec& spec) {
  TimingTrace trace;
  trace.source = TraceSource::kLttng;
  trace.path = "synthetic";
  trace.period_ns = spec.period_ns;
  trace.deadline_ns = spec.deadline_ns;
  trace.planned_cycles = spec.releases;
  trace.loop = LoopThread{kLoopTid, kLoopCpu, 1, 80};
  trace.pid = kLoopPid;
  trace.complete = true;
  std::uint64_t k = 0;
  std::int64_t previous_end_ns = 0;
  while (k < spec.releases) {
    std::int64_t latency = spec.latency_ns(k);
    std::int64_t compute = spec.compute_ns(k);
    if (const auto o = spec.overrides.find(k); o != spec.overrides.end()) {
      latency = o->second.latency_ns;
      compute = o->second.compute_ns;
    }
    scheduler::TimingSample s;
    s.cycle = k;
    s.release_ns = spec.t0_ns + static_cast<std::int64_t>(k) * spec.period_ns;
    s.wake_ns = s.release_ns + latency;
    if (spec.catch_up && k > 0 && previous_end_ns > s.release_ns) {
      s.wake_ns = previous_end_ns + kCatchUpWakeNs;
    }
    s.start_ns = s.wake_ns + kWakeToStartNs;
    s.io_ns = spec.io_ns;
    s.end_ns = s.start_ns + compute + spec.io_ns;
    s.missed = s.end_ns > s.release_ns + spec.deadline_ns;
    const auto first_not_passed =
        static_cast<std::uint64_t>((s.end_ns - spec.t0_ns + spec.period_ns - 1) / spec.period_ns);
    const std::uint64_t next =
        spec.catch_up ? k + 1
                      : std::min(std::max(first_not_passed, k + 1), std::max(spec.releases, k + 1));
    s.releases_skipped = static_cast<std::uint32_t>(next - k - 1);
    trace.cycles.push_back({s, spec.unjudged.count(k) == 0});
    previous_end_ns = s.end_ns;
    k = next;
  }
  return trace;
}

KernelEvent& KernelScript::Add(std::int64_t t, int cpu, KernelEventKind kind) {
  KernelEvent e;
  e.time_ns = t;
  e.cpu = cpu;
  e.kind = kind;
  trace_.events.push_back(e);
  return trace_.events.back();
}

void KernelScript::Switch(std::int64_t t, int cpu, int prev_pid, const std::string& prev_comm,
                          int prev_prio, std::int64_t prev_state, int next_pid,
                          const std::string& next_comm, int next_prio) {
  KernelEvent& e = Add(t, cpu, KernelEventKind::kSchedSwitch);
  e.pid = prev_pid;
  e.comm = prev_comm;
  e.prio = prev_prio;
  e.prev_state = prev_state;
  e.next_pid = next_pid;
  e.next_comm = next_comm;
  e.next_prio = next_prio;
}

void KernelScript::Wakeup(std::int64_t t, int pid, const std::string& comm, int prio,
                          int target_cpu) {
  KernelEvent& e = Add(t, target_cpu, KernelEventKind::kSchedWakeup);
  e.pid = pid;
  e.comm = comm;
  e.prio = prio;
  e.target_cpu = target_cpu;
}

void KernelScript::Irq(std::int64_t begin, std::int64_t end, int cpu, int irq,
                       const std::string& name) {
  KernelEvent& entry = Add(begin, cpu, KernelEventKind::kIrqEntry);
  entry.irq = irq;
  entry.name = name;
  Add(end, cpu, KernelEventKind::kIrqExit).irq = irq;
}

void KernelScript::LocalTimer(std::int64_t begin, std::int64_t end, int cpu) {
  Add(begin, cpu, KernelEventKind::kLocalTimerEntry);
  Add(end, cpu, KernelEventKind::kLocalTimerExit);
}

void KernelScript::Softirq(std::int64_t begin, std::int64_t end, int cpu, int vector,
                           const std::string& name) {
  KernelEvent& entry = Add(begin, cpu, KernelEventKind::kSoftirqEntry);
  entry.irq = vector;
  entry.name = name;
  KernelEvent& exit = Add(end, cpu, KernelEventKind::kSoftirqExit);
  exit.irq = vector;
  exit.name = name;
}

void KernelScript::Fault(std::int64_t t, int cpu, int pid, std::uint64_t address) {
  KernelEvent& e = Add(t, cpu, KernelEventKind::kPageFaultUser);
  e.pid = pid;
  e.comm = "hiltwin-loop";
  e.address = address;
}

void KernelScript::Task(int pid, const std::string& comm, const std::string& policy,
                        int rt_priority) {
  trace_.tasks.push_back({pid, comm, policy, rt_priority});
}

void KernelScript::LoopIn(std::int64_t t, int from_pid, const std::string& from_comm,
                          int from_prio, std::int64_t from_state) {
  Switch(t, kLoopCpu, from_pid, from_comm, from_prio, from_state, kLoopTid, "hiltwin-loop",
         kLoopKernelPrio);
}

void KernelScript::LoopOutToIdle(std::int64_t t) {
  Switch(t, kLoopCpu, kLoopTid, "hiltwin-loop", kLoopKernelPrio, 1, 0, "swapper/1", 120);
}

void KernelScript::LoopWakeup(std::int64_t t) {
  Wakeup(t, kLoopTid, "hiltwin-loop", kLoopKernelPrio, kLoopCpu);
}

KernelTrace KernelScript::Finish() {
  std::stable_sort(trace_.events.begin(), trace_.events.end(),
                   [](const KernelEvent& a, const KernelEvent& b) { return a.time_ns < b.time_ns; });
  trace_.cpus = {kLoopCpu};
  return trace_;
}

void ArriveFromIdle(KernelScript& script, const scheduler::TimingSample& s) {
  script.LocalTimer(s.wake_ns - 2'000, s.wake_ns - 1'200, kLoopCpu);
  script.LoopWakeup(s.wake_ns - 1'100);
  script.LoopIn(s.wake_ns - 500);
}

void NormalCycle(KernelScript& script, const scheduler::TimingSample& s) {
  ArriveFromIdle(script, s);
  script.LoopOutToIdle(s.end_ns + 500);
}

KernelTrace MakeKernel(const TimingTrace& trace, const std::map<std::uint64_t, SpecialCycle>& special) {
  KernelScript script;
  const std::vector<TracedCycle>& cycles = trace.cycles;
  for (std::size_t i = 0; i < cycles.size(); ++i) {
    const scheduler::TimingSample& s = cycles[i].sample;
    const auto it = special.find(s.cycle);
    if (it != special.end()) {
      it->second(script, s);
      continue;
    }
    const bool behind = i > 0 && cycles[i - 1].sample.end_ns > s.release_ns;
    const bool sleeps_after =
        i + 1 == cycles.size() || cycles[i + 1].sample.release_ns >= s.end_ns;
    if (!behind) ArriveFromIdle(script, s);
    if (sleeps_after) script.LoopOutToIdle(s.end_ns + 500);
  }
  return script.Finish();
}

TracedRun MakeTracedRun() {
  RunSpec spec;
  spec.releases = 4'000;
  spec.latency_ns = [](std::uint64_t k) { return 3'000 + static_cast<std::int64_t>(k % 5) * 100; };
  spec.overrides[1000] = {3'000, 60'000};  // miss, one release skipped
  spec.overrides[2000] = {25'000, 20'000};  // late wake-up, still met (45.1 µs)
  spec.overrides[3000] = {3'000, 49'000};  // miss (response 52.1 µs), one release skipped
  TracedRun run{MakeTrace(spec), {}};
  run.trace.rules = {qos::MakeMkRule(3, 4)};
  std::map<std::uint64_t, SpecialCycle> special;
  special[1000] = [](KernelScript& k, const scheduler::TimingSample& s) {
    NormalCycle(k, s);
    k.Irq(s.start_ns + 1'000, s.start_ns + 41'000, kLoopCpu, 42, "eth0");
  };
  run.kernel = MakeKernel(run.trace, special);
  return run;
}

TempDir::TempDir() {
  std::string pattern =
      (std::filesystem::temp_directory_path() / "hiltwin-jitter-test-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string FindOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");  // NOLINT(concurrency-mt-unsafe): test set-up
  const std::string dirs = path != nullptr ? path : "";
  std::size_t begin = 0;
  while (begin <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', begin), dirs.size());
    std::string candidate = dirs.substr(begin, end - begin) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    begin = end + 1;
  }
  return "";
}

}  // namespace hiltwin::analysis::testing
