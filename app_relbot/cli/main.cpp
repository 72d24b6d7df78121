// The single `hiltwin` binary: parses the command line, runs the chosen subcommand and maps
// every failure to the documented exit codes (DESIGN.md "Contracts").
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "hiltwin/app_relbot/commands.h"
#if defined(HILTWIN_HAS_FPGA_SIM)
#include "hiltwin/fpga_sim/verilated_backend.h"
#endif

namespace hiltwin::app {

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;  // function-local: safe during static init
  return registry;
}

bool RegisterCommand(int order, CommandFactory factory) {
  CommandRegistry().push_back({order, factory});
  return true;
}

}  // namespace hiltwin::app

int main(int argc, char** argv) {
  using hiltwin::app::ExitCode;
  // Past a file-size limit (ulimit -f) the kernel sends SIGXFSZ, whose default kills the
  // process mid-run with a core dump. Ignored, the write fails with EFBIG instead: the log ends
  // on its last whole row and the run ends as an I/O fault (exit 5) with its report.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{
      "hiltwin: a real-time Hardware-in-the-Loop runtime for digital twins.\n"
      "Runs a plant model behind the plant's own electrical interface, checks every deadline\n"
      "and tells you whether a run can be trusted.",
      "hiltwin"};
  app.require_subcommand(1);
#if defined(HILTWIN_HAS_FPGA_SIM)
  hiltwin::fpga_sim::RegisterVerilatedBackend();  // --io verilated: the RTL under Verilator
#endif
  app.fallthrough();  // --log-level may also follow the command
  app.set_version_flag("--version", "hiltwin 0.1.0");
  app.footer("Run 'hiltwin <command> --help' for the flags of one command.");

  // Non-real-time messages (start-up, warnings, progress of long work) go through spdlog, on
  // stderr so that stdout stays the command's result; nothing logs from inside the loop.
  auto logger = spdlog::stderr_color_mt("hiltwin");
  logger->set_pattern("hiltwin: %^%l%$: %v");
  spdlog::set_default_logger(logger);
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "how much the non-real-time messages say: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.parse_complete_callback(
      [&log_level] { spdlog::set_level(spdlog::level::from_str(log_level)); });

  auto entries = hiltwin::app::CommandRegistry();
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  std::vector<hiltwin::app::Command> commands;
  for (const auto& entry : entries) commands.push_back(entry.factory(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "hiltwin: %s\n", e.what());
    std::fprintf(stderr, "hiltwin: run 'hiltwin --help' or 'hiltwin <command> --help' for usage\n");
    return static_cast<int>(ExitCode::kUsage);
  }

  for (auto& command : commands) {
    if (!command.app->parsed()) continue;
    try {
      return command.run();
    } catch (const hiltwin::app::CommandError& e) {
      std::fprintf(stderr, "hiltwin %s: %s\n", command.app->get_name().c_str(), e.what());
      return static_cast<int>(e.code());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "hiltwin %s: internal error: %s\n", command.app->get_name().c_str(),
                   e.what());
      return static_cast<int>(ExitCode::kInternal);
    }
  }
  return static_cast<int>(ExitCode::kUsage);
}
