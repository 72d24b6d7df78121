#pragma once
/// Real-time set-up of the calling thread and process: SCHED_FIFO, CPU affinity, memory
/// locking with heap and stack pre-fault, and /dev/cpu_dma_latency held at 0 µs.
/// Every step that the OS refuses is warned about once (errno and advice) and skipped; the
/// run continues and the returned record says what is in effect (it goes into run reports).
/// See docs/realtime-setup.md for what each step does and how to grant the privileges.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hiltwin/kernel_glue/os_calls.h"

namespace hiltwin::kernel_glue {

/// What to ask of the OS. Defaults suit a twin at kHz rates on a desktop machine.
struct RtSetupRequest {
  int fifo_priority = 0;    ///< 1..99: SCHED_FIFO; 0: stay SCHED_OTHER
  std::vector<int> cpus;    ///< pin the calling thread; empty: no pinning
  bool lock_memory = true;  ///< mallopt + mlockall + heap pre-fault
  std::size_t prefault_stack_bytes =
      std::size_t{256} * 1024;                  ///< stack of the calling thread to touch
  std::size_t prefault_heap_bytes = 32u << 20;  ///< heap to touch and keep (needs mallopt)
  bool hold_cpu_dma_latency = true;             ///< keep deep C-states off while alive
};

/// What is actually in effect after RtSession::Apply, and why not where it is not.
struct RtSetupRecord {
  bool sched_fifo = false;       ///< calling thread runs SCHED_FIFO
  int fifo_priority = 0;         ///< its priority (0 when SCHED_OTHER)
  bool affinity = false;         ///< calling thread pinned to `cpus`
  std::vector<int> cpus;         ///< CPUs pinned to (empty when not pinned)
  bool memory_locked = false;    ///< mlockall(MCL_CURRENT|MCL_FUTURE) succeeded
  bool heap_prefaulted = false;  ///< heap touched and kept by malloc (trim/mmap off)
  std::size_t heap_prefault_bytes = 0;
  bool stack_prefaulted = false;  ///< calling thread's stack touched
  std::size_t stack_prefault_bytes = 0;
  bool cpu_dma_latency_held = false;  ///< /dev/cpu_dma_latency open with 0 µs
  std::vector<std::string> warnings;  ///< one line per refused or reduced step
};

/// Applies a RtSetupRequest and owns what must be released at the end (the cpu_dma_latency
/// descriptor). Scheduling, affinity and stack pre-fault act on the CALLING thread: call
/// Apply from the thread that will run the loop. Memory locking and the mallopt settings are
/// process-wide and deliberately stay in effect after the session ends; mallopt is not
/// thread-safe, so apply during start-up, before other threads allocate.
class RtSession {
 public:
  /// Runs every requested step; refused steps warn and are skipped. Throws
  /// std::invalid_argument only for a bad request (priority outside 0..99, negative CPU).
  /// `os` must outlive the session (RealOsCalls() does).
  [[nodiscard]] static RtSession Apply(const RtSetupRequest& request,
                                       const OsCalls& os = RealOsCalls());

  /// A session that holds nothing (nothing requested).
  RtSession() noexcept = default;
  RtSession(RtSession&& other) noexcept;
  RtSession& operator=(RtSession&& other) noexcept;
  RtSession(const RtSession&) = delete;
  RtSession& operator=(const RtSession&) = delete;
  /// Closes /dev/cpu_dma_latency, which ends the latency request.
  ~RtSession();

  /// What is in effect.
  [[nodiscard]] const RtSetupRecord& record() const noexcept { return record_; }

 private:
  void Release() noexcept;

  RtSetupRecord record_;
  const OsCalls* os_ = nullptr;
  int dma_latency_fd_ = -1;
};

/// The record as a run-report object (keys as the struct's field names).
[[nodiscard]] nlohmann::json ToJson(const RtSetupRecord& record);

/// One line for a console summary, e.g. "SCHED_FIFO 90, CPUs 1, memory locked, ...".
[[nodiscard]] std::string Summary(const RtSetupRecord& record);

/// How many set-up warnings this process has sent to the log so far. Each kind of refusal
/// is logged only the first time; later sessions still list it in their record.
[[nodiscard]] std::uint64_t RtSetupWarningsLogged() noexcept;
/// Test hook: forgets which kinds of refusal were logged, so a test sees a first one again.
void ResetRtSetupWarningsForTest() noexcept;

}  // namespace hiltwin::kernel_glue
