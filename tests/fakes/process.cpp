#include "fakes/process.h"

#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace hiltwin::test {

kernel_glue::Process Spawn(const std::vector<std::string>& argv, const std::string& output_path) {
  kernel_glue::ProcessOptions options;
  if (!output_path.empty()) {
    options.out = kernel_glue::OutputTarget::File(output_path);
    options.err = kernel_glue::OutputTarget::File(output_path + ".err");
  }
  return kernel_glue::Process::Start(argv, options);
}

std::string ReadOutput(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

RunResult Run(const std::vector<std::string>& argv, int timeout_ms) {
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::Capture();
  options.err = kernel_glue::OutputTarget::Capture();
  auto result = kernel_glue::RunProcess(argv, options, std::chrono::milliseconds(timeout_ms));
  return RunResult{result.status.exited ? result.status.code : -1, result.status,
                   std::move(result.out), std::move(result.err)};
}

}  // namespace hiltwin::test
