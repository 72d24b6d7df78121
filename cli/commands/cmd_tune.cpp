// `hiltwin tune`: measure this machine, recommend the twin's update rate (thesis §3.8.2,
// method 2) and validate it with runs like thesis Table 5.1 (docs/tuning.md). Thin: flags ->
// TuneOptions (typed, read once) -> RunTune -> one TuneReport -> text, JSON, plot.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "hiltwin/tuning/tuning_report.h"
#include "commands.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/runs/output_files.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/tune.h"
#include "session_flags.h"

namespace hiltwin::app {
namespace {

struct TuneCommandOptions {
  TuneOptions tune;  ///< every flag but --clock, whose text is read in RunTuneCommand
  std::string clock = "realtime";
  bool json = false;
  std::string report_path;
  std::string plot_path;
  bool no_progress = false;
};

/// A bar redrawn in place on a terminal; one line per step otherwise (logs, CI).
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
  ~ProgressBar() {
    if (enabled_ && tty_ && drawn_) std::fputc('\n', stderr);
  }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void Show(double fraction, const std::string& what) {
    if (!enabled_) return;
    constexpr int kWidth = 24;
    const int filled = static_cast<int>(std::lround(fraction * kWidth));
    const std::string bar = std::string(static_cast<std::size_t>(filled), '#') +
                            std::string(static_cast<std::size_t>(kWidth - filled), '-');
    std::fprintf(stderr, "%shiltwin tune: [%s] %3d %% %-52s%s", tty_ ? "\r" : "", bar.c_str(),
                 static_cast<int>(std::lround(fraction * 100.0)), what.c_str(), tty_ ? "" : "\n");
    std::fflush(stderr);
    drawn_ = true;
  }

 private:
  bool enabled_;
  bool tty_;
  bool drawn_ = false;
};

/// Checks output paths before minutes of measuring, so a typo fails first.
void CheckOutputPath(const std::string& path, const char* flag) {
  if (path.empty()) return;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    ThrowUsage(std::string(flag) + " " + path + ": the folder " + parent.string() +
          " does not exist; create it or write elsewhere");
  }
}

/// Every file tune reads and writes, for CheckFilesDistinct.
std::vector<NamedFile> TuneFiles(const TuneCommandOptions& o) {
  return {ProfileFile("--input", o.tune.input, BuiltinProfileNames()),
          {"--config", o.tune.config_path, false},
          {"--report", o.report_path, true},
          {"--plot", o.plot_path, true}};
}

int RunTuneCommand(const TuneCommandOptions& flags) {
  TuneCommandOptions o = flags;
  o.tune.clock = ClockKindOf(flags.clock);
  CheckTuneOptions(o.tune);
  CheckFilesDistinct(TuneFiles(o));
  // Made now (a bad path fails before minutes of measuring), written whole at the end.
  ReportFile report_file(o.report_path);
  CheckOutputPath(o.plot_path, "--plot");
  analysis::TuneReport report;
  {
    ProgressBar bar(!o.no_progress);
    report = RunTune(
        o.tune, [&bar](double fraction, const std::string& what) { bar.Show(fraction, what); });
  }
  if (o.json) {
    std::printf("%s\n", analysis::ToJson(report).dump(2).c_str());
  } else {
    std::fputs(analysis::FormatTuneText(report).c_str(), stdout);
  }
  std::fflush(stdout);
  report_file.Write(analysis::ToJson(report).dump(2) + '\n');
  if (!o.plot_path.empty()) {
    try {
      analysis::WriteTunePlotHtml(report, o.plot_path);
    } catch (const std::runtime_error& e) {
      throw CommandError(ExitCode::kIo, std::string("--plot: ") + e.what());
    }
  }
  const analysis::Recommendation& rec = report.recommendation;
  if (rec.recommended_hz < o.tune.controller_rate_hz) {
    std::fprintf(stderr,
                 "hiltwin tune: this machine's timing allows at most %.0f Hz (%s), below the "
                 "controller's %g Hz: the twin cannot answer every controller sample; prepare "
                 "the machine (hiltwin doctor) or lower --controller-rate\n",
                 rec.recommended_hz, analysis::ToString(rec.deciding_bound),
                 o.tune.controller_rate_hz);
    return static_cast<int>(ExitCode::kFlagged);
  }
  for (const analysis::CandidateResult& c : report.candidates) {
    if (c.recommended && c.qos_verdict != "PASS") {
      std::fprintf(stderr,
                   "hiltwin tune: the recommended %.0f Hz did not pass its own validation run "
                   "(%s, %.3f %% misses); use the highest passing rate or prepare the machine "
                   "(hiltwin doctor)\n",
                   c.rate_hz, c.qos_verdict.c_str(), c.miss_pct);
      return static_cast<int>(ExitCode::kFlagged);
    }
  }
  return static_cast<int>(ExitCode::kPass);
}

void AddTuneFlags(CLI::App& app, TuneCommandOptions& o) {
  TuneOptions& t = o.tune;
  app.add_option("--controller-rate", t.controller_rate_hz,
                 "rate in Hz at which the controller samples the twin (the ECS; the thesis's "
                 "runs at 1000)")
      ->capture_default_str();
  app.add_option("--tolerance-m", t.tolerance_m,
                 "RMS wheel-position error (m) allowed against the reference, as the controller "
                 "sees it")
      ->capture_default_str();
  app.add_option("--candidates", t.candidates_hz,
                 "rates in Hz to validate, ascending, comma-separated (the recommendation is "
                 "added)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--validate-seconds", t.validate_seconds,
                 "length of each validation run and of the error window")
      ->capture_default_str();
  app.add_option("--latency-seconds", t.latency_seconds,
                 "real clock: length of the wake-up latency run at each candidate")
      ->capture_default_str();
  app.add_option("--clock", o.clock,
                 "realtime, or virtual: validation in virtual time with the measured (or "
                 "injected) costs charged to every cycle")
      ->check(CLI::IsMember({"realtime", "virtual"}))
      ->capture_default_str();
  app.add_option("--inject-compute-us", t.inject_compute_us,
                 "virtual clock: the model step's cost instead of measuring it");
  app.add_option("--inject-overhead-us", t.inject_overhead_us,
                 "virtual clock: the loop's own cost per cycle instead of measuring it");
  app.add_option("--inject-latency-us", t.inject_latency_us,
                 "virtual clock: the wake-up latency of every sleep (default 0)");
}

void AddOutputFlags(CLI::App& app, TuneCommandOptions& o) {
  TuneOptions& t = o.tune;
  app.add_option("--priority", t.priority, "SCHED_FIFO priority of the runs (0: none)")
      ->capture_default_str();
  app.add_option("--cpu", t.cpus, "pin the runs' loop to these CPUs");
  app.add_option("--input", t.input, "input profile of the runs and the reference")
      ->capture_default_str();
  app.add_option("--config", t.config_path, "RELbot parameter file (TOML)");
  app.add_option("--integrator", t.integrator, "euler | rk2 | rk4")->capture_default_str();
  app.add_flag("--json", o.json, "print the JSON report on stdout instead of the text");
  app.add_option("--report", o.report_path, "also write the JSON report to this file");
  app.add_option("--plot", o.plot_path,
                 "write a self-contained HTML page: miss % and RMS error against rate, log axes");
  app.add_flag("--no-progress", o.no_progress, "no progress bar on stderr");
}

Command AddTuneCommand(CLI::App& parent) {
  auto o = std::make_shared<TuneCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "tune",
      "Recommend the twin's update rate and validate it (thesis §3.8.2, Table 5.1).\n"
      "Measures the model step, the loop's overhead and the wake-up latency, recommends 75 %\n"
      "of 1/(overhead + compute) clamped to 4-10x --controller-rate and raised to the accuracy\n"
      "bound (lowest rate within --tolerance-m) where timing allows, then runs every candidate.\n"
      "Exit: 0 done, 2 bad input, 3 the recommended rate is below --controller-rate or failed\n"
      "its validation run, 5 I/O.");
  AddTuneFlags(*app, *o);
  AddOutputFlags(*app, *o);
  return {app, [o] { return RunTuneCommand(*o); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(45, AddTuneCommand);

}  // namespace hiltwin::app
