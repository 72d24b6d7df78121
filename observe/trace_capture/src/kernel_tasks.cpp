// The threads of a kernel recording and their scheduling class, read once it has ended (the
// events carry only the kernel prio, which does not tell SCHED_FIFO from SCHED_RR).
#include "kernel_tasks.h"

#include <sched.h>

#include <cerrno>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace hiltwin::trace_capture {
namespace {

using analysis::KernelEvent;
using analysis::KernelEventKind;
using analysis::KernelTask;

constexpr int kSchedDeadline = 6;  // not in every libc's <sched.h>
constexpr int kMaxRtPrio = 100;    // kernel prio = kMaxRtPrio - 1 - rt_priority

// The last name each pid had in the events (a thread may rename itself; the last name is the
// one it ran under most recently). Pids without a name map to "".
std::map<int, std::string> NamesByPid(const std::vector<KernelEvent>& events) {
  std::map<int, std::string> names;
  const auto note = [&names](int pid, const std::string& comm) {
    std::string& name = names[pid];
    if (!comm.empty()) name = comm;
  };
  for (const KernelEvent& event : events) {
    switch (event.kind) {
      case KernelEventKind::kSchedSwitch:
        note(event.pid, event.comm);
        note(event.next_pid, event.next_comm);
        break;
      case KernelEventKind::kSchedWakeup:
      case KernelEventKind::kPageFaultUser:
        note(event.pid, event.comm);
        break;
      default:
        break;
    }
  }
  return names;
}

std::string ProcComm(int pid) {
  std::string comm;
  std::getline(std::ifstream("/proc/" + std::to_string(pid) + "/comm"), comm);
  return comm;
}

// /proc/<pid>/sched, for when the system calls refuse (a sandbox's seccomp policy, say).
void ReadProcSched(int pid, KernelTask& task) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/sched");
  int policy = -1;
  int prio = -1;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key;
    std::string colon;
    fields >> key >> colon;
    if (key == "policy") fields >> policy;
    if (key == "prio") fields >> prio;
  }
  if (policy < 0) return;
  task.policy = PolicyName(policy);
  if ((policy == SCHED_FIFO || policy == SCHED_RR) && prio >= 0 && prio < kMaxRtPrio) {
    task.rt_priority = kMaxRtPrio - 1 - prio;
  }
}

KernelTask ReadTask(int pid, const std::string& comm) {
  KernelTask task{.pid = pid, .comm = comm, .policy = {}, .rt_priority = 0};
  errno = 0;
  const int policy = ::sched_getscheduler(pid);
  if (policy >= 0) {
    task.policy = PolicyName(policy & ~SCHED_RESET_ON_FORK);
    sched_param param{};
    if (::sched_getparam(pid, &param) == 0) task.rt_priority = param.sched_priority;
    return task;
  }
  if (errno != ESRCH) ReadProcSched(pid, task);  // ESRCH: gone, the policy stays empty
  return task;
}

}  // namespace

std::string PolicyName(int policy) {
  switch (policy) {
    case SCHED_OTHER:
      return "SCHED_OTHER";
    case SCHED_FIFO:
      return "SCHED_FIFO";
    case SCHED_RR:
      return "SCHED_RR";
    case SCHED_BATCH:
      return "SCHED_BATCH";
    case SCHED_IDLE:
      return "SCHED_IDLE";
    case kSchedDeadline:
      return "SCHED_DEADLINE";
    default:
      return "policy " + std::to_string(policy);
  }
}

void FillMissingComms(std::vector<KernelEvent>& events) {
  const std::map<int, std::string> names = NamesByPid(events);
  std::map<int, std::string> from_proc;
  for (KernelEvent& event : events) {
    if (event.kind != KernelEventKind::kPageFaultUser || !event.comm.empty()) continue;
    const auto named = names.find(event.pid);
    if (named != names.end() && !named->second.empty()) {
      event.comm = named->second;
      continue;
    }
    const auto [cached, inserted] = from_proc.try_emplace(event.pid);
    if (inserted) cached->second = ProcComm(event.pid);
    event.comm = cached->second;
  }
}

std::vector<KernelTask> TasksSeen(const std::vector<KernelEvent>& events) {
  std::vector<KernelTask> tasks;
  for (const auto& [pid, comm] : NamesByPid(events)) {
    if (pid == 0) continue;  // the idle task; sched_getscheduler(0) would answer for us
    tasks.push_back(ReadTask(pid, comm.empty() ? ProcComm(pid) : comm));
  }
  return tasks;
}

}  // namespace hiltwin::trace_capture
