#pragma once
/// An LTTng recording session for the `hiltwin` provider, driven through liblttng-ctl (the
/// library the `lttng` command is built on; no shell-outs): a reachable session daemon (started
/// when none answers and the user may), a session writing CTF into a folder, a user-space
/// channel sized for the loop's rate, the hiltwin:* events with vpid/vtid context. Control side
/// only: it allocates and blocks freely, never on the loop thread.

#include <cstdint>
#include <string>

namespace hiltwin::trace_capture {

struct LttngSessionConfig {
  std::string output_dir;     ///< the CTF trace goes under it (created when missing)
  double rate_hz = 4000.0;    ///< the loop's rate: sizes the channel's sub-buffers
  /// Start an lttng-sessiond when none answers (root, or a member of the `tracing` group).
  bool may_start_daemon = true;
};

/// What the tracer says about the channel after the run.
struct LttngChannelFigures {
  std::uint64_t discarded_events = 0;  ///< events dropped because the buffers were full
  std::uint64_t lost_packets = 0;
  std::uint64_t subbuf_bytes = 0;      ///< the channel's sizing, for the report
  std::uint64_t subbuf_count = 0;
};

class LttngSession {
 public:
  /// Everything above, then starts tracing. Throws CaptureError (capture_error.h) with what
  /// to do when the daemon is unreachable and cannot be started, or a session call fails.
  explicit LttngSession(const LttngSessionConfig& config);
  /// Stop() when still recording; stops the daemon this object started.
  ~LttngSession();
  LttngSession(const LttngSession&) = delete;
  LttngSession& operator=(const LttngSession&) = delete;

  /// Stops tracing, waits until the trace is complete on disk, reads the channel's figures and
  /// destroys the session. Idempotent (later calls return the same figures).
  LttngChannelFigures Stop();

  [[nodiscard]] const std::string& session_name() const noexcept { return name_; }
  /// Whether this object started the session daemon (and so will stop it).
  [[nodiscard]] bool started_daemon() const noexcept { return daemon_pid_ > 0; }

 private:
  std::string name_;
  int daemon_pid_ = 0;
  bool stopped_ = false;
  LttngChannelFigures figures_;
};

}  // namespace hiltwin::trace_capture
