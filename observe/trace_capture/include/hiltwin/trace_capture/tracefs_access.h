#pragma once
/// Whether this process may record the kernel's events from tracefs, and if not, why and what
/// to do. The facts are gathered apart from the judgement, so the judgement (the messages a
/// user sees) is tested with any condition injected, root or not.

#include <string>

namespace hiltwin::trace_capture {

/// What ProbeTracefs found on this machine.
struct TracefsAccessFacts {
  std::string mount_point = "/sys/kernel/tracing";  ///< where tracefs is, or would be mounted
  bool mounted = false;                             ///< tracefs is mounted at mount_point
  bool may_mount = true;                            ///< the caller allowed mounting it
  bool mount_attempted = false;                     ///< this probe tried to mount it
  int mount_errno = 0;                              ///< why mounting failed (0: it did not fail)
  bool writable = false;  ///< mount_point/instances may be written (an instance made)
  int access_errno = 0;   ///< why not (EACCES, EROFS, ...)
};

/// Looks for tracefs in /proc/mounts; when it is not mounted and `may_mount`, mounts it at
/// /sys/kernel/tracing (spdlog::info says so). No other side effect.
[[nodiscard]] TracefsAccessFacts ProbeTracefs(bool may_mount);

/// Empty when the facts allow recording; otherwise what was refused and what to do.
[[nodiscard]] std::string ExplainTracefsAccess(const TracefsAccessFacts& facts);

}  // namespace hiltwin::trace_capture
