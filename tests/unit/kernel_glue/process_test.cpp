#include "hiltwin/kernel_glue/process.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace hiltwin::kernel_glue {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

ProcessOptions CaptureBoth() {
  ProcessOptions options;
  options.out = OutputTarget::Capture();
  options.err = OutputTarget::Capture();
  return options;
}

// A child scripted by the shell; the helper itself never uses one.
ProcessResult Sh(const std::string& script, const ProcessOptions& options = CaptureBoth(),
                 std::optional<milliseconds> timeout = milliseconds(30'000)) {
  return RunProcess({"sh", "-c", script}, options, timeout);
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

fs::path TempPath(const std::string& tag) {
  return fs::temp_directory_path() / ("hiltwin_process_" + std::to_string(::getpid()) + "_" + tag);
}

bool Reaped(pid_t pid) { return ::kill(pid, 0) != 0 && errno == ESRCH; }

TEST(Process, ExitCodesAreReportedAsExits) {
  const ProcessResult ok = RunProcess({"true"});  // found on PATH
  EXPECT_TRUE(ok.status.exited);
  EXPECT_EQ(ok.status.code, 0);
  EXPECT_EQ(ok.status.signal, 0);
  EXPECT_FALSE(ok.status.timed_out);
  EXPECT_TRUE(ok.status.Success());

  const ProcessResult three = Sh("exit 3");
  EXPECT_TRUE(three.status.exited);
  EXPECT_EQ(three.status.code, 3);
  EXPECT_EQ(three.status.signal, 0);
  EXPECT_FALSE(three.status.Success());
  EXPECT_EQ(three.status.Describe(), "exit code 3");
}

TEST(Process, DeathBySignalIsNotAnExitCode) {
  const ProcessResult killed = Sh("kill -USR1 $$; sleep 5");
  EXPECT_FALSE(killed.status.exited);
  EXPECT_EQ(killed.status.code, -1);
  EXPECT_EQ(killed.status.signal, SIGUSR1);
  EXPECT_FALSE(killed.status.timed_out);
  EXPECT_FALSE(killed.status.Success());
  EXPECT_EQ(killed.status.Describe(), "killed by signal " + std::to_string(SIGUSR1) + " (SIGUSR1)");
}

// 1 MB on stderr first, then 1 MB on stdout: a reader that waits for stdout's end before
// reading stderr would leave the child blocked on a full stderr pipe forever.
TEST(Process, CapturesLargeOutputOnBothStreamsWithoutDeadlock) {
  const ProcessResult r = Sh("yes e | head -c 1000000 >&2; yes o | head -c 1000000");
  ASSERT_FALSE(r.status.timed_out);
  EXPECT_TRUE(r.status.Success()) << r.status.Describe();
  ASSERT_EQ(r.out.size(), 1'000'000u);
  ASSERT_EQ(r.err.size(), 1'000'000u);
  EXPECT_EQ(r.out.substr(0, 6), "o\no\no\n");
  EXPECT_EQ(r.err.substr(0, 6), "e\ne\ne\n");
  EXPECT_EQ(r.out.find('e'), std::string::npos);
  EXPECT_EQ(r.err.find('o'), std::string::npos);
}

TEST(Process, OutputGoesToAFileToDevNullOrStaysSeparate) {
  const fs::path log = TempPath("log");
  ProcessOptions to_file;
  to_file.out = OutputTarget::File(log);
  to_file.err = OutputTarget::SameAsStdout();
  const ProcessResult file = Sh("echo out; echo err >&2", to_file);
  EXPECT_TRUE(file.status.Success());
  EXPECT_EQ(Slurp(log), "out\nerr\n");
  EXPECT_EQ(file.out, "");
  EXPECT_EQ(file.err, "");
  fs::remove(log);

  ProcessOptions discard_out;
  discard_out.out = OutputTarget::Discard();
  discard_out.err = OutputTarget::Capture();
  const ProcessResult discarded = Sh("echo out; echo err >&2", discard_out);
  EXPECT_EQ(discarded.out, "");
  EXPECT_EQ(discarded.err, "err\n");
}

TEST(Process, MissingProgramIsTellableFromOtherFailures) {
  try {
    (void)RunProcess({"hiltwin-no-such-program", "--flag"});
    FAIL() << "no SpawnError";
  } catch (const SpawnError& e) {
    EXPECT_TRUE(e.NotFound());
    EXPECT_EQ(e.error_number(), ENOENT);
    EXPECT_EQ(e.program(), "hiltwin-no-such-program");
    EXPECT_STREQ(e.what(), "cannot start hiltwin-no-such-program: not found on PATH");
  }
  try {
    (void)RunProcess({"/no/such/dir/program"});
    FAIL() << "no SpawnError";
  } catch (const SpawnError& e) {
    EXPECT_TRUE(e.NotFound());
    EXPECT_STREQ(e.what(), "cannot start /no/such/dir/program: no such file");
  }
  // A directory cannot be executed: it exists, so it is not "not found".
  try {
    (void)RunProcess({fs::temp_directory_path().string()});
    FAIL() << "no SpawnError";
  } catch (const SpawnError& e) {
    EXPECT_FALSE(e.NotFound());
    EXPECT_EQ(e.error_number(), EACCES);
  }
  // A bad output path is the path's problem, not a missing program.
  ProcessOptions bad_file;
  bad_file.out = OutputTarget::File("/no/such/dir/out.txt");
  try {
    (void)RunProcess({"true"}, bad_file);
    FAIL() << "no SpawnError";
  } catch (const SpawnError& e) {
    EXPECT_FALSE(e.NotFound());
    EXPECT_EQ(e.error_number(), ENOENT);
    EXPECT_NE(std::string(e.what()).find("/no/such/dir/out.txt"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)RunProcess({}), std::invalid_argument);
}

TEST(Process, ChildStartsWithNoBlockedSignals) {
  // A command may block SIGTERM in its own threads; the child must not inherit that.
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  sigset_t old;
  ASSERT_EQ(pthread_sigmask(SIG_BLOCK, &term, &old), 0);
  Process sleeper = Process::Start({"sleep", "30"});
  ASSERT_EQ(pthread_sigmask(SIG_SETMASK, &old, nullptr), 0);
  const ExitStatus status = sleeper.Kill(SIGTERM);
  EXPECT_EQ(status.signal, SIGTERM);
  EXPECT_EQ(sleeper.pid(), -1);
}

TEST(Process, DestroyingAHandleKillsAndReapsItsChild) {
  pid_t pid = -1;
  {
    Process sleeper = Process::Start({"sleep", "30"});
    pid = sleeper.pid();
    ASSERT_GT(pid, 0);
    Process moved = std::move(sleeper);
    EXPECT_EQ(sleeper.pid(), -1);  // NOLINT(bugprone-use-after-move): the moved-from state
    EXPECT_EQ(moved.pid(), pid);
  }
  EXPECT_TRUE(Reaped(pid));
}

TEST(ProcessTiming, TimeoutKillsTheChildAndSaysSo) {
  const auto start = std::chrono::steady_clock::now();
  const ProcessResult r = Sh("echo started; exec sleep 30", CaptureBoth(), milliseconds(300));
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_TRUE(r.status.timed_out);
  EXPECT_FALSE(r.status.exited);
  EXPECT_EQ(r.status.signal, SIGKILL);
  EXPECT_EQ(r.status.Describe(), "timed out and was killed (SIGKILL)");
  EXPECT_EQ(r.out, "started\n");  // what it wrote before the timeout is kept
  EXPECT_GE(elapsed, milliseconds(300));
  EXPECT_LT(elapsed, milliseconds(10'000));

  // The same without capture (waitpid polling instead of poll on pipes).
  const ProcessResult quiet = RunProcess({"sleep", "30"}, {}, milliseconds(200));
  EXPECT_TRUE(quiet.status.timed_out);
  EXPECT_EQ(quiet.status.signal, SIGKILL);
}

TEST(ProcessTiming, AGrandchildHoldingThePipeDoesNotHoldTheWait) {
  const auto start = std::chrono::steady_clock::now();
  const ProcessResult r = Sh("sleep 3 & echo done");
  EXPECT_TRUE(r.status.Success()) << r.status.Describe();
  EXPECT_EQ(r.out, "done\n");
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(2'500));
}

TEST(ProcessTiming, WaitForReturnsNothingWhileRunningThenTheStatus) {
  Process child = Process::Start({"sleep", "0.3"});
  EXPECT_FALSE(child.WaitFor(milliseconds(20)).has_value());
  EXPECT_GT(child.pid(), 0);  // still ours, still running
  const auto status = child.WaitFor(milliseconds(20'000));
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(status->Success());
  EXPECT_EQ(child.pid(), -1);
}

std::atomic<int> g_wait_interruptions{0};
void CountWaitInterruption(int) { g_wait_interruptions.fetch_add(1, std::memory_order_relaxed); }

// Sends SIGUSR2 to the constructing thread every few ms, with a handler installed without
// SA_RESTART, so every blocking call of that thread fails with EINTR; undone on destruction
// (also when the code under test throws).
class Interrupter {
 public:
  Interrupter() : target_(pthread_self()) {
    struct sigaction action {};
    action.sa_handler = CountWaitInterruption;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;  // no SA_RESTART
    EXPECT_EQ(sigaction(SIGUSR2, &action, &old_), 0);
    thread_ = std::thread([this] {
      while (!done_.load()) {
        pthread_kill(target_, SIGUSR2);
        std::this_thread::sleep_for(milliseconds(3));
      }
    });
  }
  ~Interrupter() {
    done_.store(true);
    thread_.join();
    sigaction(SIGUSR2, &old_, nullptr);
  }
  Interrupter(const Interrupter&) = delete;
  Interrupter& operator=(const Interrupter&) = delete;

 private:
  pthread_t target_;
  struct sigaction old_ {};
  std::atomic<bool> done_{false};
  std::thread thread_;
};

// The waits block in waitpid (no capture, no timeout), in poll (capture) and in the sleep
// between waitpid polls (timeout): each must retry after EINTR, not fail or return early.
TEST(ProcessTiming, WaitingSurvivesEintr) {
  ProcessResult blocking;
  ProcessResult captured;
  ProcessResult polled;
  {
    const Interrupter interrupter;
    blocking = RunProcess({"sleep", "0.3"});
    captured = Sh("sleep 0.3; echo end");
    polled = RunProcess({"sleep", "0.3"}, {}, milliseconds(20'000));
  }
  EXPECT_GT(g_wait_interruptions.load(), 10);
  EXPECT_TRUE(blocking.status.Success()) << blocking.status.Describe();
  EXPECT_TRUE(captured.status.Success()) << captured.status.Describe();
  EXPECT_EQ(captured.out, "end\n");
  EXPECT_TRUE(polled.status.Success()) << polled.status.Describe();
}

}  // namespace
}  // namespace hiltwin::kernel_glue
