#pragma once
/// Child processes without a shell: one way to start a program (posix_spawn after a PATH
/// lookup as execvp's), route its output, wait for it with a timeout and tell an exit code
/// from a signal. Used by the doctor's tools, the assess plot (gnuplot), the benchmarks and
/// the integration tests.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace hiltwin::kernel_glue {

/// Where one output stream of a child goes.
struct OutputTarget {
  enum class Kind { kInherit, kCapture, kDiscard, kFile, kStdout };
  Kind kind = Kind::kInherit;
  std::filesystem::path path;  ///< kFile only: created or truncated

  /// The parent's stream (the default).
  [[nodiscard]] static OutputTarget Inherit() { return {}; }
  /// Collected into ProcessResult::out / ::err.
  [[nodiscard]] static OutputTarget Capture() { return {Kind::kCapture, {}}; }
  /// /dev/null.
  [[nodiscard]] static OutputTarget Discard() { return {Kind::kDiscard, {}}; }
  /// A file, created or truncated (mode 0644).
  [[nodiscard]] static OutputTarget File(std::filesystem::path file) {
    return {Kind::kFile, std::move(file)};
  }
  /// For stderr only: wherever stdout goes (2>&1).
  [[nodiscard]] static OutputTarget SameAsStdout() { return {Kind::kStdout, {}}; }
};

/// How to start a child.
struct ProcessOptions {
  OutputTarget out;  ///< the child's stdout
  OutputTarget err;  ///< the child's stderr
};

/// How a child ended.
struct ExitStatus {
  bool exited = false;     ///< it returned from main or called exit
  int code = -1;           ///< the exit code when `exited`, else -1
  int signal = 0;          ///< the signal that ended it when not `exited`, else 0
  bool timed_out = false;  ///< it outlived its timeout and was killed with SIGKILL

  /// Exited with code 0.
  [[nodiscard]] bool Success() const noexcept { return exited && code == 0; }
  /// "exit code 3", "killed by signal 11 (SIGSEGV)", "timed out and was killed (SIGKILL)".
  [[nodiscard]] std::string Describe() const;
  /// From a waitpid() status.
  [[nodiscard]] static ExitStatus FromWaitStatus(int wait_status) noexcept;
};

/// A finished child: how it ended and what it wrote to captured streams.
struct ProcessResult {
  ExitStatus status;
  std::string out;  ///< stdout, when captured
  std::string err;  ///< stderr, when captured
};

/// The child could not be started (nothing ran). `NotFound()` tells a missing program, so a
/// caller can name the package that provides it.
class SpawnError : public std::runtime_error {
 public:
  SpawnError(std::string program, int error_number, const std::string& what,
             bool not_found = false);
  /// argv[0] as given.
  [[nodiscard]] const std::string& program() const noexcept { return program_; }
  /// The errno of the failed step.
  [[nodiscard]] int error_number() const noexcept { return error_number_; }
  /// The program is not on PATH (or the path given does not exist).
  [[nodiscard]] bool NotFound() const noexcept { return not_found_; }

 private:
  std::string program_;
  int error_number_;
  bool not_found_;
};

/// A started child. It owns the pid: destroying a handle whose child is still running kills
/// (SIGKILL) and reaps it, so a failing test never leaves a peer behind.
class Process {
 public:
  /// Starts `argv[0]` (looked up on PATH unless it holds a '/') with `argv`, no shell.
  /// Throws SpawnError when it cannot start, std::invalid_argument for an empty argv.
  [[nodiscard]] static Process Start(const std::vector<std::string>& argv,
                                     const ProcessOptions& options = {});

  Process(Process&& other) noexcept;
  Process& operator=(Process&& other) noexcept;
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process();

  /// The child's pid (-1 once it has been reaped).
  [[nodiscard]] pid_t pid() const noexcept { return pid_; }
  /// Waits until it ends (reading captured output meanwhile) and reaps it.
  ExitStatus Wait();
  /// Waits at most `timeout`; nullopt when it is still running (it keeps running).
  std::optional<ExitStatus> WaitFor(std::chrono::milliseconds timeout);
  /// Sends `signal` and reaps it (e.g. SIGTERM to a peer that stops cleanly).
  ExitStatus Kill(int signal);
  /// Output captured so far (all of it once Wait/WaitFor/Kill returned a status).
  [[nodiscard]] const std::string& out() const noexcept { return out_; }
  /// Stderr captured so far.
  [[nodiscard]] const std::string& err() const noexcept { return err_; }
  /// Moves the captured output out, with the status.
  [[nodiscard]] ProcessResult TakeResult(const ExitStatus& status);

 private:
  Process(pid_t pid, int out_fd, int err_fd) noexcept;
  std::optional<ExitStatus> Await(std::optional<std::chrono::steady_clock::time_point> deadline);
  void CloseFds() noexcept;
  void Release() noexcept;

  pid_t pid_ = -1;
  int out_fd_ = -1;  // read ends of the capture pipes, -1 when not captured or at EOF
  int err_fd_ = -1;
  std::string out_;
  std::string err_;
};

/// Runs `argv` to completion. With a timeout, a child still running after `timeout` is
/// killed (SIGKILL) and the status says `timed_out`. Throws SpawnError when it cannot start.
[[nodiscard]] ProcessResult RunProcess(
    const std::vector<std::string>& argv, const ProcessOptions& options = {},
    std::optional<std::chrono::milliseconds> timeout = std::nullopt);

}  // namespace hiltwin::kernel_glue
