#pragma once
/// An LTTng recording session for the `hiltwin` provider, driven through liblttng-ctl (the
/// library the `lttng` command is built on; no shell-outs): a reachable session daemon (started
/// when none answers and the user may), a session writing CTF into a folder, a user-space
/// channel sized for the loop's rate, the hiltwin:* events with the vpid context. Control side
/// only: it allocates and blocks freely, never on the loop thread.

#include <cstdint>
#include <memory>
#include <string>

namespace hiltwin::trace_capture {

struct LttngSessionConfig {
  std::string output_dir;   ///< the CTF trace goes under it (created when missing)
  double rate_hz = 4000.0;  ///< the loop's rate: sizes the channel's sub-buffers
  /// Start an lttng-sessiond when none answers (root, or a member of the `tracing` group).
  bool may_start_daemon = true;
  /// Record only this process's events (0: every process of the user). `hiltwin trace` passes
  /// its own pid, so other hiltwin processes running meanwhile stay out of its trace.
  int only_pid = 0;
  /// With only_pid: wait (up to registration_timeout_ms) until that process has registered
  /// with the daemon before recording. A process that was running before the daemon started
  /// registers late (LTTng-UST retries after 5 s), and the events it fires meanwhile are lost:
  /// `hiltwin trace` traces itself, so it waits. The process must link LTTng-UST.
  bool await_registration = false;
  /// LTTng-UST's 5 s retry, with margin.
  int registration_timeout_ms = 12'000;
};

/// What the tracer says about the channel after the run.
struct LttngChannelFigures {
  std::uint64_t discarded_events = 0;  ///< events dropped because the buffers were full
  std::uint64_t lost_packets = 0;
  std::uint64_t subbuf_bytes = 0;  ///< the channel's sizing, for the report
  std::uint64_t subbuf_count = 0;
};

/// How the session's user-space channel is sized for a loop rate (ChannelSizeFor).
struct LttngChannelSize {
  std::uint64_t subbuf_bytes = 0;     ///< a power of two
  std::uint64_t subbuf_count = 0;     ///< a power of two
  std::uint32_t switch_timer_us = 0;  ///< a sub-buffer goes to the consumer at least this often
};

/// Bytes of one hiltwin:cycle event in the channel, rounded up: payload, header and the vpid
/// context.
inline constexpr std::uint64_t kCycleEventBytes = 80;

/// The channel for a loop at `rate_hz` (one hiltwin:cycle per cycle; the rarer events are a
/// small fraction): sub-buffers of the next power of two of 0.1 s of events, at least 256 KiB,
/// 8 of them, a 100 ms switch timer. Pure, so its arithmetic is tested on its own.
[[nodiscard]] LttngChannelSize ChannelSizeFor(double rate_hz);

/// A session daemon this process started, shared by its sessions (src/session_daemon.h).
class SessionDaemon;

class LttngSession {
 public:
  /// Everything above, then starts tracing. Throws CaptureError (capture_error.h) with what
  /// to do when the daemon is unreachable and cannot be started, or a session call fails.
  explicit LttngSession(const LttngSessionConfig& config);
  /// Stop() when still recording; the last session of this process to use a daemon the
  /// process started stops that daemon (SIGTERM, waiting for it to exit).
  ~LttngSession();
  LttngSession(const LttngSession&) = delete;
  LttngSession& operator=(const LttngSession&) = delete;

  /// Stops tracing, waits until the trace is complete on disk, reads the channel's figures and
  /// destroys the session. Idempotent (later calls return the same figures).
  LttngChannelFigures Stop();

  [[nodiscard]] const std::string& session_name() const noexcept { return name_; }
  /// Whether this process started the session daemon this session uses (and so stops it
  /// when the last of its sessions is destroyed).
  [[nodiscard]] bool started_daemon() const noexcept { return daemon_ != nullptr; }
  /// That daemon's pid; 0 when the daemon was already running (it is left alone).
  [[nodiscard]] int daemon_pid() const noexcept;

 private:
  std::shared_ptr<SessionDaemon> daemon_;  // null: someone else's daemon, never stopped here
  std::string name_;
  bool stopped_ = false;
  LttngChannelFigures figures_;
};

}  // namespace hiltwin::trace_capture
