// `hiltwin doctor`: how ready this machine is for real-time runs, one line per check with
// what to do about it. It reports; it does not judge, so it exits 0 whenever it ran.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "hiltwin/kernel_glue/rt_probe.h"
#include "hiltwin/runs/doctor_format.h"

namespace hiltwin::app {
namespace {

struct DoctorOptions {
  bool json = false;
  std::string root = "/";
  int steal_sample_ms = 200;
  bool no_try = false;
};

int RunDoctor(const DoctorOptions& options) {
  kernel_glue::ProbeOptions probe;
  probe.root = options.root;
  probe.steal_sample_ms = options.steal_sample_ms;
  probe.try_privileges = !options.no_try;
  const kernel_glue::ProbeReport report = kernel_glue::RunRtProbe(probe);
  if (options.json) {
    std::printf("%s\n", DoctorJson(report).dump(2).c_str());
  } else {
    std::printf("hiltwin doctor: real-time readiness of this machine%s\n\n%s",
                options.root == "/" ? "" : (" (files under " + options.root + ")").c_str(),
                DoctorText(report).c_str());
    std::printf(
        "See docs/realtime-setup.md for each step. Runs still work with warnings: the "
        "run report records which real-time settings were in effect.\n");
  }
  return static_cast<int>(ExitCode::kPass);
}

Command AddDoctorCommand(CLI::App& parent) {
  auto options = std::make_shared<DoctorOptions>();
  CLI::App* app = parent.add_subcommand(
      "doctor",
      "Check this machine's real-time readiness: preemption, privileges, governor, "
      "isolation, throttling.");
  app->add_flag("--json", options->json,
                "print {checks: [{id, name, value, status, advice}], summary: {ok, warn, bad}} "
                "instead of the table");
  app->add_option("--steal-ms", options->steal_sample_ms,
                  "window in ms over which steal time is sampled from /proc/stat (0: since "
                  "boot only)")
      ->check(CLI::Range(0, 10000))
      ->default_val(200);
  app->add_flag("--no-try", options->no_try,
                "do not try SCHED_FIFO, mlockall and /dev/cpu_dma_latency for real");
  app->add_option("--root", options->root,
                  "read /sys, /proc and /boot below this directory instead of / (to inspect a "
                  "copied tree; privilege tries still act on this process)")
      ->check(CLI::ExistingDirectory)
      ->default_val("/");
  app->footer(
      "Checks, each tried or read without changing the machine: kernel preemption model\n"
      "(PREEMPT_RT?), SCHED_FIFO / mlockall / cpu_dma_latency (really tried on a throwaway\n"
      "thread or briefly, then undone), RLIMIT_RTPRIO / RLIMIT_MEMLOCK, capabilities, CPU\n"
      "governor, isolated CPUs / nohz_full, RT throttling, SMT, clocksource, CPUs online,\n"
      "virtualisation and steal time (sampled over --steal-ms).\n"
      "Each line reads: check, status (ok / WARN / BAD), value, and after '->' what to do.\n\n"
      "Exit code: 0 whenever the checks ran, even with WARN or BAD lines (the doctor reports, "
      "it does not fail a machine); 2 for bad usage; 1 for an internal error. Scripts can "
      "read the verdicts from --json.");
  return Command{app, [options] { return RunDoctor(*options); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(60, AddDoctorCommand);

}  // namespace hiltwin::app
