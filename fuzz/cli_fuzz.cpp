// The `hiltwin` command line (cli/): argv goes through the same CLI11 app main.cpp
// builds (BuildCliApp, every subcommand registered) and its parse step only; no command runs.
// CLI11 reports every bad command line as a CLI::ParseError (help and version requests are
// ParseErrors too), which main.cpp turns into exit code 2; anything else escaping the parse
// (a validator or option callback throwing std::invalid_argument, say) would end the process
// as an internal error instead, so it is a finding.
//
// Input: the arguments after "hiltwin", separated by NUL bytes.
#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cli_app.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = [] {
    // A --log-level callback sets spdlog's level; keep the default logger silent anyway.
    spdlog::set_default_logger(spdlog::null_logger_mt("hiltwin"));
    return true;
  }();
  (void)quiet;
  std::vector<std::string> arguments{"hiltwin"};
  std::string current;
  for (const char c : hiltwin::fuzz::AsText(data, size)) {
    if (c == '\0') {
      arguments.push_back(current);
      current.clear();
    } else {
      current.push_back(c);
    }
  }
  if (size > 0) arguments.push_back(current);
  std::vector<char*> argv;
  for (auto& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);

  const auto cli = hiltwin::app::BuildCliApp();
  try {
    cli->app.parse(static_cast<int>(argv.size() - 1), argv.data());
  } catch (const CLI::ParseError&) {
  }
  HILTWIN_FUZZ_UNDOCUMENTED("hiltwin's command line")
  return 0;
}
