#include "cause_attribution.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "jitter_format.h"

namespace hiltwin::analysis::detail {
namespace {

enum class LoopState : std::uint8_t { kRunning, kRunnable, kSleeping, kUnknown };
enum class IrqKind : std::uint8_t { kHard, kTimer, kSoft };

// Who held a CPU from begin to end (segments of one CPU are back to back).
struct RunSegment {
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  int pid = 0;
  int prio = 0;
  std::uint32_t comm = 0;  // interned
};

struct IrqSegment {
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  std::uint32_t name = 0;  // interned
  int irq = -1;
  IrqKind kind = IrqKind::kHard;
};

struct CpuIndex {
  bool seen = false;
  std::vector<RunSegment> runs;
  std::vector<IrqSegment> irqs;  // by begin
  std::int64_t longest_irq_ns = 0;
  std::vector<std::int64_t> event_times;  // every event on the CPU, for page-fault charges
};

// The loop thread's state from begin to end (back to back over the recording).
struct LoopSegment {
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  LoopState state = LoopState::kUnknown;
  int cpu = -1;
};

struct Fault {
  std::int64_t time_ns = 0;
  int cpu = 0;
  std::uint64_t address = 0;
};

std::int64_t Overlap(std::int64_t a0, std::int64_t a1, std::int64_t b0, std::int64_t b1) {
  return std::max<std::int64_t>(0, std::min(a1, b1) - std::max(a0, b0));
}

// Below this, an unexplained stall on an idle CPU may be a deep C-state's exit latency.
constexpr std::int64_t kShortStallNs = 100'000;

std::string SoftirqName(const KernelEvent& e) {
  static constexpr const char* kNames[] = {"HI",       "TIMER",   "NET_TX", "NET_RX",  "BLOCK",
                                           "IRQ_POLL", "TASKLET", "SCHED",  "HRTIMER", "RCU"};
  if (!e.name.empty()) return e.name;
  if (e.irq >= 0 && e.irq < 10) return kNames[e.irq];
  return "softirq " + std::to_string(e.irq);
}

}  // namespace

struct KernelIndex {
  int tid = 0;
  int home_cpu = -1;
  // The loop's kernel prio when it is real-time (99 - rt priority); -1 for SCHED_OTHER, which
  // outranks nothing: every thread may preempt it.
  int loop_kernel_prio = -1;
  std::string preemption_model;  // as recorded; "" when the recording does not say
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
  std::vector<int> recorded_cpus;  // as the recorder listed them; empty: those with events
  std::vector<std::string> names;
  std::vector<CpuIndex> cpus;  // by CPU number
  std::vector<LoopSegment> loop;
  std::vector<Fault> faults;
  std::unordered_map<int, KernelTask> tasks;
  std::uint64_t unmatched_interrupts = 0;
  std::uint64_t unrecorded_switches = 0;  // switches in that the kernel did not trace
  bool reordered = false;

  [[nodiscard]] bool Recorded(int cpu) const {
    if (cpu < 0) return false;
    if (!recorded_cpus.empty()) {
      return std::find(recorded_cpus.begin(), recorded_cpus.end(), cpu) != recorded_cpus.end();
    }
    return static_cast<std::size_t>(cpu) < cpus.size() && cpus[static_cast<std::size_t>(cpu)].seen;
  }
  [[nodiscard]] const CpuIndex* Cpu(int cpu) const {
    if (cpu < 0 || static_cast<std::size_t>(cpu) >= cpus.size()) return nullptr;
    return &cpus[static_cast<std::size_t>(cpu)];
  }
};

namespace {

struct OpenIrq {
  std::int64_t begin_ns = 0;
  std::uint32_t name = 0;
  int irq = -1;
  IrqKind kind = IrqKind::kHard;
};

struct CpuBuild {
  bool occupant_known = false;
  RunSegment occupant;  // open: end_ns not set yet
  std::vector<OpenIrq> open_irqs;
};

// One pass over the events, in time order, fills a KernelIndex.
class IndexBuilder {
 public:
  explicit IndexBuilder(KernelIndex& index) : ix_(index) {}
  void Add(const KernelEvent& e);
  void Finish();

 private:
  CpuIndex& Cpu(int cpu);
  CpuBuild& Build(int cpu) { return build_[static_cast<std::size_t>(cpu)]; }
  std::uint32_t Intern(const std::string& name);
  void OnSwitch(const KernelEvent& e);
  [[nodiscard]] RunSegment Reconstruct(CpuBuild& b, const KernelEvent& e);
  void OnWakeup(const KernelEvent& e);
  void OnIrqEntry(const KernelEvent& e, IrqKind kind);
  void OnIrqExit(const KernelEvent& e, IrqKind kind);
  void LoopTo(std::int64_t t, LoopState before, LoopState next, int cpu);
  void AssignLoopCpus();

  KernelIndex& ix_;
  std::vector<CpuBuild> build_;
  std::unordered_map<std::string, std::uint32_t> ids_;
  bool loop_started_ = false;
  LoopSegment loop_;
  std::unordered_map<int, std::int64_t> last_wakeup_ns_;  // by pid
};

CpuIndex& IndexBuilder::Cpu(int cpu) {
  const auto i = static_cast<std::size_t>(cpu);
  if (i >= ix_.cpus.size()) {
    ix_.cpus.resize(i + 1);
    build_.resize(i + 1);
  }
  return ix_.cpus[i];
}

std::uint32_t IndexBuilder::Intern(const std::string& name) {
  const auto [it, inserted] = ids_.try_emplace(name, static_cast<std::uint32_t>(ix_.names.size()));
  if (inserted) ix_.names.push_back(name);
  return it->second;
}

void IndexBuilder::Add(const KernelEvent& e) {
  if (e.cpu < 0) return;
  CpuIndex& cpu = Cpu(e.cpu);
  cpu.seen = true;
  cpu.event_times.push_back(e.time_ns);
  switch (e.kind) {
    case KernelEventKind::kSchedSwitch: OnSwitch(e); break;
    case KernelEventKind::kSchedWakeup: OnWakeup(e); break;
    case KernelEventKind::kIrqEntry: OnIrqEntry(e, IrqKind::kHard); break;
    case KernelEventKind::kIrqExit: OnIrqExit(e, IrqKind::kHard); break;
    case KernelEventKind::kLocalTimerEntry: OnIrqEntry(e, IrqKind::kTimer); break;
    case KernelEventKind::kLocalTimerExit: OnIrqExit(e, IrqKind::kTimer); break;
    case KernelEventKind::kSoftirqEntry: OnIrqEntry(e, IrqKind::kSoft); break;
    case KernelEventKind::kSoftirqExit: OnIrqExit(e, IrqKind::kSoft); break;
    case KernelEventKind::kPageFaultUser:
      if (e.pid == ix_.tid) ix_.faults.push_back({e.time_ns, e.cpu, e.address});
      break;
  }
}

void IndexBuilder::LoopTo(std::int64_t t, LoopState before, LoopState next, int cpu) {
  if (!loop_started_) {
    loop_ = {ix_.first_ns, 0, before, cpu};
    loop_started_ = true;
  }
  loop_.end_ns = t;
  if (loop_.end_ns > loop_.begin_ns) ix_.loop.push_back(loop_);
  loop_ = {t, 0, next, cpu};
}

// The segment a switch closes. Its prev is normally the occupant the last switch brought in;
// when it is not, a switch in went untraced. Seen on this project's VM: the kernel never
// records the switch out of CPU 1's idle task (it does on CPU 0), so a thread woken onto an
// idle CPU would seem never to run. Its run is rebuilt from its wake-up on this CPU (or, with
// none since the last switch, from that switch): the occupant until then, prev after.
RunSegment IndexBuilder::Reconstruct(CpuBuild& b, const KernelEvent& e) {
  if (!b.occupant_known) {  // before a CPU's first switch: prev has held it since the start
    return RunSegment{ix_.first_ns, 0, e.pid, e.prio, Intern(e.comm)};
  }
  if (b.occupant.pid == e.pid) return b.occupant;
  ++ix_.unrecorded_switches;
  std::int64_t start_ns = b.occupant.begin_ns;
  if (const auto it = last_wakeup_ns_.find(e.pid);
      it != last_wakeup_ns_.end() && it->second > start_ns && it->second < e.time_ns) {
    start_ns = it->second;
  }
  RunSegment before = b.occupant;
  before.end_ns = start_ns;
  if (before.end_ns > before.begin_ns) Cpu(e.cpu).runs.push_back(before);
  if (e.pid == ix_.tid && loop_started_ && loop_.state != LoopState::kRunning) {
    LoopTo(start_ns, loop_.state, LoopState::kRunning, e.cpu);
  }
  return RunSegment{start_ns, 0, e.pid, e.prio, Intern(e.comm)};
}

void IndexBuilder::OnSwitch(const KernelEvent& e) {
  CpuBuild& b = Build(e.cpu);
  RunSegment closing = Reconstruct(b, e);
  closing.end_ns = e.time_ns;
  if (closing.end_ns > closing.begin_ns) Cpu(e.cpu).runs.push_back(closing);
  b.occupant = RunSegment{e.time_ns, 0, e.next_pid, e.next_prio, Intern(e.next_comm)};
  b.occupant_known = true;
  if (e.pid == ix_.tid) {
    LoopTo(e.time_ns, LoopState::kRunning,
           e.prev_state == 0 ? LoopState::kRunnable : LoopState::kSleeping, e.cpu);
  }
  if (e.next_pid == ix_.tid) LoopTo(e.time_ns, LoopState::kUnknown, LoopState::kRunning, e.cpu);
}

void IndexBuilder::OnWakeup(const KernelEvent& e) {
  last_wakeup_ns_[e.pid] = e.time_ns;
  if (e.pid != ix_.tid) return;
  const int cpu = e.target_cpu >= 0 ? e.target_cpu : e.cpu;
  if (!loop_started_) {
    LoopTo(e.time_ns, LoopState::kSleeping, LoopState::kRunnable, cpu);
  } else if (loop_.state == LoopState::kSleeping || loop_.state == LoopState::kUnknown) {
    LoopTo(e.time_ns, loop_.state, LoopState::kRunnable, cpu);
  }
}

void IndexBuilder::OnIrqEntry(const KernelEvent& e, IrqKind kind) {
  std::string name;
  switch (kind) {
    case IrqKind::kHard: name = e.name.empty() ? "irq " + std::to_string(e.irq) : e.name; break;
    case IrqKind::kTimer: name = "local_timer"; break;
    case IrqKind::kSoft: name = SoftirqName(e); break;
  }
  Build(e.cpu).open_irqs.push_back({e.time_ns, Intern(name), e.irq, kind});
}

void IndexBuilder::OnIrqExit(const KernelEvent& e, IrqKind kind) {
  std::vector<OpenIrq>& open = Build(e.cpu).open_irqs;
  auto match = std::find_if(open.rbegin(), open.rend(), [&](const OpenIrq& o) {
    return o.kind == kind && (kind == IrqKind::kTimer || o.irq == e.irq);
  });
  if (match == open.rend()) {
    ++ix_.unmatched_interrupts;
    return;
  }
  const OpenIrq entry = *match;
  const auto matched = match.base() - 1;
  // Entries opened after it that never exited: dropped, counted.
  ix_.unmatched_interrupts += static_cast<std::uint64_t>(open.end() - matched - 1);
  open.erase(matched, open.end());
  if (e.time_ns < entry.begin_ns) return;
  CpuIndex& cpu = Cpu(e.cpu);
  cpu.irqs.push_back({entry.begin_ns, e.time_ns, entry.name, entry.irq, entry.kind});
  cpu.longest_irq_ns = std::max(cpu.longest_irq_ns, e.time_ns - entry.begin_ns);
}

void IndexBuilder::Finish() {
  for (std::size_t i = 0; i < build_.size(); ++i) {
    CpuBuild& b = build_[i];
    if (b.occupant_known && ix_.last_ns > b.occupant.begin_ns) {
      b.occupant.end_ns = ix_.last_ns;
      ix_.cpus[i].runs.push_back(b.occupant);
    }
    ix_.unmatched_interrupts += b.open_irqs.size();
    // Pushed at their exits, so a nested handler came first: order by entry.
    std::sort(ix_.cpus[i].irqs.begin(), ix_.cpus[i].irqs.end(),
              [](const IrqSegment& a, const IrqSegment& b2) { return a.begin_ns < b2.begin_ns; });
  }
  if (loop_started_) {
    loop_.end_ns = ix_.last_ns;
    if (loop_.end_ns > loop_.begin_ns) ix_.loop.push_back(loop_);
  } else if (ix_.last_ns > ix_.first_ns) {
    ix_.loop.push_back({ix_.first_ns, ix_.last_ns, LoopState::kUnknown, ix_.home_cpu});
  }
  AssignLoopCpus();
}

// A sleeping or unknown stretch belongs to the CPU the loop next ran on (where its wake-up
// took it); with no later run, to the loop's pin.
void IndexBuilder::AssignLoopCpus() {
  int next_cpu = -1;
  for (auto it = ix_.loop.rbegin(); it != ix_.loop.rend(); ++it) {
    if (it->state == LoopState::kRunning) {
      next_cpu = it->cpu;
    } else if (it->state == LoopState::kSleeping || it->state == LoopState::kUnknown) {
      if (next_cpu >= 0) {
        it->cpu = next_cpu;
      } else if (it->state == LoopState::kUnknown || it->cpu < 0) {
        it->cpu = ix_.home_cpu;
      }
    }
  }
}

// Event indices in time order (the recorder writes them so; a merge of per-CPU buffers that
// is slightly off is put right rather than misread).
std::vector<std::size_t> IndicesByTime(const std::vector<KernelEvent>& events, bool& reordered) {
  std::vector<std::size_t> order(events.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  reordered = !std::is_sorted(events.begin(), events.end(),
                              [](const KernelEvent& a, const KernelEvent& b) {
                                return a.time_ns < b.time_ns;
                              });
  if (reordered) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return events[a].time_ns < events[b].time_ns;
    });
  }
  return order;
}

}  // namespace

namespace {

struct ThreadTally {
  std::int64_t ns = 0;
  int prio = 0;
  std::uint32_t comm = 0;
  int cpu = -1;
};

struct IrqTally {
  std::int64_t ns = 0;
  int irq = -1;
  IrqKind kind = IrqKind::kHard;
  std::uint64_t runs = 0;
  int cpu = -1;
};

// What happened inside one window.
struct Tally {
  std::map<int, ThreadTally> threads;     // by pid
  std::map<std::uint32_t, IrqTally> irqs;  // by interned name
  std::int64_t idle_ns = 0;               // pid 0 held the CPU while the loop wanted it
  std::map<int, std::int64_t> demand_ns;  // per CPU: how long the loop wanted it
  std::int64_t in_step_ns = 0;            // of the explained time, inside the step
  std::uint64_t faults = 0;
  std::uint64_t first_address = 0;
  std::int64_t fault_ns = 0;
  int fault_cpu = -1;
  bool cpu_missing = false;  // the window needs a CPU the recording lacks (or none is known)
  int missing_cpu = -1;
};

// The attribution of one window against the index.
class WindowQuery {
 public:
  WindowQuery(const KernelIndex& ix, const CauseWindow& w) : ix_(ix), w_(w) {}
  Tally Collect();

 private:
  void AddRuns(int cpu, std::int64_t lo, std::int64_t hi, bool credit_threads);
  static std::int64_t IrqTime(const CpuIndex& cpu, std::int64_t a, std::int64_t b);
  void AddInterrupts(int cpu, std::int64_t lo, std::int64_t hi);
  void AddFaults();
  std::int64_t FaultCharge(const Fault& f) const;
  std::int64_t InStep(std::int64_t a, std::int64_t b) const {
    return Overlap(a, b, w_.step_begin_ns, w_.step_end_ns);
  }

  const KernelIndex& ix_;
  const CauseWindow& w_;
  Tally t_;
};

Tally WindowQuery::Collect() {
  const auto& loop = ix_.loop;
  auto it = std::partition_point(loop.begin(), loop.end(), [&](const LoopSegment& s) {
    return s.end_ns <= w_.begin_ns;
  });
  for (; it != loop.end() && it->begin_ns < w_.end_ns; ++it) {
    const std::int64_t lo = std::max(it->begin_ns, w_.begin_ns);
    const std::int64_t hi = std::min(it->end_ns, w_.end_ns);
    // The sleep the loop is in at the release is the wait for this release (a late wake-up
    // is part of the delay); a sleep begun inside the cycle is the step's own I/O wait.
    const bool waiting_for_release = it->state == LoopState::kSleeping && it->begin_ns < w_.begin_ns;
    if (lo >= hi || (it->state == LoopState::kSleeping && !waiting_for_release)) continue;
    if (!ix_.Recorded(it->cpu)) {
      t_.cpu_missing = true;
      t_.missing_cpu = it->cpu;
      continue;
    }
    t_.demand_ns[it->cpu] += hi - lo;
    AddInterrupts(it->cpu, lo, hi);
    if (it->state != LoopState::kRunning) {
      AddRuns(it->cpu, lo, hi, /*credit_threads=*/!waiting_for_release);
    }
  }
  AddFaults();
  return t_;
}

void WindowQuery::AddRuns(int cpu_number, std::int64_t lo, std::int64_t hi, bool credit_threads) {
  const CpuIndex* cpu = ix_.Cpu(cpu_number);
  if (cpu == nullptr) return;
  auto r = std::partition_point(cpu->runs.begin(), cpu->runs.end(),
                                [&](const RunSegment& s) { return s.end_ns <= lo; });
  for (; r != cpu->runs.end() && r->begin_ns < hi; ++r) {
    const std::int64_t a = std::max(r->begin_ns, lo);
    const std::int64_t b = std::min(r->end_ns, hi);
    if (b <= a || r->pid == ix_.tid) continue;
    // An interrupt taken while the thread was current held the CPU, not the thread: its time
    // is the interrupt's (AddInterrupts), never both.
    const std::int64_t ov = b - a - IrqTime(*cpu, a, b);
    if (r->pid == 0) {
      t_.idle_ns += ov;
      continue;
    }
    if (!credit_threads) continue;
    ThreadTally& th = t_.threads[r->pid];
    th.ns += ov;
    th.prio = r->prio;
    th.comm = r->comm;
    th.cpu = cpu_number;
    const std::int64_t step_a = std::max(a, w_.step_begin_ns);
    const std::int64_t step_b = std::min(b, w_.step_end_ns);
    if (step_b > step_a) t_.in_step_ns += step_b - step_a - IrqTime(*cpu, step_a, step_b);
  }
}

// How long interrupt handlers ran on `cpu` inside [a, b): nested ones counted once.
std::int64_t WindowQuery::IrqTime(const CpuIndex& cpu, std::int64_t a, std::int64_t b) {
  auto r = std::partition_point(cpu.irqs.begin(), cpu.irqs.end(), [&](const IrqSegment& s) {
    return s.begin_ns < a - cpu.longest_irq_ns;
  });
  std::int64_t covered_until = a;
  std::int64_t total = 0;
  for (; r != cpu.irqs.end() && r->begin_ns < b; ++r) {
    const std::int64_t from = std::max(r->begin_ns, covered_until);
    const std::int64_t to = std::min(r->end_ns, b);
    if (to <= from) continue;
    total += to - from;
    covered_until = to;
  }
  return total;
}

void WindowQuery::AddInterrupts(int cpu_number, std::int64_t lo, std::int64_t hi) {
  const CpuIndex* cpu = ix_.Cpu(cpu_number);
  if (cpu == nullptr) return;
  // Handlers are ordered by entry; one entered up to the longest handler's length before lo
  // may still be running at lo.
  auto r = std::partition_point(cpu->irqs.begin(), cpu->irqs.end(), [&](const IrqSegment& s) {
    return s.begin_ns < lo - cpu->longest_irq_ns;
  });
  for (; r != cpu->irqs.end() && r->begin_ns < hi; ++r) {
    const std::int64_t ov = Overlap(r->begin_ns, r->end_ns, lo, hi);
    if (ov <= 0) continue;
    IrqTally& x = t_.irqs[r->name];
    x.ns += ov;
    x.irq = r->irq;
    x.kind = r->kind;
    ++x.runs;
    x.cpu = cpu_number;
    t_.in_step_ns += InStep(std::max(r->begin_ns, lo), std::min(r->end_ns, hi));
  }
}

void WindowQuery::AddFaults() {
  auto f = std::partition_point(ix_.faults.begin(), ix_.faults.end(),
                                [&](const Fault& x) { return x.time_ns < w_.begin_ns; });
  for (; f != ix_.faults.end() && f->time_ns < w_.end_ns; ++f) {
    if (t_.faults == 0) {
      t_.first_address = f->address;
      t_.fault_cpu = f->cpu;
    }
    ++t_.faults;
    const std::int64_t charge = FaultCharge(*f);
    t_.fault_ns += charge;
    t_.in_step_ns += InStep(f->time_ns, f->time_ns + charge);
  }
}

// The time to the next event on the fault's CPU, at most kPageFaultChargeMaxNs; when that
// event is the loop blocking inside the window (a major fault), the time it stayed blocked.
std::int64_t WindowQuery::FaultCharge(const Fault& f) const {
  const CpuIndex* cpu = ix_.Cpu(f.cpu);
  std::int64_t next_ns = ix_.last_ns;
  if (cpu != nullptr) {
    const auto n = std::upper_bound(cpu->event_times.begin(), cpu->event_times.end(), f.time_ns);
    if (n != cpu->event_times.end()) next_ns = *n;
  }
  const std::int64_t until_ns = w_.end_ns;
  const auto& loop = ix_.loop;
  const auto seg = std::partition_point(loop.begin(), loop.end(), [&](const LoopSegment& s) {
    return s.begin_ns < next_ns;
  });
  if (seg != loop.end() && seg->begin_ns == next_ns && seg->begin_ns < until_ns &&
      seg->state == LoopState::kSleeping) {
    return std::max<std::int64_t>(0, std::min(seg->end_ns, until_ns) - f.time_ns);
  }
  return std::max<std::int64_t>(
      0, std::min({next_ns - f.time_ns, kPageFaultChargeMaxNs, until_ns - f.time_ns}));
}

}  // namespace

namespace {

// The candidate with the largest duration; an earlier candidate wins a tie.
struct Choice {
  CauseClass cause = CauseClass::kInvisible;
  std::int64_t ns = 0;
  int pid = 0;             // kPreempted
  std::uint32_t name = 0;  // kInterrupt
};

struct Decision {
  Choice best;
  std::int64_t own_ns = 0;
  std::int64_t invisible_ns = 0;
};

// Whether a thread that held the loop's CPU ranks below the loop (kernel prio: lower is
// higher; < 0 is SCHED_DEADLINE, 100 and above SCHED_OTHER). The scheduler would have
// preempted it for the loop at once, unless the kernel did not let it.
bool BelowTheLoop(const KernelIndex& ix, int prio) {
  return ix.loop_kernel_prio >= 0 && prio > ix.loop_kernel_prio;
}

Decision Decide(const KernelIndex& ix, const Tally& t, const CauseWindow& w) {
  Decision d;
  std::int64_t explained = 0;
  auto offer = [&](const Choice& c) {
    explained += c.ns;
    if (c.ns > d.best.ns) d.best = c;
  };
  for (const auto& [pid, th] : t.threads) {
    const CauseClass cls =
        BelowTheLoop(ix, th.prio) ? CauseClass::kNonPreemptible : CauseClass::kPreempted;
    offer({cls, th.ns, pid, 0});
  }
  for (const auto& [name, x] : t.irqs) offer({CauseClass::kInterrupt, x.ns, 0, name});
  if (t.faults > 0) offer({CauseClass::kPageFault, t.fault_ns, 0, 0});
  if (!w.wake_only && w.compute_ns > w.compute_p999_ns) {
    // What the step took beyond its median, less what events inside the step account for.
    d.own_ns = std::max<std::int64_t>(0, w.compute_ns - w.compute_p50_ns - t.in_step_ns);
    if (d.own_ns > 0) offer({CauseClass::kOwnCompute, d.own_ns, 0, 0});
  }
  d.invisible_ns = std::max<std::int64_t>(0, w.excess_ns - explained);
  const bool unexplained = 2 * explained < w.excess_ns || d.best.ns <= 0;
  if (unexplained && (d.best.ns <= 0 || d.invisible_ns > d.best.ns)) {
    d.best = {CauseClass::kInvisible, d.invisible_ns, 0, 0};
  }
  return d;
}

int BusiestCpu(const Tally& t, int fallback) {
  int cpu = fallback;
  std::int64_t most = -1;
  for (const auto& [c, ns] : t.demand_ns) {
    if (ns > most) {
      most = ns;
      cpu = c;
    }
  }
  return cpu;
}

std::string PolicyText(const std::string& policy, int priority) {
  if (policy == "SCHED_FIFO" || policy == "SCHED_RR" || policy == "SCHED_FIFO/RR") {
    return policy + " " + std::to_string(priority);
  }
  return policy;
}

void DescribePreemption(const KernelIndex& ix, const Choice& c, const Tally& t, Cause& out) {
  const ThreadTally& th = t.threads.at(c.pid);
  out.thread = ix.names[th.comm];
  out.pid = c.pid;
  out.cpu = th.cpu;
  const auto task = ix.tasks.find(c.pid);
  if (task != ix.tasks.end() && !task->second.policy.empty()) {
    out.policy = task->second.policy;
    out.priority = task->second.rt_priority;
  } else if (th.prio < 0) {
    out.policy = "SCHED_DEADLINE";
  } else if (th.prio < 100) {  // kernel prio 0..99 is real-time: rt priority 99 - prio
    out.policy = "SCHED_FIFO/RR";
    out.priority = 99 - th.prio;
  } else {
    out.policy = "SCHED_OTHER";
  }
  const std::string policy = PolicyText(out.policy, out.priority);
  const std::string who =
      out.thread + " (pid " + std::to_string(out.pid) + (policy.empty() ? "" : ", " + policy) + ")";
  if (c.cause == CauseClass::kPreempted) {
    out.evidence = "preempted by " + who + " for " + FormatDuration(c.ns);
    return;
  }
  const std::string model = ix.preemption_model.empty() || ix.preemption_model == "unknown"
                                ? "preemption model unknown"
                                : ix.preemption_model + " kernel";
  out.evidence = "kernel non-preemptible section while " + who + " ran for " +
                 FormatDuration(c.ns) + " (" + model + ")";
}

void DescribeInterrupt(const KernelIndex& ix, const Choice& c, const Tally& t, Cause& out) {
  const IrqTally& x = t.irqs.at(c.name);
  out.interrupt = ix.names[c.name];
  out.irq = x.kind == IrqKind::kHard ? x.irq : -1;
  out.cpu = x.cpu;
  std::string what = out.interrupt;
  if (x.kind == IrqKind::kHard && x.irq >= 0) what += " (irq " + std::to_string(x.irq) + ")";
  if (x.kind == IrqKind::kSoft) what = "softirq " + what;
  out.evidence = "interrupt: " + what + " for " + FormatDuration(c.ns);
  if (x.runs > 1) out.evidence += " in " + std::to_string(x.runs) + " runs";
}

void DescribeFaults(const Tally& t, Cause& out) {
  out.faults = t.faults;
  out.address = t.first_address;
  out.cpu = t.fault_cpu;
  char address[32];
  std::snprintf(address, sizeof address, "0x%llx", static_cast<unsigned long long>(t.first_address));
  out.evidence = std::to_string(t.faults) + (t.faults == 1 ? " page fault" : " page faults") +
                 " of the loop thread (first at " + address + ") for " +
                 FormatDuration(out.duration_ns);
}

void DescribeInvisible(const Tally& t, const CauseWindow& w, Cause& out) {
  const std::string cpu = "CPU " + std::to_string(out.cpu);
  const std::string delay = FormatDuration(std::max<std::int64_t>(w.excess_ns, 0)) + " delay";
  const std::int64_t idle_ns = std::min(t.idle_ns, std::max<std::int64_t>(w.excess_ns, 0));
  if (idle_ns > 0 && 2 * idle_ns >= out.duration_ns) {
    out.evidence = "nothing ran on " + cpu + " for " + FormatDuration(idle_ns) + " of the " +
                   delay;
  } else {
    out.evidence = "no event on " + cpu + " explains " + FormatDuration(out.duration_ns) +
                   " of the " + delay;
  }
  // A short stall on an idle CPU is as likely the exit from a deep idle state.
  const bool short_idle = idle_ns > 0 && out.duration_ns < kShortStallNs;
  out.evidence += short_idle ? ": invisible to the guest (idle-state exit, hypervisor steal or SMI)"
                             : ": invisible to the guest (hypervisor steal or SMI)";
}

Cause MakeCause(const KernelIndex& ix, const Decision& d, const Tally& t, const CauseWindow& w) {
  Cause out;
  out.cause = d.best.cause;
  out.duration_ns = d.best.ns;
  out.cpu = BusiestCpu(t, ix.home_cpu);
  switch (out.cause) {
    case CauseClass::kPreempted:
    case CauseClass::kNonPreemptible: DescribePreemption(ix, d.best, t, out); break;
    case CauseClass::kInterrupt: DescribeInterrupt(ix, d.best, t, out); break;
    case CauseClass::kPageFault: DescribeFaults(t, out); break;
    case CauseClass::kOwnCompute:
      out.evidence = "own compute: the step took " + FormatDuration(w.compute_ns) + " (p50 " +
                     FormatDuration(w.compute_p50_ns) + ", p99.9 " +
                     FormatDuration(w.compute_p999_ns) + "), " + FormatDuration(d.own_ns) +
                     " more than usual with nothing else running";
      break;
    case CauseClass::kInvisible: DescribeInvisible(t, w, out); break;
    case CauseClass::kBacklog:  // decided from the cycles, not the kernel (BacklogBehind)
    case CauseClass::kNotRecorded: break;
  }
  return out;
}

Cause NotRecorded(std::string why) {
  Cause out;
  out.cause = CauseClass::kNotRecorded;
  out.evidence = std::move(why);
  return out;
}

}  // namespace

CauseAttributor::CauseAttributor(const KernelTrace& kernel, const LoopThread& loop) {
  auto ix = std::make_unique<KernelIndex>();
  ix->tid = loop.tid;
  ix->home_cpu = loop.cpu;
  const bool rt = loop.policy == 1 || loop.policy == 2;  // SCHED_FIFO, SCHED_RR
  ix->loop_kernel_prio = rt ? 99 - loop.priority : -1;
  ix->preemption_model = kernel.preemption_model;
  ix->recorded_cpus = kernel.cpus;
  for (const KernelTask& task : kernel.tasks) ix->tasks[task.pid] = task;
  const auto [lo, hi] = std::minmax_element(
      kernel.events.begin(), kernel.events.end(),
      [](const KernelEvent& a, const KernelEvent& b) { return a.time_ns < b.time_ns; });
  if (lo != kernel.events.end()) {
    ix->first_ns = lo->time_ns;
    ix->last_ns = hi->time_ns;
  }
  IndexBuilder builder(*ix);
  for (const std::size_t i : IndicesByTime(kernel.events, ix->reordered)) builder.Add(kernel.events[i]);
  builder.Finish();
  index_ = std::move(ix);
}

CauseAttributor::~CauseAttributor() = default;

Cause CauseAttributor::Attribute(const CauseWindow& window) const {
  const KernelIndex& ix = *index_;
  if (ix.loop.empty() || window.begin_ns < ix.first_ns || window.end_ns > ix.last_ns) {
    return NotRecorded("the kernel recording does not cover this cycle");
  }
  WindowQuery query(ix, window);
  const Tally tally = query.Collect();
  if (tally.cpu_missing) {
    return NotRecorded(tally.missing_cpu < 0
                           ? "the loop's CPU is unknown (no scheduler event of the loop thread, "
                             "no pin)"
                           : "CPU " + std::to_string(tally.missing_cpu) +
                                 ", where the loop was, was not recorded");
  }
  return MakeCause(ix, Decide(ix, tally, window), tally, window);
}

std::vector<std::string> CauseAttributor::Warnings() const {
  const KernelIndex& ix = *index_;
  std::vector<std::string> out;
  if (ix.unmatched_interrupts > 0) {
    out.push_back(std::to_string(ix.unmatched_interrupts) +
                  " interrupt entries or exits without their partner were left out of the causes");
  }
  if (ix.reordered) out.emplace_back("the kernel events were not in time order; they were sorted");
  if (ix.unrecorded_switches > 0) {
    out.push_back(std::to_string(ix.unrecorded_switches) +
                  " switches in were not traced by the kernel (seen for the idle task); those "
                  "runs were rebuilt from the thread's wake-up");
  }
  const bool seen = std::any_of(ix.loop.begin(), ix.loop.end(), [](const LoopSegment& s) {
    return s.state != LoopState::kUnknown;
  });
  if (!seen) {
    out.push_back("the loop thread (tid " + std::to_string(ix.tid) +
                  ") never appears in the kernel's scheduler events: it is taken to be runnable "
                  "on CPU " + std::to_string(ix.home_cpu) + " throughout");
  }
  if (!ix.recorded_cpus.empty() && !ix.Recorded(ix.home_cpu)) {
    out.push_back("the loop's CPU " + std::to_string(ix.home_cpu) +
                  " was not among the recorded CPUs: its late cycles have no cause");
  }
  return out;
}

std::string CulpritName(const Cause& cause) {
  switch (cause.RankedAs()) {
    case CauseClass::kPreempted:
    case CauseClass::kNonPreemptible:
      return cause.thread + " (pid " + std::to_string(cause.pid) + ")";
    case CauseClass::kInterrupt: return cause.interrupt;
    case CauseClass::kPageFault: return "loop thread";
    case CauseClass::kOwnCompute: return "the step";
    case CauseClass::kInvisible: return "CPU " + std::to_string(cause.cpu);
    case CauseClass::kBacklog:  // RankedAs() is never a backlog: it names the stall's class
    case CauseClass::kNotRecorded: return "";
  }
  return "";
}

Cause BacklogBehind(const Cause& stall, std::uint64_t stall_k, std::int64_t waited_ns) {
  Cause out = stall;
  out.cause = CauseClass::kBacklog;
  out.inherited = stall.cause;
  out.behind_cycle = stall_k;
  out.duration_ns = waited_ns;
  out.evidence = "backlog behind k=" + std::to_string(stall_k) + " (" + stall.evidence + ")";
  return out;
}

std::vector<CauseCount> RankCauses(const std::vector<NotableCycle>& notable) {
  constexpr std::size_t kTopCulprits = 5;
  std::map<CauseClass, CauseCount> by_class;
  std::map<CauseClass, std::map<std::string, std::uint64_t>> culprits;
  for (const NotableCycle& n : notable) {
    const CauseClass cls = n.cause.RankedAs();
    CauseCount& c = by_class[cls];
    c.cause = cls;
    ++c.cycles;
    if (n.missed) ++c.misses;
    if (n.cause.cause == CauseClass::kBacklog) ++c.backlog;
    const std::string name = CulpritName(n.cause);
    if (!name.empty()) ++culprits[cls][name];
  }
  std::vector<CauseCount> ranked;
  for (auto& [cls, c] : by_class) {
    for (const auto& entry : culprits[cls]) c.culprits.emplace_back(entry);
    std::stable_sort(c.culprits.begin(), c.culprits.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    if (c.culprits.size() > kTopCulprits) c.culprits.resize(kTopCulprits);
    ranked.push_back(std::move(c));
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const CauseCount& a, const CauseCount& b) {
    return a.cycles != b.cycles ? a.cycles > b.cycles : a.misses > b.misses;
  });
  return ranked;
}

}  // namespace hiltwin::analysis::detail
