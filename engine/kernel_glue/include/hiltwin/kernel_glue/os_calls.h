#pragma once
/// The operating-system calls behind real-time set-up and the readiness probe, behind one
/// interface so tests can make any of them fail (EPERM, ENOMEM, ...) without privileges.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace hiltwin::kernel_glue {

/// Each call returns 0 on success or a positive errno value (never -1 plus errno), so a fake
/// can refuse a call by returning the code alone. Thread-affecting calls act on the caller.
class OsCalls {
 public:
  /// A resource limit without bound (RLIM_INFINITY).
  static constexpr std::uint64_t kUnlimited = ~std::uint64_t{0};
  virtual ~OsCalls() = default;
  /// pthread_setschedparam(pthread_self(), policy, priority).
  [[nodiscard]] virtual int SetThreadScheduler(int policy, int priority) const = 0;
  /// pthread_getschedparam(pthread_self(), ...).
  [[nodiscard]] virtual int GetThreadScheduler(int& policy, int& priority) const = 0;
  /// pthread_setaffinity_np(pthread_self(), ...) to exactly `cpus`.
  [[nodiscard]] virtual int SetThreadAffinity(std::span<const int> cpus) const = 0;
  /// mlockall(flags).
  [[nodiscard]] virtual int LockAllMemory(int flags) const = 0;
  /// munlockall().
  [[nodiscard]] virtual int UnlockAllMemory() const = 0;
  /// mallopt(param, value); glibc reports failure without errno, mapped to EINVAL.
  [[nodiscard]] virtual int SetMallocOption(int param, int value) const = 0;
  /// Opens /dev/cpu_dma_latency and writes `latency_us` (binary int32); the request holds
  /// while the descriptor stays open. On success `fd` receives the descriptor.
  [[nodiscard]] virtual int OpenCpuDmaLatency(std::int32_t latency_us, int& fd) const = 0;
  /// Closes a descriptor from OpenCpuDmaLatency.
  virtual void CloseFd(int fd) const = 0;
  /// getrlimit(RLIMIT_MEMLOCK) in bytes; kUnlimited for RLIM_INFINITY.
  [[nodiscard]] virtual int GetMemlockLimit(std::uint64_t& soft_bytes,
                                            std::uint64_t& hard_bytes) const = 0;
  /// setrlimit(RLIMIT_MEMLOCK) soft limit (the hard limit is kept).
  [[nodiscard]] virtual int SetMemlockSoftLimit(std::uint64_t soft_bytes) const = 0;
  /// True when CAP_IPC_LOCK is in the effective set (locking ignores RLIMIT_MEMLOCK then).
  [[nodiscard]] virtual bool HasIpcLockCapability() const = 0;
  /// Size of the calling thread's stack in bytes (0 when unknown).
  [[nodiscard]] virtual std::size_t ThreadStackBytes() const = 0;
};

/// The real calls. The object lives for the whole program.
[[nodiscard]] const OsCalls& RealOsCalls() noexcept;

/// "EPERM (Operation not permitted)" for errno value `error`.
[[nodiscard]] std::string ErrnoText(int error);

}  // namespace hiltwin::kernel_glue
