#include "hiltwin/kernel_glue/rt_setup.h"

#include <alloca.h>
#include <malloc.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace hiltwin::kernel_glue {
namespace {

// One flag per kind of refusal: the log gets each kind once per process, however many
// threads or sessions hit it, so a multi-threaded run does not repeat the same advice.
enum class Step : std::size_t {
  kSchedFifo,
  kAffinity,
  kMallopt,
  kMlockall,
  kHeapPrefault,
  kStackPrefault,
  kCpuDmaLatency,
  kCount,
};

std::array<std::atomic<bool>, static_cast<std::size_t>(Step::kCount)> g_warned{};
std::atomic<std::uint64_t> g_warnings_logged{0};

void Warn(RtSetupRecord& record, Step step, std::string message) {
  if (!g_warned[static_cast<std::size_t>(step)].exchange(true)) {
    g_warnings_logged.fetch_add(1);
    spdlog::warn("RT set-up: {}", message);
  }
  record.warnings.push_back(std::move(message));
}

std::string CpuList(const std::vector<int>& cpus) {
  std::string text;
  for (const int cpu : cpus) {
    if (!text.empty()) text += ',';
    text += std::to_string(cpu);
  }
  return text;
}

std::size_t PageBytes() noexcept {
  const long page = sysconf(_SC_PAGESIZE);
  return page > 0 ? static_cast<std::size_t>(page) : 4096;
}

// Writes one byte per page so every page is faulted in (and, after mlockall, stays).
void TouchPages(unsigned char* memory, std::size_t bytes) noexcept {
  const std::size_t page = PageBytes();
  volatile unsigned char* touch = memory;
  for (std::size_t offset = 0; offset < bytes; offset += page) touch[offset] = 0;
  if (bytes > 0) touch[bytes - 1] = 0;
}

// noinline: the alloca'd block must be this frame's, below the caller's, and released on
// return, leaving the pages faulted in for the loop's own frames.
[[gnu::noinline]] void PrefaultStack(std::size_t bytes) noexcept {
  auto* block = static_cast<unsigned char*>(alloca(bytes));
  TouchPages(block, bytes);
  asm volatile("" : : "r"(block) : "memory");  // keep the touches from being optimised out
}

// With MCL_FUTURE every later mapping must fit under RLIMIT_MEMLOCK, so a small limit lets
// mlockall succeed and then makes malloc, thread stacks and file maps fail mid-run (seen here:
// an 8 MiB limit locked a small process, then a 32 MiB malloc returned null). Lock only
// with CAP_IPC_LOCK or a limit large enough for the whole process; raise soft to hard first.
constexpr std::uint64_t kMinMemlockForFutureBytes = std::uint64_t{1} << 30;

bool MemlockLimitAllowsLocking(const OsCalls& os, RtSetupRecord& record) {
  if (os.HasIpcLockCapability()) return true;
  std::uint64_t soft_bytes = 0;
  std::uint64_t hard_bytes = 0;
  if (os.GetMemlockLimit(soft_bytes, hard_bytes) != 0) return true;  // let mlockall decide
  if (soft_bytes < hard_bytes && os.SetMemlockSoftLimit(hard_bytes) == 0) soft_bytes = hard_bytes;
  if (soft_bytes == OsCalls::kUnlimited || soft_bytes >= kMinMemlockForFutureBytes) return true;
  Warn(record, Step::kMlockall,
       "mlockall skipped: RLIMIT_MEMLOCK is " + std::to_string(soft_bytes >> 10) +
           " KiB without CAP_IPC_LOCK, and with MCL_FUTURE every allocation past that limit "
           "would fail mid-run; grant CAP_IPC_LOCK (sudo setcap cap_ipc_lock,cap_sys_nice+ep "
           "<hiltwin>) or set '@realtime - memlock unlimited' in /etc/security/limits.conf; "
           "continuing unlocked: page faults and swapping may stall the loop");
  return false;
}

void ApplyMemory(const RtSetupRequest& request, const OsCalls& os, RtSetupRecord& record) {
  // mallopt first: with trimming and mmap off, the heap pre-fault below stays in malloc's
  // arena after free() instead of going back to the kernel (cactus-rt app.cc LockMemory).
  const int trim_error = os.SetMallocOption(M_TRIM_THRESHOLD, -1);
  const int mmap_error = trim_error == 0 ? os.SetMallocOption(M_MMAP_MAX, 0) : 0;
  const bool mallopt_ok = trim_error == 0 && mmap_error == 0;
  if (!mallopt_ok) {
    Warn(record, Step::kMallopt,
         "mallopt(" + std::string(trim_error != 0 ? "M_TRIM_THRESHOLD" : "M_MMAP_MAX") +
             ") refused (" + ErrnoText(trim_error != 0 ? trim_error : mmap_error) +
             "): the allocator is not glibc's (or runs under a sanitizer); continuing "
             "without heap pre-fault, so first allocations may page-fault");
  }

  if (MemlockLimitAllowsLocking(os, record)) {
    const int lock_error = os.LockAllMemory(MCL_CURRENT | MCL_FUTURE);
    record.memory_locked = lock_error == 0;
    if (lock_error != 0) {
      Warn(record, Step::kMlockall,
           "mlockall(MCL_CURRENT|MCL_FUTURE) refused (" + ErrnoText(lock_error) +
               "): run as root, or grant CAP_IPC_LOCK (sudo setcap cap_ipc_lock,cap_sys_nice+ep "
               "<hiltwin>) or a memlock limit in /etc/security/limits.conf ('@realtime - "
               "memlock unlimited'); continuing unlocked: page faults and swapping may stall "
               "the loop");
    }
  }

  if (request.prefault_heap_bytes > 0 && mallopt_ok) {
    auto* heap = static_cast<unsigned char*>(std::malloc(request.prefault_heap_bytes));
    if (heap == nullptr) {
      Warn(record, Step::kHeapPrefault,
           "heap pre-fault of " + std::to_string(request.prefault_heap_bytes >> 10) +
               " KiB failed (malloc returned null): lower prefault_heap_bytes; continuing");
    } else {
      TouchPages(heap, request.prefault_heap_bytes);
      std::free(heap);  // stays in the arena: trimming is off
      record.heap_prefaulted = true;
      record.heap_prefault_bytes = request.prefault_heap_bytes;
    }
  }
}

void ApplyStack(const RtSetupRequest& request, const OsCalls& os, RtSetupRecord& record) {
  if (request.prefault_stack_bytes == 0) return;
  // Never touch more than half the thread's stack: the caller's frames use some of it, and
  // running off the end would crash instead of warning.
  constexpr std::size_t kUnknownStackLimitBytes = std::size_t{256} * 1024;
  const std::size_t stack_bytes = os.ThreadStackBytes();
  const std::size_t limit_bytes = stack_bytes > 0 ? stack_bytes / 2 : kUnknownStackLimitBytes;
  std::size_t bytes = request.prefault_stack_bytes;
  if (bytes > limit_bytes) {
    bytes = limit_bytes;
    Warn(record, Step::kStackPrefault,
         "stack pre-fault reduced from " + std::to_string(request.prefault_stack_bytes >> 10) +
             " KiB to " + std::to_string(bytes >> 10) + " KiB (thread stack " +
             (stack_bytes > 0 ? std::to_string(stack_bytes >> 10) + " KiB" : "size unknown") +
             "): give the RT thread a larger stack or ask for less; continuing");
  }
  PrefaultStack(bytes);
  record.stack_prefaulted = true;
  record.stack_prefault_bytes = bytes;
}

void ApplyAffinity(const RtSetupRequest& request, const OsCalls& os, RtSetupRecord& record) {
  if (request.cpus.empty()) return;
  const int error = os.SetThreadAffinity(request.cpus);
  if (error == 0) {
    record.affinity = true;
    record.cpus = request.cpus;
    return;
  }
  Warn(record, Step::kAffinity,
       "CPU affinity to {" + CpuList(request.cpus) + "} refused (" + ErrnoText(error) + "): " +
           (error == EINVAL
                ? "a CPU is offline, outside this process's cpuset (container, taskset) or "
                  "beyond the machine; check /sys/devices/system/cpu/online and `taskset -pc "
                  "$$`"
                : "grant CAP_SYS_NICE or run as root") +
           "; continuing on all allowed CPUs");
}

void ApplyDmaLatency(const OsCalls& os, RtSetupRecord& record, int& fd) {
  const int error = os.OpenCpuDmaLatency(0, fd);
  if (error == 0) {
    record.cpu_dma_latency_held = true;
    return;
  }
  fd = -1;
  Warn(record, Step::kCpuDmaLatency,
       "/dev/cpu_dma_latency refused (" + ErrnoText(error) + "): " +
           (error == ENOENT ? "the kernel has no PM QoS device here"
                            : "run as root, or give a group write access with a udev rule "
                              "(KERNEL==\"cpu_dma_latency\", GROUP=\"realtime\", MODE=\"0660\")") +
           "; continuing: deep CPU idle states may add wake-up latency");
}

void ApplyScheduler(const RtSetupRequest& request, const OsCalls& os, RtSetupRecord& record) {
  if (request.fifo_priority == 0) return;
  const int error = os.SetThreadScheduler(SCHED_FIFO, request.fifo_priority);
  if (error == 0) {
    record.sched_fifo = true;
    record.fifo_priority = request.fifo_priority;
    return;
  }
  Warn(record, Step::kSchedFifo,
       "SCHED_FIFO priority " + std::to_string(request.fifo_priority) + " refused (" +
           ErrnoText(error) +
           "): run as root, or grant CAP_SYS_NICE (sudo setcap cap_sys_nice,cap_ipc_lock+ep "
           "<hiltwin>) or an rtprio limit in /etc/security/limits.conf ('@realtime - rtprio "
           "98'); in a container add --cap-add=SYS_NICE, and with RT group scheduling give "
           "the cgroup cpu.rt_runtime_us; continuing with SCHED_OTHER");
}

}  // namespace

RtSession RtSession::Apply(const RtSetupRequest& request, const OsCalls& os) {
  if (request.fifo_priority < 0 || request.fifo_priority > 99) {
    throw std::invalid_argument("RT set-up: fifo_priority " +
                                std::to_string(request.fifo_priority) +
                                " is outside 0..99 (0 keeps SCHED_OTHER); choose 1..99");
  }
  for (const int cpu : request.cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
      throw std::invalid_argument("RT set-up: CPU " + std::to_string(cpu) +
                                  " is not a CPU number; list CPUs from "
                                  "/sys/devices/system/cpu/online");
    }
  }

  RtSession session;
  session.os_ = &os;
  RtSetupRecord& record = session.record_;
  // Order: memory work first, while still SCHED_OTHER, so touching tens of MiB does not
  // hog a CPU at RT priority; SCHED_FIFO last, once everything else is in place.
  if (request.lock_memory) ApplyMemory(request, os, record);
  ApplyStack(request, os, record);
  ApplyAffinity(request, os, record);
  if (request.hold_cpu_dma_latency) ApplyDmaLatency(os, record, session.dma_latency_fd_);
  ApplyScheduler(request, os, record);
  return session;
}

RtSession::RtSession(RtSession&& other) noexcept
    : record_(std::move(other.record_)),
      os_(other.os_),
      dma_latency_fd_(std::exchange(other.dma_latency_fd_, -1)) {
  other.record_.cpu_dma_latency_held = false;
}

RtSession& RtSession::operator=(RtSession&& other) noexcept {
  if (this != &other) {
    Release();
    record_ = std::move(other.record_);
    os_ = other.os_;
    dma_latency_fd_ = std::exchange(other.dma_latency_fd_, -1);
    other.record_.cpu_dma_latency_held = false;
  }
  return *this;
}

RtSession::~RtSession() { Release(); }

void RtSession::Release() noexcept {
  if (dma_latency_fd_ >= 0 && os_ != nullptr) os_->CloseFd(dma_latency_fd_);
  dma_latency_fd_ = -1;
  record_.cpu_dma_latency_held = false;
}

nlohmann::json ToJson(const RtSetupRecord& record) {
  return nlohmann::json{
      {"sched_fifo", record.sched_fifo},
      {"fifo_priority", record.fifo_priority},
      {"affinity", record.affinity},
      {"cpus", record.cpus},
      {"memory_locked", record.memory_locked},
      {"heap_prefaulted", record.heap_prefaulted},
      {"heap_prefault_bytes", record.heap_prefault_bytes},
      {"stack_prefaulted", record.stack_prefaulted},
      {"stack_prefault_bytes", record.stack_prefault_bytes},
      {"cpu_dma_latency_held", record.cpu_dma_latency_held},
      {"warnings", record.warnings},
  };
}

std::string Summary(const RtSetupRecord& record) {
  std::string text = record.sched_fifo ? "SCHED_FIFO " + std::to_string(record.fifo_priority)
                                       : std::string("SCHED_OTHER");
  text += record.affinity ? ", CPUs " + CpuList(record.cpus) : ", not pinned";
  text += record.memory_locked ? ", memory locked" : ", memory NOT locked";
  if (record.heap_prefaulted) {
    text += ", heap " + std::to_string(record.heap_prefault_bytes >> 20) + " MiB pre-faulted";
  }
  if (record.stack_prefaulted) {
    text += ", stack " + std::to_string(record.stack_prefault_bytes >> 10) + " KiB pre-faulted";
  }
  text +=
      record.cpu_dma_latency_held ? ", cpu_dma_latency 0 us held" : ", cpu_dma_latency not held";
  text += "; " + std::to_string(record.warnings.size()) +
          (record.warnings.size() == 1 ? " warning" : " warnings");
  return text;
}

std::uint64_t RtSetupWarningsLogged() noexcept { return g_warnings_logged.load(); }

void ResetRtSetupWarningsForTest() noexcept {
  for (auto& warned : g_warned) warned.store(false);
}

}  // namespace hiltwin::kernel_glue
