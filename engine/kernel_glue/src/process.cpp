#include "hiltwin/kernel_glue/process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

extern char** environ;

namespace hiltwin::kernel_glue {
namespace {

using SteadyClock = std::chrono::steady_clock;

// How often a wait with a deadline and no pipes to watch looks at the child again.
constexpr std::chrono::milliseconds kWaitTick{2};
// The longest a captured wait blocks in poll() before it checks whether the child exited
// while something else (a grandchild) still holds a pipe open.
constexpr int kPollTickMs = 50;

std::string ErrnoMessage(int error_number) { return std::strerror(error_number); }

// File descriptors that exist only while a child is being started: the child's ends are
// closed in the parent once posix_spawn returned, whatever happened.
class SpawnFds {
 public:
  SpawnFds() = default;
  SpawnFds(const SpawnFds&) = delete;
  SpawnFds& operator=(const SpawnFds&) = delete;
  ~SpawnFds() {
    for (const int fd : child_fds_) ::close(fd);
    for (const int fd : parent_fds_) {
      if (fd >= 0) ::close(fd);
    }
  }

  // Makes `child_fd` (1 or 2) of the child go to `target`; a capture keeps the pipe's read
  // end for the parent.
  void Route(const std::string& program, const OutputTarget& target, int child_fd,
             posix_spawn_file_actions_t& actions) {
    int fd = -1;
    switch (target.kind) {
      case OutputTarget::Kind::kInherit:
        return;
      case OutputTarget::Kind::kStdout:
        if (child_fd == STDOUT_FILENO) {
          throw std::invalid_argument("stdout cannot be redirected to itself");
        }
        posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, child_fd);
        return;
      case OutputTarget::Kind::kCapture: {
        int ends[2];
        if (::pipe2(ends, O_CLOEXEC) != 0) {
          const int error = errno;
          throw SpawnError(program, error,
                           "cannot start " + program + ": pipe: " + ErrnoMessage(error));
        }
        // Non-blocking on our side, so draining stops at "nothing more for now".
        ::fcntl(ends[0], F_SETFL, O_NONBLOCK);
        parent_fds_[child_fd == STDOUT_FILENO ? 0 : 1] = ends[0];
        fd = ends[1];
        break;
      }
      case OutputTarget::Kind::kDiscard:
        fd = Open(program, "/dev/null");
        break;
      case OutputTarget::Kind::kFile:
        fd = Open(program, target.path);
        break;
    }
    child_fds_.push_back(fd);
    posix_spawn_file_actions_adddup2(&actions, fd, child_fd);
  }

  // Hands the read ends of the capture pipes to the caller (-1 where not captured).
  std::pair<int, int> TakeParentFds() noexcept {
    return {std::exchange(parent_fds_[0], -1), std::exchange(parent_fds_[1], -1)};
  }

 private:
  // Opened here rather than by the child, so a bad path is reported as the path's problem
  // and a missing program is the only ENOENT posix_spawn can return.
  int Open(const std::string& program, const std::filesystem::path& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
      const int error = errno;
      throw SpawnError(program, error,
                       "cannot open " + path.string() + " for the output of " + program + ": " +
                           ErrnoMessage(error));
    }
    return fd;
  }

  std::vector<int> child_fds_;
  std::array<int, 2> parent_fds_{-1, -1};
};

std::string SpawnMessage(const std::string& program, int error) {
  const bool has_slash = program.find('/') != std::string::npos;
  if (error == ENOENT) {
    return "cannot start " + program + (has_slash ? ": no such file" : ": not found on PATH");
  }
  if (error == EACCES) return "cannot start " + program + ": permission denied (not executable?)";
  return "cannot start " + program + ": " + ErrnoMessage(error);
}

// The program's file, looked up as execvp would (a name with a slash is taken as it is), and
// checked before the spawn: posix_spawn reports a failed exec only where the C library's
// vfork-style clone lets the child report back, which an emulated arm64 process under
// qemu-user does not (there a missing program "starts" and exits 127). Checking first gives
// the same SpawnError on every machine. Returns the errno of the failure, or 0.
// 0 when `path` is a file this process may execute; otherwise the errno execve would give
// (EACCES for a directory, which access(X_OK) alone lets through).
int ExecutableFile(const std::string& path) {
  if (::access(path.c_str(), X_OK) != 0) return errno;
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return errno;
  return S_ISREG(info.st_mode) ? 0 : EACCES;
}

int ResolveProgram(const std::string& program, std::string& file) {
  if (program.find('/') != std::string::npos) {
    file = program;
    return ExecutableFile(file);
  }
  const char* path = std::getenv("PATH");  // NOLINT(concurrency-mt-unsafe): read only
  std::string_view dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  int error = ENOENT;
  while (true) {
    const auto colon = dirs.find(':');
    const std::string_view dir = dirs.substr(0, colon);  // empty: the current folder
    const std::string candidate = std::string(dir.empty() ? "." : dir) + "/" + program;
    const int why = ExecutableFile(candidate);
    if (why == 0) {
      file = candidate;
      return 0;
    }
    if (why == EACCES) error = EACCES;  // found but not executable: say so, as execvp does
    if (colon == std::string_view::npos) return error;
    dirs.remove_prefix(colon + 1);
  }
}

// Reads what is available on `fd` into `text`; closes it and sets -1 at end of file.
void Drain(int& fd, std::string& text) {
  if (fd < 0) return;
  std::array<char, 65536> buffer;
  for (;;) {
    const ssize_t got = ::read(fd, buffer.data(), buffer.size());
    if (got > 0) {
      text.append(buffer.data(), static_cast<std::size_t>(got));
      continue;
    }
    if (got < 0 && errno == EINTR) continue;
    if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    ::close(fd);  // end of file, or an error that no retry will cure
    fd = -1;
    return;
  }
}

// waitpid(WNOHANG) retried on EINTR; nullopt while the child runs.
std::optional<ExitStatus> ReapIfDone(pid_t pid) {
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) return ExitStatus::FromWaitStatus(status);
    if (done == 0) return std::nullopt;
    if (errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "waitpid " + std::to_string(pid));
    }
  }
}

ExitStatus ReapBlocking(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "waitpid " + std::to_string(pid));
    }
  }
  return ExitStatus::FromWaitStatus(status);
}

int PollTimeoutMs(std::optional<SteadyClock::time_point> deadline) {
  if (!deadline) return kPollTickMs;
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(*deadline - SteadyClock::now());
  return static_cast<int>(std::clamp<std::chrono::milliseconds::rep>(left.count(), 0, kPollTickMs));
}

}  // namespace

std::string ExitStatus::Describe() const {
  if (timed_out) return "timed out and was killed (SIGKILL)";
  if (exited) return "exit code " + std::to_string(code);
  const char* abbrev = sigabbrev_np(signal);
  return "killed by signal " + std::to_string(signal) +
         (abbrev != nullptr ? " (SIG" + std::string(abbrev) + ")" : std::string());
}

ExitStatus ExitStatus::FromWaitStatus(int wait_status) noexcept {
  ExitStatus status;
  if (WIFEXITED(wait_status)) {
    status.exited = true;
    status.code = WEXITSTATUS(wait_status);
  } else if (WIFSIGNALED(wait_status)) {
    status.signal = WTERMSIG(wait_status);
  }
  return status;
}

SpawnError::SpawnError(std::string program, int error_number, const std::string& what,
                       bool not_found)
    : std::runtime_error(what),
      program_(std::move(program)),
      error_number_(error_number),
      not_found_(not_found) {}

Process Process::Start(const std::vector<std::string>& argv, const ProcessOptions& options) {
  if (argv.empty()) throw std::invalid_argument("Process::Start: empty argv");
  const std::string& program = argv.front();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  // The child starts clean: no blocked signals and default handlers, whatever this process
  // (a command that blocks or ignores signals) did to its own.
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  sigfillset(&signals);
  posix_spawnattr_setsigdefault(&attributes, &signals);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

  std::string file;
  if (const int missing = ResolveProgram(program, file); missing != 0) {
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    throw SpawnError(program, missing, SpawnMessage(program, missing), missing == ENOENT);
  }
  SpawnFds fds;
  int error = 0;
  pid_t pid = -1;
  try {
    fds.Route(program, options.out, STDOUT_FILENO, actions);
    fds.Route(program, options.err, STDERR_FILENO, actions);
    std::vector<char*> args;
    args.reserve(argv.size() + 1);
    for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    error = posix_spawn(&pid, file.c_str(), &actions, &attributes, args.data(), environ);
  } catch (...) {
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    throw;
  }
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  // Output files were opened before the spawn (SpawnFds::Open), so an ENOENT from
  // posix_spawn itself can only be the program (removed since ResolveProgram looked).
  if (error != 0) throw SpawnError(program, error, SpawnMessage(program, error), error == ENOENT);
  const auto [out_fd, err_fd] = fds.TakeParentFds();
  return Process(pid, out_fd, err_fd);
}

Process::Process(pid_t pid, int out_fd, int err_fd) noexcept
    : pid_(pid), out_fd_(out_fd), err_fd_(err_fd) {}

Process::Process(Process&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)),
      out_fd_(std::exchange(other.out_fd_, -1)),
      err_fd_(std::exchange(other.err_fd_, -1)),
      out_(std::move(other.out_)),
      err_(std::move(other.err_)) {}

Process& Process::operator=(Process&& other) noexcept {
  if (this != &other) {
    Release();
    pid_ = std::exchange(other.pid_, -1);
    out_fd_ = std::exchange(other.out_fd_, -1);
    err_fd_ = std::exchange(other.err_fd_, -1);
    out_ = std::move(other.out_);
    err_ = std::move(other.err_);
  }
  return *this;
}

Process::~Process() { Release(); }

void Process::Release() noexcept {
  CloseFds();
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  pid_ = -1;
}

void Process::CloseFds() noexcept {
  for (int* fd : {&out_fd_, &err_fd_}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
}

ExitStatus Process::Wait() { return *Await(std::nullopt); }

std::optional<ExitStatus> Process::WaitFor(std::chrono::milliseconds timeout) {
  return Await(SteadyClock::now() + timeout);
}

ExitStatus Process::Kill(int signal) {
  if (pid_ <= 0) throw std::logic_error("Process::Kill: the child was already reaped");
  ::kill(pid_, signal);
  return Wait();
}

ProcessResult Process::TakeResult(const ExitStatus& status) {
  return ProcessResult{status, std::move(out_), std::move(err_)};
}

std::optional<ExitStatus> Process::Await(std::optional<SteadyClock::time_point> deadline) {
  if (pid_ <= 0) throw std::logic_error("Process: the child was already reaped");
  for (;;) {
    // Once the deadline has passed, one more look without blocking, so a child that ended
    // during the last tick is not reported as still running.
    const bool last_look = deadline && SteadyClock::now() >= *deadline;
    std::optional<ExitStatus> status;
    if (out_fd_ >= 0 || err_fd_ >= 0) {
      // Both pipes at once, so a child filling one while we block on the other cannot stall.
      std::array<pollfd, 2> watched{pollfd{out_fd_, POLLIN, 0}, pollfd{err_fd_, POLLIN, 0}};
      const int poll_ms = last_look ? 0 : PollTimeoutMs(deadline);
      if (::poll(watched.data(), watched.size(), poll_ms) < 0 && errno != EINTR) {
        throw std::system_error(errno, std::generic_category(), "poll");
      }
      Drain(out_fd_, out_);
      Drain(err_fd_, err_);
      // EOF on both usually means the child is gone; if a grandchild still holds a pipe,
      // the child's own exit ends the capture (everything it wrote is in the pipe by then).
      status = ReapIfDone(pid_);
      if (status) {
        Drain(out_fd_, out_);
        Drain(err_fd_, err_);
        CloseFds();
      }
    } else {
      status = deadline ? ReapIfDone(pid_) : ReapBlocking(pid_);
    }
    if (status) {
      pid_ = -1;
      return status;
    }
    if (last_look) return std::nullopt;
    if (out_fd_ < 0 && err_fd_ < 0) std::this_thread::sleep_for(kWaitTick);
  }
}

ProcessResult RunProcess(const std::vector<std::string>& argv, const ProcessOptions& options,
                         std::optional<std::chrono::milliseconds> timeout) {
  Process process = Process::Start(argv, options);
  std::optional<ExitStatus> status = timeout ? process.WaitFor(*timeout) : process.Wait();
  if (!status) {
    status = process.Kill(SIGKILL);
    status->timed_out = true;
  }
  return process.TakeResult(*status);
}

}  // namespace hiltwin::kernel_glue
