// `hiltwin trace`: record the twin's run with LTTng (and the kernel's scheduler events with
// --kernel) and write a jitter report that names the cause of each late cycle; or analyse a
// recording or timing log made earlier (--analyze). Flags -> TraceOptions -> trace_run.h; the
// run's flags are read only for a run (--analyze refuses them unread).
#include <memory>
#include <string>

#include "commands.h"
#include "hiltwin/runs/trace_run.h"
#include "session_flags.h"

namespace hiltwin::app {
namespace {

/// --analyze runs nothing, so a run flag beside it is a mistake worth naming.
void RefuseRunFlagsWithAnalyze(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = option->get_name();
    if (option->count() == 0 || name == "--analyze" || name == "--output" || name == "--pid" ||
        name == "--help" || name == "--log-level") {
      continue;
    }
    throw CommandError(ExitCode::kUsage,
                       name +
                           " does not go with --analyze: --analyze reads a recording made "
                           "earlier and runs nothing (drop " +
                           name + ")");
  }
}

Command AddTraceCommand(CLI::App& parent) {
  auto o = std::make_shared<TraceOptions>();
  auto run_flags = std::make_shared<TwinRunFlags>();
  CLI::App* app = parent.add_subcommand(
      "trace",
      "Run a twin as 'hiltwin run' does, inside an LTTng recording, and report its jitter.\n"
      "The jitter report goes into --output DIR: wake-up latency, period jitter, compute and response\n"
      "time (histograms, percentiles), misses and how they cluster, the 10 worst cycles, pictures\n"
      "(PNG, one HTML page) and a Perfetto trace (ui.perfetto.dev opens DIR/perfetto_trace.json).\n"
      "--kernel also records the kernel's scheduler and interrupt events and names the cause of\n"
      "every late cycle (preempted by whom, interrupt, page fault, own compute, invisible).\n"
      "--analyze PATH reports on a recording made earlier: a trace folder (also one recorded by\n"
      "hand with lttng while 'hiltwin run' ran) or a timing log ('hiltwin run --timing-log').\n"
      "Needs an lttng-sessiond (started when none runs and you are root or in group 'tracing').\n"
      "Exit: as 'hiltwin run' (0 PASS, 3 FLAGGED, 4 ABORTED, 5 I/O fault, 1 model fault, 128+N\n"
      "stopped by signal N before any cycle was judged), 2 bad input, 5 when tracing is not\n"
      "possible here or the trace could not be read.");
  AddTwinRunFlags(*app, *run_flags);
  app->add_option("--output", o->output_dir,
                  "folder for the trace and the report (new or empty; with --analyze: where the "
                  "report goes, default the trace folder or FILE.jitter/)");
  app->add_flag("--kernel", o->kernel,
                "also record the kernel's scheduler, interrupt and page-fault events (root, or "
                "tracefs readable) and name the cause of every late cycle");
  app->add_option("--analyze", o->analyze_path,
                  "analyse this trace folder or timing log instead of running");
  app->add_option("--pid", o->analyze_pid,
                  "with --analyze: report on this process of a trace holding several (default: "
                  "the first to start its loop)")
      ->check(CLI::PositiveNumber);
  return {app, [o, run_flags, app] {
            if (o->analyze_path.empty()) {
              if (o->analyze_pid != 0) {
                throw CommandError(ExitCode::kUsage,
                                   "--pid goes with --analyze: a recording made by trace keeps "
                                   "only its own process");
              }
              o->run = TwinRunOptionsFrom(*run_flags, "trace", TraceOutputFiles(o->output_dir));
              return TraceTwin(*o);
            }
            RefuseRunFlagsWithAnalyze(*app);
            return AnalyzeTrace(*o);
          }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(40, AddTraceCommand);

}  // namespace hiltwin::app
