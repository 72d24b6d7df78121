#pragma once
// A tracefs instance of this process: a ring buffer and settings of its own, so the system's
// top-level tracing settings (and anyone else's recording) stay untouched.

#include <cstdint>
#include <string>
#include <vector>

#include "tracefs_api.h"

namespace hiltwin::trace_capture {

class TracefsInstance {
 public:
  /// Creates instances/<name>; throws CaptureError when it cannot, or when it already exists
  /// (another recorder of this process, or a leftover of a crashed one with this pid).
  explicit TracefsInstance(const std::string& name);
  /// Destroy() when not done yet; never throws.
  ~TracefsInstance();
  TracefsInstance(const TracefsInstance&) = delete;
  TracefsInstance& operator=(const TracefsInstance&) = delete;

  [[nodiscard]] tracefs_instance* get() const noexcept { return instance_; }

  /// Recording off, trace_clock mono, cpumask `cpus`, `buffer_kb` per recorded CPU.
  void Configure(const std::vector<int>& cpus, int buffer_kb);
  /// Enables the recorder's events; one this kernel lacks is skipped with a warning. Throws
  /// CaptureError when none could be enabled.
  void EnableEvents();
  void SetRecording(bool on);
  /// Events the ring buffers of `cpus` lost (per_cpu/cpuN/stats).
  [[nodiscard]] std::uint64_t LostEvents(const std::vector<int>& cpus) const;

  /// Turns recording off, removes the instance and frees it. Idempotent, never throws.
  void Destroy() noexcept;

 private:
  void Write(const std::string& file, const std::string& value) const;

  tracefs_instance* instance_ = nullptr;
  std::string name_;
};

/// CPUs in the kernel's list form ("0-3,6"); throws CaptureError on a malformed list.
[[nodiscard]] std::vector<int> ParseCpuList(const std::string& text);
/// The online CPUs (/sys/devices/system/cpu/online).
[[nodiscard]] std::vector<int> OnlineCpus();

}  // namespace hiltwin::trace_capture
