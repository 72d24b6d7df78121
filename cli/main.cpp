// The single `hiltwin` binary: parses the command line, runs the chosen subcommand and maps
// every failure to the documented exit codes (docs/architecture.md, "Exit codes").
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <cstdio>
#include <exception>

#include "cli_app.h"
#if defined(HILTWIN_HAS_FPGA_SIM)
#include "hiltwin/fpga_sim/verilated_backend.h"
#endif

namespace {

extern "C" void OnBrokenPipe(int /*signal_number*/) {}

/// `hiltwin run ... | head -1`: once the reader has gone, SIGPIPE's default would kill the
/// process at its next write to stdout, and exit 141 would replace the verdict's code. Caught,
/// the write fails with EPIPE instead, which stdio records and the command ignores: the run,
/// its log, its report and its exit code are untouched. A handler rather than SIG_IGN: a
/// caught signal is reset to its default across exec, so the programs hiltwin starts (gnuplot,
/// lttng-sessiond, hil's two sides) keep the usual behaviour.
void SurviveAClosedPipe() {
  struct sigaction action {};
  action.sa_handler = &OnBrokenPipe;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGPIPE, &action, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  using hiltwin::app::ExitCode;
  // Past a file-size limit (ulimit -f) the kernel sends SIGXFSZ, whose default kills the
  // process mid-run with a core dump. Ignored, the write fails with EFBIG instead: the log ends
  // on its last whole row and the run ends as an I/O fault (exit 5) with its report.
  std::signal(SIGXFSZ, SIG_IGN);
  SurviveAClosedPipe();
#if defined(HILTWIN_HAS_FPGA_SIM)
  hiltwin::fpga_sim::RegisterVerilatedBackend();  // --io verilated: the RTL under Verilator
#endif
  // Non-real-time messages (start-up, warnings, progress of long work) go through spdlog, on
  // stderr so that stdout stays the command's result; nothing logs from inside the loop.
  auto logger = spdlog::stderr_color_mt("hiltwin");
  logger->set_pattern("hiltwin: %^%l%$: %v");
  spdlog::set_default_logger(logger);

  const auto cli = hiltwin::app::BuildCliApp();
  CLI::App& app = cli->app;
  std::vector<hiltwin::app::Command>& commands = cli->commands;

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
