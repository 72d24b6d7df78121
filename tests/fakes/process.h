#pragma once
// Helper processes for integration tests, over kernel_glue's process helper: the test's file
// conventions (a peer's output in FILE and FILE.err) and a result shaped for assertions.

#include <string>
#include <vector>

#include "hiltwin/kernel_glue/process.h"

namespace hiltwin::test {

/// Starts `argv[0]` with `argv`; stdout goes to `output_path` and stderr to `output_path`.err
/// when a path is given. The handle kills and reaps the process if the test ends first.
kernel_glue::Process Spawn(const std::vector<std::string>& argv,
                           const std::string& output_path = "");

/// What a spawned process wrote to `path` (its `output_path`, or that with ".err"); empty when
/// there is no such file.
std::string ReadOutput(const std::string& path);

/// Runs a command to completion, capturing stdout and stderr separately.
struct RunResult {
  int exit_code = -1;  ///< -1 when it timed out (and was killed) or died from a signal
  kernel_glue::ExitStatus status;
  std::string out;
  std::string err;
};
RunResult Run(const std::vector<std::string>& argv, int timeout_ms = 60'000);

}  // namespace hiltwin::test
