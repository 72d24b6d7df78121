#include "hiltwin/kernel_glue/os_calls.h"

#include <fcntl.h>
#include <linux/capability.h>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hiltwin::kernel_glue {
namespace {

class LinuxOsCalls final : public OsCalls {
 public:
  int SetThreadScheduler(int policy, int priority) const override {
    sched_param param{};
    param.sched_priority = priority;
    return pthread_setschedparam(pthread_self(), policy, &param);
  }

  int GetThreadScheduler(int& policy, int& priority) const override {
    sched_param param{};
    const int error = pthread_getschedparam(pthread_self(), &policy, &param);
    priority = param.sched_priority;
    return error;
  }

  int SetThreadAffinity(std::span<const int> cpus) const override {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (const int cpu : cpus) {
      if (cpu < 0 || cpu >= CPU_SETSIZE) return EINVAL;
      CPU_SET(static_cast<std::size_t>(cpu), &set);
    }
    return pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  }

  int LockAllMemory(int flags) const override { return mlockall(flags) == 0 ? 0 : errno; }

  int UnlockAllMemory() const override { return munlockall() == 0 ? 0 : errno; }

  int SetMallocOption(int param, int value) const override {
    // Not thread-safe (tidy: concurrency-mt-unsafe): RtSession::Apply documents that it runs
    // during start-up, before other threads allocate.
    return mallopt(param, value) == 1 ? 0 : EINVAL;  // NOLINT(concurrency-mt-unsafe)
  }

  int OpenCpuDmaLatency(std::int32_t latency_us, int& fd) const override {
    const int opened = open("/dev/cpu_dma_latency", O_RDWR | O_CLOEXEC);
    if (opened < 0) return errno;
    // The kernel takes a binary 32-bit value; the request lasts until the fd is closed.
    const ssize_t written = write(opened, &latency_us, sizeof(latency_us));
    if (written != static_cast<ssize_t>(sizeof(latency_us))) {
      const int error = written < 0 ? errno : EIO;
      close(opened);
      return error;
    }
    fd = opened;
    return 0;
  }

  void CloseFd(int fd) const override {
    if (fd >= 0) close(fd);
  }

  int GetMemlockLimit(std::uint64_t& soft_bytes, std::uint64_t& hard_bytes) const override {
    rlimit limit{};
    if (getrlimit(RLIMIT_MEMLOCK, &limit) != 0) return errno;
    soft_bytes = limit.rlim_cur == RLIM_INFINITY ? kUnlimited : limit.rlim_cur;
    hard_bytes = limit.rlim_max == RLIM_INFINITY ? kUnlimited : limit.rlim_max;
    return 0;
  }

  int SetMemlockSoftLimit(std::uint64_t soft_bytes) const override {
    rlimit limit{};
    if (getrlimit(RLIMIT_MEMLOCK, &limit) != 0) return errno;
    limit.rlim_cur = soft_bytes == kUnlimited ? RLIM_INFINITY : soft_bytes;
    return setrlimit(RLIMIT_MEMLOCK, &limit) == 0 ? 0 : errno;
  }

  bool HasIpcLockCapability() const override {
    // capget directly: glibc has no wrapper and libcap would be one more dependency.
    __user_cap_header_struct header{};
    header.version = _LINUX_CAPABILITY_VERSION_3;
    header.pid = 0;
    __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3] = {};
    if (syscall(SYS_capget, &header, data) != 0) return false;
    return (data[CAP_IPC_LOCK / 32].effective & (1U << (CAP_IPC_LOCK % 32))) != 0;
  }

  std::size_t ThreadStackBytes() const override {
    pthread_attr_t attr;
    if (pthread_getattr_np(pthread_self(), &attr) != 0) return 0;
    void* address = nullptr;
    std::size_t size = 0;
    if (pthread_attr_getstack(&attr, &address, &size) != 0) size = 0;
    pthread_attr_destroy(&attr);
    return size;
  }
};

}  // namespace

const OsCalls& RealOsCalls() noexcept {
  static const LinuxOsCalls calls;
  return calls;
}

std::string ErrnoText(int error) {
  const char* name = strerrorname_np(error);
  std::string text = name != nullptr ? name : ("errno " + std::to_string(error));
  const char* description = strerrordesc_np(error);
  if (description != nullptr) text += std::string(" (") + description + ")";
  return text;
}

}  // namespace hiltwin::kernel_glue
