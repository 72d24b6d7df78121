#pragma once
/// The one way hiltwin starts a thread. Every thread, the loop's included, is created here at
/// SCHED_OTHER with an explicit CPU set, never inheriting its creator's scheduling: a helper
/// started from a SCHED_FIFO loop would otherwise compete at the loop's priority on the loop's
/// CPU (cactus-rt `Thread::Create` owns thread creation for the same reason). The loop thread
/// raises itself afterwards (RtSession::Apply); nothing else may.

#include <pthread.h>

#include <functional>
#include <span>
#include <string>
#include <vector>

namespace hiltwin::kernel_glue {

/// How to start a thread.
struct ThreadSpec {
  std::string name;       ///< shown by ps/top/perf; at most 15 characters (kernel limit)
  std::vector<int> cpus;  ///< CPUs it may run on; empty: every CPU this process may use
};

/// A named SCHED_OTHER thread, joined on destruction.
class NamedThread {
 public:
  /// Starts `body` on a new thread created with PTHREAD_EXPLICIT_SCHED at SCHED_OTHER and
  /// the spec's CPU set, so it never runs a moment at its creator's policy or affinity.
  /// Throws std::invalid_argument for a bad spec, std::system_error when creation fails.
  NamedThread(const ThreadSpec& spec, std::function<void()> body);
  NamedThread() noexcept = default;
  NamedThread(NamedThread&& other) noexcept;
  NamedThread& operator=(NamedThread&& other) noexcept;
  NamedThread(const NamedThread&) = delete;
  NamedThread& operator=(const NamedThread&) = delete;
  ~NamedThread();

  /// Waits for the body to return. Idempotent.
  void Join() noexcept;
  [[nodiscard]] bool joinable() const noexcept { return started_; }
  [[nodiscard]] pthread_t native_handle() const noexcept { return handle_; }

 private:
  pthread_t handle_{};
  bool started_ = false;
};

/// The CPUs the calling thread may run on (its affinity mask), in increasing order.
[[nodiscard]] std::vector<int> AllowedCpus();

/// Pins the calling thread to `cpus`; 0 or an errno value (EINVAL for a bad CPU number).
[[nodiscard]] int SetCallingThreadCpus(std::span<const int> cpus) noexcept;

/// Moves the calling thread to `cpus` for a scope and back to the CPUs it had: threads that
/// libraries start meanwhile (Cyclone DDS, an HTTP server) inherit the scope's CPUs, so they
/// stay off the loop's. Best effort, like SetCallingThreadCpus; empty `cpus`: no change.
class ScopedThreadCpus {
 public:
  explicit ScopedThreadCpus(std::span<const int> cpus);
  ~ScopedThreadCpus();
  ScopedThreadCpus(const ScopedThreadCpus&) = delete;
  ScopedThreadCpus& operator=(const ScopedThreadCpus&) = delete;

 private:
  std::vector<int> previous_;
};

/// CPUs for helper threads: `allowed` minus `loop_cpus`; all of `allowed` when the loop is not
/// pinned or takes every allowed CPU (a helper must run somewhere).
[[nodiscard]] std::vector<int> HelperCpus(std::span<const int> allowed,
                                          std::span<const int> loop_cpus);

}  // namespace hiltwin::kernel_glue
