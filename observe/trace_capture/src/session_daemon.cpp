// The LTTng session daemon: found through liblttng-ctl, started as `lttng-sessiond
// --daemonize` (no shell) when none answers and the user may, stopped by pid.
#include "session_daemon.h"

#if HILTWIN_WITH_LTTNG

#include <grp.h>
#include <lttng/lttng.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "lttng_text.h"

namespace hiltwin::trace_capture {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

constexpr milliseconds kSpawnTimeout{10'000};  // --daemonize returns once the daemon is ready
constexpr milliseconds kAliveTimeout{5'000};
constexpr milliseconds kExitTimeout{5'000};  // it stops its consumer daemons first
constexpr milliseconds kDaemonPollTick{20};

constexpr const char* kWhatToDo =
    "start one with `lttng-sessiond --daemonize` as root, or join the `tracing` group "
    "(`sudo usermod -aG tracing $USER`, then log in again) so hiltwin may start it";

// Guards the daemon this process started: a session being created must not find it alive
// just before the last session of this process stops it.
std::mutex& DaemonMutex() {
  static std::mutex mutex;
  return mutex;
}

std::weak_ptr<SessionDaemon>& OurDaemon() {
  static std::weak_ptr<SessionDaemon> daemon;
  return daemon;
}

bool InGroup(const char* name) {
  std::vector<char> buffer(16384);
  group entry{};
  group* found = nullptr;
  if (getgrnam_r(name, &entry, buffer.data(), buffer.size(), &found) != 0 || found == nullptr) {
    return false;
  }
  if (getegid() == found->gr_gid) return true;
  const int count = getgroups(0, nullptr);
  std::vector<gid_t> groups(static_cast<std::size_t>(std::max(count, 0)));
  const int filled = getgroups(count, groups.data());
  groups.resize(static_cast<std::size_t>(std::max(filled, 0)));
  return std::find(groups.begin(), groups.end(), found->gr_gid) != groups.end();
}

// Where lttng-sessiond writes its pid: its run directory, /var/run/lttng for root and
// $LTTNG_HOME/.lttng (LTTNG_HOME defaults to HOME) for anyone else.
fs::path PidFile() {
  if (geteuid() == 0) return "/var/run/lttng/lttng-sessiond.pid";
  // Read once on the control side before any thread of ours could change the environment.
  const char* home = std::getenv("LTTNG_HOME");  // NOLINT(concurrency-mt-unsafe)
  if (home == nullptr || *home == '\0')
    home = std::getenv("HOME");  // NOLINT(concurrency-mt-unsafe)
  return fs::path(home != nullptr ? home : "/") / ".lttng" / "lttng-sessiond.pid";
}

std::string CommOf(int pid) {
  std::string comm;
  std::ifstream(fs::path("/proc") / std::to_string(pid) / "comm") >> comm;
  return comm;
}

int DaemonPid() {
  int pid = 0;
  std::ifstream(PidFile()) >> pid;
  return pid > 0 && CommOf(pid) == "lttng-sessiond" ? pid : 0;
}

bool WaitUntil(milliseconds timeout, const auto& done) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(kDaemonPollTick);
  }
  return true;
}

void RunDaemonize() {
  const std::vector<std::string> argv = {"lttng-sessiond", "--daemonize",
                                         // The kernel's events come from tracefs
                                         // (kernel_recorder.h): no LTTng kernel modules.
                                         "--no-kernel"};
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::Capture();
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  kernel_glue::ProcessResult result;
  try {
    result = kernel_glue::RunProcess(argv, options, kSpawnTimeout);
  } catch (const kernel_glue::SpawnError& error) {
    throw CaptureError(std::string("cannot start lttng-sessiond: ") + error.what() +
                       (error.NotFound() ? " (install it: apt-get install lttng-tools)" : ""));
  }
  if (!result.status.Success()) {
    throw CaptureError("`lttng-sessiond --daemonize --no-kernel` failed (" +
                       result.status.Describe() + "): " + result.out + "; " + kWhatToDo);
  }
}

// Starts a daemon and returns its pid (0 when its pid file cannot be found: it then stays
// running, because stopping a process we cannot identify could stop someone else's).
int StartDaemon() {
  RunDaemonize();
  if (!WaitUntil(kAliveTimeout, [] { return lttng_session_daemon_alive() == 1; })) {
    throw CaptureError("started lttng-sessiond, but it did not answer within " +
                       std::to_string(kAliveTimeout.count()) + " ms; " + kWhatToDo);
  }
  const int pid = DaemonPid();
  if (pid == 0) {
    spdlog::warn("started lttng-sessiond, but found no pid in {}: it is left running",
                 PidFile().string());
  } else {
    spdlog::info("started lttng-sessiond (pid {}); it stops when the trace session ends", pid);
  }
  return pid;
}

}  // namespace

bool ProcessGone(int pid) {
  // Reap it if it happens to be our child (it is not, after --daemonize, unless this process
  // is a subreaper), so it does not linger as our zombie.
  ::waitpid(pid, nullptr, WNOHANG);
  if (::kill(pid, 0) != 0 && errno == ESRCH) return true;
  std::ifstream stat(fs::path("/proc") / std::to_string(pid) / "stat");
  std::string line;
  std::getline(stat, line);
  const std::size_t paren = line.rfind(')');
  return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] == 'Z';
}

std::shared_ptr<SessionDaemon> SessionDaemon::Ensure(bool may_start) {
  const std::lock_guard lock(DaemonMutex());
  const int alive = lttng_session_daemon_alive();
  if (alive < 0) throw CaptureError("asking for an LTTng session daemon: " + LttngText(alive));
  if (alive == 1) return OurDaemon().lock();  // ours while a session of ours holds it
  if (!may_start) {
    throw CaptureError(
        std::string("no LTTng session daemon answers (and starting one was not allowed): ") +
        kWhatToDo);
  }
  if (geteuid() != 0 && !InGroup("tracing")) {
    throw CaptureError(
        std::string("no LTTng session daemon answers, and this user may not start one (not "
                    "root, not in the `tracing` group): ") +
        kWhatToDo);
  }
  const int pid = StartDaemon();
  if (pid == 0) return nullptr;  // cannot be identified, so it is not stopped either
  std::shared_ptr<SessionDaemon> daemon(new SessionDaemon(pid));
  OurDaemon() = daemon;
  return daemon;
}

SessionDaemon::~SessionDaemon() {
  const std::lock_guard lock(DaemonMutex());
  // The pid may have been reused if the daemon died on its own: check it still is one.
  if (pid_ <= 0 || ProcessGone(pid_) || CommOf(pid_) != "lttng-sessiond") return;
  ::kill(pid_, SIGTERM);
  if (WaitUntil(kExitTimeout, [this] { return ProcessGone(pid_); })) return;
  spdlog::warn("lttng-sessiond (pid {}) did not exit within {} ms of SIGTERM: killing it", pid_,
               kExitTimeout.count());
  ::kill(pid_, SIGKILL);
  if (!WaitUntil(kExitTimeout, [this] { return ProcessGone(pid_); })) {
    spdlog::warn("lttng-sessiond (pid {}) is still there after SIGKILL", pid_);
  }
}

}  // namespace hiltwin::trace_capture

#endif  // HILTWIN_WITH_LTTNG
