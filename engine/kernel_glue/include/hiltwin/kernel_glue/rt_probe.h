#pragma once
/// The real-time readiness probe behind `hiltwin doctor`: kernel preemption model, RT
/// privileges, CPU governor, isolation, RT throttling, SMT, clocksource, virtualisation and
/// steal time. Files are read below a root prefix so tests can feed a fake /sys and /proc;
/// a missing or unreadable file gives "unknown" with a warning, never an exception. The probe
/// returns data; how it is shown (table, JSON) is up to the command.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/kernel_glue/os_calls.h"

namespace hiltwin::kernel_glue {

/// How good a finding is for real-time measurement.
enum class CheckStatus { kOk, kWarn, kBad };

/// "ok", "warn", "bad".
[[nodiscard]] std::string_view ToString(CheckStatus status) noexcept;

/// One finding.
struct ProbeCheck {
  std::string id;     ///< stable key for scripts, e.g. "preemption"
  std::string name;   ///< human label, e.g. "preemption model"
  std::string value;  ///< what was found
  CheckStatus status = CheckStatus::kWarn;
  std::string advice;  ///< what to do (empty when nothing is needed, or when not_tried)
  /// A privilege try skipped because ProbeOptions::try_privileges was false: the value is
  /// unknown, and the caller words how to try it.
  bool not_tried = false;
};

/// Where and how to probe.
struct ProbeOptions {
  std::filesystem::path root = "/";  ///< prefix for /sys, /proc, /boot (tests: a temp tree)
  bool try_privileges = true;        ///< really try SCHED_FIFO, mlockall, cpu_dma_latency
  int steal_sample_ms = 200;         ///< window for the steal-time sample (0: since boot only)
  bool run_tools = true;             ///< may run systemd-detect-virt and gzip (root "/" only)
};

/// All findings, in display order.
struct ProbeReport {
  std::vector<ProbeCheck> checks;
  /// How many checks have `status`.
  [[nodiscard]] std::size_t Count(CheckStatus status) const noexcept;
  /// The check with `id`, or nullptr.
  [[nodiscard]] const ProbeCheck* Find(std::string_view id) const noexcept;
};

/// Runs every check. The privilege tries use `os` (SCHED_FIFO on a throwaway thread;
/// mlockall with MCL_ONFAULT then munlockall, skipped when memory is already locked), so a
/// fake can refuse them. Never throws for missing files.
[[nodiscard]] ProbeReport RunRtProbe(const ProbeOptions& options = {},
                                     const OsCalls& os = RealOsCalls());

/// The kernel's preemption model, found as the "preemption" check finds it (the live mode of
/// a PREEMPT_DYNAMIC kernel from debugfs or the boot option, else the kernel config, else
/// uname -v), named as the kernel config names it.
struct KernelPreemption {
  /// "PREEMPT_RT", "PREEMPT" (full), "PREEMPT_LAZY", "PREEMPT_VOLUNTARY", "PREEMPT_NONE",
  /// "PREEMPT_NONE or PREEMPT_VOLUNTARY" (uname -v cannot tell them apart) or "unknown"
  std::string model;
  /// How it was told, e.g. "PREEMPT_DYNAMIC, kernel config default; debugfs not mounted", or
  /// why it is unknown
  std::string source;
};
/// Reads it below `options.root` (runs gzip for /proc/config.gz when `options.run_tools`).
/// Never throws for missing files.
[[nodiscard]] KernelPreemption FindKernelPreemption(const ProbeOptions& options = {});

/// Cumulative CPU time from the aggregate "cpu" line of /proc/stat, in clock ticks.
struct CpuTicks {
  std::uint64_t total = 0;
  std::uint64_t steal = 0;
};

/// Parses the first ("cpu ") line of /proc/stat text; nullopt when absent or malformed.
[[nodiscard]] std::optional<CpuTicks> ParseProcStat(std::string_view proc_stat);

/// Judges steal time from the since-boot figures and a sample window (either may be absent).
[[nodiscard]] ProbeCheck AssessSteal(std::optional<CpuTicks> since_boot,
                                     std::optional<CpuTicks> window_start,
                                     std::optional<CpuTicks> window_end, int window_ms);

}  // namespace hiltwin::kernel_glue
