#include "kernel_tracks.h"

#include <algorithm>
#include <map>
#include <set>
#include <unordered_map>

namespace hiltwin::analysis::detail {
namespace {

enum class HandlerKind : std::uint8_t { kHard, kTimer, kSoft };

struct OpenHandler {
  std::int64_t begin_ns = 0;
  HandlerKind kind = HandlerKind::kHard;
  int irq = -1;
  std::string name;
};

// The thread the last traced switch brought onto a CPU.
struct Occupant {
  bool known = false;
  int pid = 0;
  int prio = 0;
  std::string comm;
  std::int64_t begin_ns = 0;
};

struct CpuState {
  Occupant occupant;
  std::vector<OpenHandler> open;
};

std::string HandlerName(const KernelEvent& e, HandlerKind kind) {
  const std::string number = std::to_string(e.irq);
  switch (kind) {
    case HandlerKind::kHard:
      return e.name.empty() ? "irq " + number : e.name + " (irq " + number + ")";
    case HandlerKind::kTimer: return "local_timer";
    case HandlerKind::kSoft: return "softirq " + (e.name.empty() ? "vector " + number : e.name);
  }
  return "interrupt";
}

void OnEntry(const KernelEvent& e, HandlerKind kind, CpuState& cpu) {
  cpu.open.push_back({e.time_ns, kind, e.irq, HandlerName(e, kind)});
}

// The recorded CPUs the loop thread used: its pin and every CPU a switch moved it on or off.
std::vector<int> LoopCpus(const KernelTrace& kernel, const LoopThread& loop) {
  std::set<int> used;
  if (loop.cpu >= 0) used.insert(loop.cpu);
  for (const KernelEvent& e : kernel.events) {
    if (e.kind == KernelEventKind::kSchedSwitch && (e.pid == loop.tid || e.next_pid == loop.tid)) {
      used.insert(e.cpu);
    }
  }
  std::vector<int> cpus;
  for (const int cpu : used) {
    const bool recorded = kernel.cpus.empty() || std::find(kernel.cpus.begin(), kernel.cpus.end(),
                                                           cpu) != kernel.cpus.end();
    if (recorded) cpus.push_back(cpu);
  }
  return cpus;
}

class TrackBuilder {
 public:
  TrackBuilder(const KernelTrace& kernel, const LoopThread& loop, std::int64_t from_ns,
               std::int64_t to_ns)
      : kernel_(kernel), tid_(loop.tid), from_ns_(from_ns), to_ns_(to_ns) {
    out_.cpus = LoopCpus(kernel, loop);
    for (const int cpu : out_.cpus) cpus_.try_emplace(cpu);
  }
  void Add(const KernelEvent& e);
  KernelTracks Finish(std::int64_t last_ns);

 private:
  void OnSwitch(const KernelEvent& e, CpuState& cpu);
  void OnExit(const KernelEvent& e, HandlerKind kind, CpuState& cpu);
  void Emit(const Occupant& who, int cpu, std::int64_t end_ns);

  const KernelTrace& kernel_;
  int tid_ = 0;
  std::int64_t from_ns_ = 0;
  std::int64_t to_ns_ = 0;
  std::int64_t first_ns_ = 0;
  bool started_ = false;
  std::map<int, CpuState> cpus_;
  std::unordered_map<int, std::int64_t> last_wakeup_ns_;  // by pid
  std::map<int, KernelTracks::Thread> names_;
  KernelTracks out_;
};

void TrackBuilder::Add(const KernelEvent& e) {
  if (!started_) first_ns_ = e.time_ns;
  started_ = true;
  if (e.kind == KernelEventKind::kSchedWakeup) last_wakeup_ns_[e.pid] = e.time_ns;
  const auto it = cpus_.find(e.cpu);
  if (it == cpus_.end()) return;
  CpuState& cpu = it->second;
  switch (e.kind) {
    case KernelEventKind::kSchedSwitch: OnSwitch(e, cpu); break;
    case KernelEventKind::kIrqEntry: OnEntry(e, HandlerKind::kHard, cpu); break;
    case KernelEventKind::kLocalTimerEntry: OnEntry(e, HandlerKind::kTimer, cpu); break;
    case KernelEventKind::kSoftirqEntry: OnEntry(e, HandlerKind::kSoft, cpu); break;
    case KernelEventKind::kIrqExit: OnExit(e, HandlerKind::kHard, cpu); break;
    case KernelEventKind::kLocalTimerExit: OnExit(e, HandlerKind::kTimer, cpu); break;
    case KernelEventKind::kSoftirqExit: OnExit(e, HandlerKind::kSoft, cpu); break;
    case KernelEventKind::kSchedWakeup:
    case KernelEventKind::kPageFaultUser: break;
  }
}

void TrackBuilder::OnSwitch(const KernelEvent& e, CpuState& cpu) {
  Occupant& now = cpu.occupant;
  Occupant prev{true, e.pid, e.prio, e.comm, now.known ? now.begin_ns : first_ns_};
  if (now.known && now.pid != e.pid) {
    // prev's switch in was not traced: it ran from its wake-up (if since the last switch).
    const auto wake = last_wakeup_ns_.find(e.pid);
    if (wake != last_wakeup_ns_.end() && wake->second > now.begin_ns &&
        wake->second < e.time_ns) {
      prev.begin_ns = wake->second;
    }
    Emit(now, e.cpu, prev.begin_ns);
  }
  Emit(prev, e.cpu, e.time_ns);
  now = Occupant{true, e.next_pid, e.next_prio, e.next_comm, e.time_ns};
}

void TrackBuilder::OnExit(const KernelEvent& e, HandlerKind kind, CpuState& cpu) {
  const auto match = std::find_if(cpu.open.rbegin(), cpu.open.rend(), [&](const OpenHandler& o) {
    return o.kind == kind && (kind == HandlerKind::kTimer || o.irq == e.irq);
  });
  if (match == cpu.open.rend()) return;
  const auto entry = match.base() - 1;
  const std::int64_t begin = std::max(entry->begin_ns, from_ns_);
  const std::int64_t end = std::min(e.time_ns, to_ns_);
  if (end > begin) out_.irqs.push_back({begin, end, e.cpu, entry->name});
  cpu.open.erase(entry, cpu.open.end());  // and the entries after it that never exited
}

void TrackBuilder::Emit(const Occupant& who, int cpu, std::int64_t end_ns) {
  if (who.pid == 0 || who.pid == tid_) return;
  const std::int64_t begin = std::max(who.begin_ns, from_ns_);
  const std::int64_t end = std::min(end_ns, to_ns_);
  if (end <= begin) return;
  out_.threads.push_back({begin, end, who.pid, cpu, who.prio});
  names_.try_emplace(who.pid, KernelTracks::Thread{who.pid, who.comm, "", 0});
}

KernelTracks TrackBuilder::Finish(std::int64_t last_ns) {
  for (const auto& [number, cpu] : cpus_) {
    if (cpu.occupant.known) Emit(cpu.occupant, number, last_ns);
  }
  auto by_begin = [](const auto& a, const auto& b) { return a.begin_ns < b.begin_ns; };
  std::stable_sort(out_.threads.begin(), out_.threads.end(), by_begin);
  std::stable_sort(out_.irqs.begin(), out_.irqs.end(), by_begin);  // pushed at their exits
  for (const KernelTask& task : kernel_.tasks) {
    const auto it = names_.find(task.pid);
    if (it == names_.end()) continue;
    it->second.policy = task.policy;
    it->second.rt_priority = task.rt_priority;
  }
  for (auto& [pid, thread] : names_) out_.names.push_back(std::move(thread));
  return std::move(out_);
}

}  // namespace

KernelTracks LoopCpuTracks(const KernelTrace& kernel, const LoopThread& loop, std::int64_t from_ns,
                           std::int64_t to_ns) {
  std::vector<const KernelEvent*> order;
  order.reserve(kernel.events.size());
  for (const KernelEvent& e : kernel.events) order.push_back(&e);
  // The recorder writes them in time order; a merge of per-CPU buffers slightly off is put right.
  std::stable_sort(order.begin(), order.end(), [](const KernelEvent* a, const KernelEvent* b) {
    return a->time_ns < b->time_ns;
  });
  TrackBuilder builder(kernel, loop, from_ns, to_ns);
  for (const KernelEvent* e : order) builder.Add(*e);
  return builder.Finish(order.empty() ? to_ns : order.back()->time_ns);
}

}  // namespace hiltwin::analysis::detail
