// `hiltwin run`: the RELbot twin in real time (or on the virtual clock) behind the FPGA link,
// with a QoS verdict, a JSON run report and an optional CSV log (docs/architecture.md, "Contracts").
#include <memory>

#include "commands.h"
#include "hiltwin/runs/twin_run.h"
#include "session_flags.h"

namespace hiltwin::app {
namespace {

Command AddRunCommand(CLI::App& parent) {
  auto flags = std::make_shared<TwinRunFlags>();
  CLI::App* app = parent.add_subcommand(
      "run",
      "Run a twin with a QoS verdict: the RELbot, or any plant with --plant.\n"
      "The twin runs at --rate behind the FPGA link (--io) and is driven by --input played into\n"
      "the emulated board's PWM reader at --input-rate (mock) or by a controller (wire/spidev).\n"
      "Exit: 0 PASS, 2 bad input, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 model fault/internal.\n"
      "No cycle judged, no verdict (NONE): 128+N when stopped by signal N first (130 SIGINT,\n"
      "143 SIGTERM, 129 SIGHUP), 5 when the controller went first.\n"
      "While it runs: SIGINT/SIGTERM/SIGHUP stop it cleanly (report and log written), SIGUSR1\n"
      "pauses (link kept, safe outputs, model frozen, not judged) and SIGUSR2 resumes.");
  AddTwinRunFlags(*app, *flags);
  return {app, [flags] { return RunTwin(TwinRunOptionsFrom(*flags, "run")).exit_code; }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(10, AddRunCommand);

}  // namespace hiltwin::app
