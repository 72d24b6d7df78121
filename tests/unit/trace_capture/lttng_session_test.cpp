// LttngSession records a real trace: a session of this process, the emitter (a known sequence
// of every hiltwin event) in another, and babeltrace2's text output as a second opinion on
// what reached the disk. Uses a running session daemon if one answers, else starts one (and
// the session must stop exactly that one). Label `integration`, lock `lttng`.
#include "fakes/test_paths.h"
#include "hiltwin/trace_capture/lttng_session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lttng/lttng.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/trace_capture/capture_error.h"

namespace {

namespace fs = std::filesystem;
using hiltwin::kernel_glue::OutputTarget;
using hiltwin::kernel_glue::Process;
using hiltwin::kernel_glue::ProcessOptions;
using hiltwin::trace_capture::CaptureError;
using hiltwin::trace_capture::LttngChannelFigures;
using hiltwin::trace_capture::LttngSession;
using hiltwin::trace_capture::LttngSessionConfig;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr int kCycles = 5000;  // ~0.5 MB of events: fits the buffers however fast they come

// Gone: no such process, or a zombie (it has exited and waits for init to reap it).
bool Gone(int pid) {
  if (::kill(pid, 0) != 0 && errno == ESRCH) return true;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const std::size_t paren = line.rfind(')');
  return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] == 'Z';
}

class LttngSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("hiltwin_lttng_session_" + std::to_string(::getpid()));
    fs::remove_all(base_);
    daemon_was_alive_ = lttng_session_daemon_alive() == 1;
  }
  void TearDown() override { fs::remove_all(base_); }

  [[nodiscard]] LttngSessionConfig Config(const std::string& name) const {
    return LttngSessionConfig{.output_dir = (base_ / name).string(), .rate_hz = 20'000.0};
  }

  // Runs the emitter to its end; its pid, whose events are the ones to count.
  static int RunEmitter(int cycles) {
    ProcessOptions options;
    options.out = OutputTarget::Discard();
    Process emitter = Process::Start({HILTWIN_TRACE_EMITTER, std::to_string(cycles)}, options);
    const int pid = emitter.pid();
    const auto status = emitter.WaitFor(std::chrono::seconds(30));
    EXPECT_TRUE(status && status->Success()) << (status ? status->Describe() : "still running");
    return pid;
  }

  /// What RecordGatedEmitter recorded.
  struct GatedRun {
    int emitter_pid = 0;
    int daemon_pid = 0;
    LttngChannelFigures figures;
  };

  // The emitter started first, waiting for a `go` file; a session for it alone that awaits its
  // registration, as `hiltwin trace` does; then `go`. Every cycle must be in the trace, however
  // late LTTng-UST registers (a process started before, or just after, a fresh daemon).
  [[nodiscard]] GatedRun RecordGatedEmitter(const std::string& name, int cycles) const {
    const fs::path go = base_ / ("go_" + name);
    fs::create_directories(base_);
    ProcessOptions options;
    options.out = OutputTarget::Discard();
    Process emitter =
        Process::Start({HILTWIN_TRACE_EMITTER, std::to_string(cycles), go.string()}, options);
    GatedRun run;
    run.emitter_pid = emitter.pid();  // pid() is -1 once reaped
    LttngSessionConfig config = Config(name);
    config.only_pid = run.emitter_pid;
    config.await_registration = true;
    LttngSession session(config);
    run.daemon_pid = session.daemon_pid();
    std::ofstream(go) << "go\n";
    const auto status = emitter.WaitFor(std::chrono::seconds(30));
    EXPECT_TRUE(status && status->Success()) << (status ? status->Describe() : "still running");
    run.figures = session.Stop();
    return run;
  }

  // hiltwin:cycle events of process `pid` in the trace under `dir`, as babeltrace2 prints them:
  // "... hiltwin:cycle: { cpu_id = 0 }, { vpid = 123 }, { k = 0, ... }". The one context a
  // session adds is vpid: an event with vtid (which costs and nothing reads) fails the test.
  static int CyclesOf(const fs::path& dir, int pid) {
    ProcessOptions options;
    options.out = OutputTarget::Capture();
    options.err = OutputTarget::Capture();
    const auto result = hiltwin::kernel_glue::RunProcess({"babeltrace2", dir.string()}, options,
                                                         std::chrono::seconds(60));
    EXPECT_TRUE(result.status.Success()) << result.err;
    const std::string vpid = "{ vpid = " + std::to_string(pid) + " }";
    std::istringstream lines(result.out);
    int cycles = 0;
    int with_vtid = 0;
    for (std::string line; std::getline(lines, line);) {
      if (line.find("hiltwin:cycle:") == std::string::npos) continue;
      if (line.find(vpid) != std::string::npos) ++cycles;
      if (line.find("vtid = ") != std::string::npos) ++with_vtid;
    }
    EXPECT_EQ(with_vtid, 0) << "cycle events with the vtid context";
    return cycles;
  }

  static bool HasMetadata(const fs::path& dir) {
    if (!fs::exists(dir)) return false;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file() && entry.path().filename() == "metadata") return true;
    }
    return false;
  }

  // After the last session: the daemon a session started is gone, anyone else's still answers.
  void ExpectDaemonHandledRightly(int started_pid) const {
    if (started_pid > 0) {
      EXPECT_TRUE(Gone(started_pid)) << "lttng-sessiond " << started_pid << " still runs";
    } else if (daemon_was_alive_) {
      EXPECT_EQ(lttng_session_daemon_alive(), 1) << "someone else's daemon was stopped";
    }
  }

  fs::path base_;
  bool daemon_was_alive_ = false;
};

TEST_F(LttngSessionTest, RecordsEveryCycleOfTheEmitterWithNothingDiscarded) {
  int daemon_pid = 0;
  {
    LttngSession session(Config("one"));
    EXPECT_EQ(session.started_daemon(), !daemon_was_alive_);
    daemon_pid = session.daemon_pid();
    EXPECT_EQ(daemon_pid > 0, session.started_daemon());
    EXPECT_THAT(session.session_name(), StartsWith("hiltwin-" + std::to_string(::getpid()) + "-"));
    const int emitter = RunEmitter(kCycles);
    const LttngChannelFigures figures = session.Stop();
    EXPECT_EQ(figures.discarded_events, 0U);
    EXPECT_EQ(figures.lost_packets, 0U);
    EXPECT_EQ(figures.subbuf_bytes, 256U * 1024U);  // ChannelSizeFor(20 kHz)
    EXPECT_EQ(figures.subbuf_count, 8U);
    EXPECT_EQ(session.Stop().subbuf_bytes, figures.subbuf_bytes);  // idempotent
    EXPECT_TRUE(HasMetadata(base_ / "one"));
    EXPECT_EQ(CyclesOf(base_ / "one", emitter), kCycles);
  }
  ExpectDaemonHandledRightly(daemon_pid);
}

TEST_F(LttngSessionTest, ASessionForOneProcessRecordsNoOtherProcess) {
  int daemon_pid = 0;
  {
    LttngSessionConfig config = Config("only");
    config.only_pid = static_cast<int>(::getpid());  // this test, which emits nothing
    LttngSession session(config);
    daemon_pid = session.daemon_pid();
    const int emitter = RunEmitter(kCycles / 5);
    session.Stop();
    // Nothing recorded at all (no stream, no trace folder), or nothing of the emitter's.
    if (HasMetadata(base_ / "only")) {
      EXPECT_EQ(CyclesOf(base_ / "only", emitter), 0);
    }
  }
  ExpectDaemonHandledRightly(daemon_pid);
}

// The race `hiltwin trace` has with itself: its process runs before the daemon it starts, so
// LTTng-UST registers late (a retry 5 s on, at worst). Awaiting registration must record the
// process from its first event. (With a daemon already running, registration is immediate and
// this checks only that awaiting it costs nothing.)
TEST_F(LttngSessionTest, AProcessRunningBeforeTheDaemonIsRecordedFromItsFirstEvent) {
  const GatedRun run = RecordGatedEmitter("early", kCycles);
  EXPECT_EQ(run.figures.discarded_events, 0U);
  EXPECT_EQ(CyclesOf(base_ / "early", run.emitter_pid), kCycles);
  ExpectDaemonHandledRightly(run.daemon_pid);
}

TEST_F(LttngSessionTest, AwaitingAProcessThatNeverRegistersSaysSoInsteadOfRecordingNothing) {
  ProcessOptions options;
  options.out = OutputTarget::Discard();
  Process sleeper = Process::Start({"sleep", "30"}, options);  // no LTTng-UST in it
  LttngSessionConfig config = Config("never");
  config.only_pid = sleeper.pid();
  config.await_registration = true;
  config.registration_timeout_ms = 300;
  try {
    LttngSession session(config);
    ADD_FAILURE() << "no CaptureError";
  } catch (const CaptureError& error) {
    EXPECT_THAT(error.what(), HasSubstr("process " + std::to_string(sleeper.pid()) +
                                        " did not register with the session daemon within 300 ms"));
  }
  sleeper.Kill(SIGKILL);
  // A daemon started for the refused session went with it.
  if (!daemon_was_alive_) {
    EXPECT_NE(lttng_session_daemon_alive(), 1);
  }
}

TEST_F(LttngSessionTest, ASecondSessionKeepsTheDaemonWhileTheFirstEnds) {
  int daemon_pid = 0;
  {
    std::optional<LttngSession> first(std::in_place, Config("first"));
    LttngSession second(Config("second"));
    EXPECT_NE(first->session_name(), second.session_name());
    EXPECT_EQ(second.daemon_pid(), first->daemon_pid());  // one daemon, shared
    daemon_pid = second.daemon_pid();
    first.reset();  // destroyed while the second records: the daemon must stay
    ASSERT_EQ(lttng_session_daemon_alive(), 1);
    const int emitter = RunEmitter(kCycles / 5);
    EXPECT_EQ(second.Stop().discarded_events, 0U);
    EXPECT_EQ(CyclesOf(base_ / "second", emitter), kCycles / 5);
    EXPECT_FALSE(HasMetadata(base_ / "first") && CyclesOf(base_ / "first", emitter) > 0);
  }
  ExpectDaemonHandledRightly(daemon_pid);
  {
    // And once more after all ended, with a daemon started afresh, gated as `hiltwin trace`
    // is: CI once recorded none of a process started just after a fresh daemon (not seen in 70
    // runs here, 40 of them beside stress-ng), and what this block checks is the daemon's
    // lifecycle, not that race.
    const GatedRun run = RecordGatedEmitter("third", 100);
    EXPECT_EQ(CyclesOf(base_ / "third", run.emitter_pid), 100);
    daemon_pid = run.daemon_pid;
  }
  ExpectDaemonHandledRightly(daemon_pid);
}

TEST_F(LttngSessionTest, WithoutADaemonAndNotAllowedToStartOneSaysWhatToDo) {
  if (daemon_was_alive_) GTEST_SKIP() << "a session daemon answers on this machine";
  LttngSessionConfig config = Config("refused");
  config.may_start_daemon = false;
  try {
    LttngSession session(config);
    ADD_FAILURE() << "no CaptureError";
  } catch (const CaptureError& error) {
    EXPECT_THAT(error.what(), HasSubstr("no LTTng session daemon answers"));
    EXPECT_THAT(error.what(), HasSubstr("start one with `lttng-sessiond --daemonize` as root, or "
                                        "join the `tracing` group"));
  }
  EXPECT_NE(lttng_session_daemon_alive(), 1);  // and none was started
}

}  // namespace
