#pragma once
// Starting and stopping helper processes for integration tests (posix_spawn, no shell).

#include <sys/types.h>

#include <string>
#include <vector>

namespace hiltwin::test {

/// Starts `argv[0]` with `argv`; stdout/stderr go to `output_path` when not empty. Returns the pid.
pid_t Spawn(const std::vector<std::string>& argv, const std::string& output_path = "");
/// Sends `signal` and reaps the process; returns its wait status.
int KillAndWait(pid_t pid, int signal);
/// Waits up to `timeout_ms` for the process to exit; returns the exit code, or -1 on timeout
/// (the process is then killed) or when it died from a signal.
int WaitExit(pid_t pid, int timeout_ms);

/// Runs a command to completion, capturing stdout and stderr separately.
struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};
RunResult Run(const std::vector<std::string>& argv, int timeout_ms = 60'000);

}  // namespace hiltwin::test
