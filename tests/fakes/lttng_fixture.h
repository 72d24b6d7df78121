#pragma once
// A real LTTng recording for tests: a private LTTNG_HOME, a session daemon (the one that
// answers, or one started here and stopped again by this fixture alone), a session that records
// chosen events into a trace folder, and the processes it traces. Every LTTng test uses it and
// holds the CTest resource lock `lttng` (hiltwin_add_gtest RESOURCE_LOCK), so one ctest run never
// has two tests starting or stopping the daemon at once. Commands run without a shell, each
// with a timeout; their output is kept for failure messages (CommandLog).

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace hiltwin::test {

class LttngFixture {
 public:
  /// `tag` ([A-Za-z0-9_]) names the session and the home folder, with this process's pid, so
  /// tests of several checkouts running at once on one machine never share a session.
  explicit LttngFixture(const std::string& tag);
  /// Destroys the session; stops the daemon if this fixture started it and no other session
  /// is left on it (another suite may be recording); removes the home folder.
  ~LttngFixture();
  LttngFixture(const LttngFixture&) = delete;
  LttngFixture& operator=(const LttngFixture&) = delete;

  /// True when a session daemon answers, starting one (--no-kernel) if none did; false when
  /// none can run here (the test should skip, quoting CommandLog()).
  [[nodiscard]] bool EnsureDaemon();

  /// What a session records.
  struct SessionOptions {
    std::string events = "hiltwin:*";  ///< user-space event pattern (lttng enable-event)
    bool vpid = true;                  ///< add the vpid context
    /// Non-zero: record into a channel of `subbuffers` sub-buffers of this many bytes (lttng
    /// enable-channel), e.g. so small that a fast emitter overruns it and events are dropped.
    std::uint64_t subbuf_bytes = 0;
    std::uint32_t subbuffers = 2;
    /// Record only the processes RunTraced starts (the session's vpid tracker holds exactly
    /// them): other suites run hiltwin meanwhile, and their events must not mix in.
    bool only_traced = true;
  };

  /// Creates the session writing to `trace_dir`, enables the events (in their own channel if
  /// asked), adds the vpid context if asked, and starts recording.
  [[nodiscard]] bool StartSession(const std::string& trace_dir, const SessionOptions& options);
  /// Runs `argv` to its end while the session records; its pid, or -1 when it did not start,
  /// failed or timed out (the log says which). With `only_traced` the process is held back
  /// until the session tracks its pid, so it is recorded from its first event.
  pid_t RunTraced(const std::vector<std::string>& argv);
  /// Stops recording: the trace on disk is then complete and readable.
  [[nodiscard]] bool StopSession();
  /// Destroys the session (its trace stays on disk), so another can be created; true when
  /// none is left.
  bool DestroySession();

  /// What Record() did.
  struct Recording {
    bool ok = false;          ///< every step succeeded
    std::vector<pid_t> pids;  ///< of the traced commands, in order
  };
  /// StartSession, RunTraced for each command in turn, StopSession, DestroySession; once
  /// more if that failed (root's one daemon may have been stopped by another checkout's tests).
  Recording Record(const std::string& trace_dir,
                   const std::vector<std::vector<std::string>>& commands,
                   const SessionOptions& options);

  /// Runs `lttng ARGS...` with this fixture's home; its exit code (-1: did not end normally).
  int Lttng(const std::vector<std::string>& args);

  [[nodiscard]] const std::filesystem::path& home() const noexcept { return home_; }
  [[nodiscard]] const std::string& session() const noexcept { return session_; }
  /// Every command so far with its output, and the daemon's own output if it was started here.
  [[nodiscard]] std::string CommandLog() const;

 private:
  /// Runs argv under `env LTTNG_HOME=...`; output goes to the log.
  int Run(const std::vector<std::string>& argv, int timeout_ms);
  /// `argv` under `env LTTNG_HOME=...` (env execs it: same pid), written to the command log.
  std::vector<std::string> LoggedCommand(const std::vector<std::string>& argv);
  void StopOwnDaemon();

  std::filesystem::path home_;
  std::string session_;
  std::string log_;
  bool session_created_ = false;
  bool only_traced_ = false;  // of the session started last
  int traced_count_ = 0;      // names each RunTraced's go file
  pid_t own_daemon_pid_ = -1;
};

}  // namespace hiltwin::test
