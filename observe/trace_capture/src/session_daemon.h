#pragma once
// Finding, starting and stopping the LTTng session daemon (liblttng-ctl builds only).

#include <memory>
#include <string>

#include "hiltwin/trace_capture/lttng_session.h"

namespace hiltwin::trace_capture {

/// A session daemon this process started. Sessions of this process share it (a second
/// session started while the first runs must not lose its daemon when the first ends); the
/// last one to let go stops exactly that daemon (SIGTERM, then waits for it to exit).
class SessionDaemon {
 public:
  /// Makes sure a session daemon answers. Returns the one this process started (shared), or
  /// null when someone else's answers (never stopped here). Starts `lttng-sessiond
  /// --daemonize` when none answers and `may_start` and the user is root or in `tracing`;
  /// otherwise throws CaptureError saying what to do.
  [[nodiscard]] static std::shared_ptr<SessionDaemon> Ensure(bool may_start);

  ~SessionDaemon();
  SessionDaemon(const SessionDaemon&) = delete;
  SessionDaemon& operator=(const SessionDaemon&) = delete;

  [[nodiscard]] int pid() const noexcept { return pid_; }

 private:
  explicit SessionDaemon(int pid) noexcept : pid_(pid) {}
  int pid_;
};

/// Whether `pid` is gone: no such process, or a zombie (it has exited; its reaper is not us).
[[nodiscard]] bool ProcessGone(int pid);

}  // namespace hiltwin::trace_capture
