// `hiltwin hil`'s run (hiltwin/runs/hil_run.h): the closed HiL loop on one machine. Starts the
// twin (`hiltwin run`) and the controller (`hiltwin ecs`) as two real processes on a fresh wire,
// lets them find each other (either may be first), waits for both, reads both run reports back
// and prints one combined summary; exits with the worse of the two exit codes. No shared memory
// is left behind.
#include "hiltwin/runs/hil_run.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/relbot/config_error.h"
#include "hiltwin/relbot/encoder_reading.h"
#include "hiltwin/relbot/input_profile.h"
#include "hiltwin/relbot/relbot_params.h"
#include "hiltwin/relbot/setpoint_profile.h"
#include "hiltwin/runs/command.h"
#include "hiltwin/runs/hil_report.h"
#include "hiltwin/runs/session_assembly.h"

namespace hiltwin::app {
namespace {

namespace fs = std::filesystem;
using kernel_glue::Process;

/// The twin runs this much longer than the ECS, so the ECS's finish ends the pair (the twin
/// then stops with peer_stopped) and the tracking error covers the whole profile.
constexpr double kTwinExtraS = 2.0;
/// After one side ended, how long the other may take to notice before it is told to stop.
constexpr auto kPeerGrace = std::chrono::seconds(3);

/// What each side leaves in the work folder: <side>.json, <side>.csv (with --log-dir), <side>.out.
constexpr const char* kReport = ".json";
constexpr const char* kLog = ".csv";
constexpr const char* kOutput = ".out";

std::string SideFile(const fs::path& dir, const std::string& side, const char* suffix) {
  return (dir / (side + suffix)).string();
}

/// One side's telemetry flags: its own namespace under --namespace; the page on the twin only;
/// --accept-commands to both sides, this pair's own processes, when hil was given it. False
/// when the side gets no telemetry.
bool AddTelemetry(std::vector<std::string>& argv, const telemetry::TelemetryOptions& t,
                  const char* side, bool serves_web) {
  if (t.specs.empty() && (t.web.empty() || !serves_web)) return false;
  for (const std::string& spec : t.specs) argv.insert(argv.end(), {"--telemetry", spec});
  if (t.accept_commands) argv.emplace_back("--accept-commands");
  argv.insert(argv.end(), {"--namespace", t.ns + "/" + side, "--telemetry-rate", Num(t.rate_hz)});
  if (serves_web && !t.web.empty()) argv.insert(argv.end(), {"--web", t.web});
  return true;
}

void AddRules(std::vector<std::string>& argv, const std::vector<std::string>& qos,
              const std::optional<double>& max_miss_pct,
              const std::optional<std::string>& on_violation) {
  for (const std::string& rule : qos) argv.insert(argv.end(), {"--qos", rule});
  if (max_miss_pct) argv.insert(argv.end(), {"--max-miss-pct", Num(*max_miss_pct)});
  if (on_violation) argv.insert(argv.end(), {"--on-violation", *on_violation});
}

std::vector<std::string> TwinArgv(const HilRunOptions& o, const std::string& wire,
                                  const fs::path& dir) {
  std::vector<std::string> argv = {"/proc/self/exe",
                                   "run",
                                   "--io",
                                   wire,
                                   "--rate",
                                   Num(o.twin_rate_hz),
                                   "--input-rate",  // the ECS's: the twin checks it follows
                                   Num(o.ecs_rate_hz),
                                   "--duration",
                                   Num(o.duration_s + kTwinExtraS),
                                   "--wait-peer",
                                   Num(o.wait_peer_s),
                                   "--clock",
                                   o.clock,
                                   "--no-progress",
                                   "--report",
                                   SideFile(dir, "twin", kReport)};
  if (!o.log_dir.empty()) argv.insert(argv.end(), {"--log", SideFile(dir, "twin", kLog)});
  if (!o.config_path.empty()) argv.insert(argv.end(), {"--config", o.config_path});
  AddRules(argv, o.twin_qos, o.twin_max_miss_pct, o.on_violation);
  // The twin serves the page, so it sends the controller's setpoint too (it has no other way
  // to know it): the page draws it beside the robot.
  if (AddTelemetry(argv, o.telemetry, "twin", true) && o.mode == "closedloop") {
    argv.insert(argv.end(), {"--show-setpoint", o.setpoint});
  }
  argv.insert(argv.end(), o.twin_args.begin(), o.twin_args.end());
  return argv;
}

std::vector<std::string> EcsArgv(const HilRunOptions& o, const std::string& wire,
                                 const fs::path& dir) {
  std::vector<std::string> argv = {"/proc/self/exe",
                                   "ecs",
                                   "--io",
                                   wire,
                                   "--rate",
                                   Num(o.ecs_rate_hz),
                                   "--duration",
                                   Num(o.duration_s),
                                   "--mode",
                                   o.mode,
                                   "--wait-peer",
                                   Num(o.wait_peer_s),
                                   "--clock",
                                   o.clock,
                                   "--no-progress",
                                   "--report",
                                   SideFile(dir, "ecs", kReport)};
  if (o.mode == "closedloop") {
    argv.insert(argv.end(), {"--setpoint", o.setpoint});
  } else {
    argv.insert(argv.end(), {"--input", o.input});
  }
  if (!o.log_dir.empty()) argv.insert(argv.end(), {"--log", SideFile(dir, "ecs", kLog)});
  if (!o.controller.empty()) argv.insert(argv.end(), {"--controller", o.controller});
  if (!o.controller_map_path.empty()) {
    argv.insert(argv.end(), {"--controller-map", o.controller_map_path});
  }
  if (!o.gains_path.empty()) argv.insert(argv.end(), {"--gains", o.gains_path});
  if (!o.config_path.empty()) argv.insert(argv.end(), {"--config", o.config_path});
  AddRules(argv, o.ecs_qos, o.ecs_max_miss_pct, o.on_violation);
  AddTelemetry(argv, o.telemetry, "controller", false);
  argv.insert(argv.end(), o.ecs_args.begin(), o.ecs_args.end());
  return argv;
}

/// A started side and how it ended.
struct Child {
  const char* name;
  Process process;
  std::optional<kernel_glue::ExitStatus> status;
  std::optional<std::chrono::steady_clock::time_point> told_to_stop;
};

Child Start(const char* name, const std::vector<std::string>& argv, const fs::path& dir) {
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::File(SideFile(dir, name, kOutput));
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  return Child{name, Process::Start(argv, options), std::nullopt, std::nullopt};
}

void Poll(Child& child) {
  if (!child.status) child.status = child.process.WaitFor(std::chrono::milliseconds(0));
}

/// The signal that asks a side to stop: SIGTERM, unless SIGTERM is what stopped `hil`. A
/// signal to the whole process group (Ctrl-C, a closed terminal's SIGHUP, `kill -TERM -PGID`)
/// reaches the sides too, and their stop handlers are one-shot: the same signal again from
/// here would kill them with their reports unwritten.
int ForwardedStopSignal() noexcept {
  return kernel_glue::StopSignal() == SIGTERM ? SIGINT : SIGTERM;
}

/// Asks a side to stop (report and log written); kills it when it has not stopped kPeerGrace
/// later.
void Stop(Child& child, const char* why) {
  const auto now = std::chrono::steady_clock::now();
  if (!child.told_to_stop) {
    std::fprintf(stderr, "\nhiltwin hil: stopping the %s (%s)\n", child.name, why);
    ::kill(child.process.pid(), ForwardedStopSignal());
    child.told_to_stop = now;
  } else if (now - *child.told_to_stop > kPeerGrace) {
    std::fprintf(stderr, "\nhiltwin hil: the %s did not stop; killing it\n", child.name);
    child.status = child.process.Kill(SIGKILL);
  }
}

/// Waits for both sides. A stop signal is passed on; a side that outlives its peer by more
/// than kPeerGrace is told to stop.
void WaitForBoth(Child& twin, Child& ecs, double duration_s, bool progress) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  std::optional<Clock::time_point> first_end;
  Clock::time_point shown{};
  while (!twin.status || !ecs.status) {
    // 10 ms: a lockstep pair runs 12 s of closed loop in about 0.15 s, so a coarser poll
    // would add most of a whole run to the command's time.
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    Poll(twin);
    Poll(ecs);
    if (!first_end && (twin.status || ecs.status)) first_end = Clock::now();
    const bool overdue = first_end && Clock::now() - *first_end > kPeerGrace;
    for (Child* child : {&twin, &ecs}) {
      if (child->status) continue;
      if (kernel_glue::StopRequested()) {
        const std::string why =
            std::string("hil got ") + kernel_glue::StopSignalName(kernel_glue::StopSignal());
        Stop(*child, why.c_str());
      }
      if (overdue) Stop(*child, "its peer ended and it did not follow");
    }
    if (progress && Clock::now() - shown >= std::chrono::milliseconds(100)) {
      shown = Clock::now();
      const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
      std::fprintf(stderr, "\r  hil: %.1f s of about %.1f s; twin %s, ECS %s   ", elapsed_s,
                   duration_s, twin.status ? "ended" : "running", ecs.status ? "ended" : "running");
      std::fflush(stderr);
    }
  }
  if (progress) std::fputc('\n', stderr);
}

/// A side that did not pass shows its own output, so the cause is on the screen.
void ShowOutputOf(const Child& child, const fs::path& dir) {
  const int code = ExitCodeOf(*child.status);
  if (code == 0 || code == 3) return;
  std::ifstream file(SideFile(dir, child.name, kOutput));
  std::string line;
  std::fprintf(stderr, "hiltwin hil: the %s ended with %s; its output:\n", child.name,
               child.status->Describe().c_str());
  while (std::getline(file, line)) std::fprintf(stderr, "  %s| %s\n", child.name, line.c_str());
}

/// Whether the ECS reads the twin's encoders often enough (relbot/encoder_reading.h): said
/// before the pair starts and kept in the combined report.
std::vector<std::string> PairWarnings(const HilRunOptions& o) {
  RelbotParams params = DefaultRelbotParams();
  try {
    if (!o.config_path.empty()) params = LoadRelbotParams(o.config_path);
  } catch (const ConfigError& e) {
    ThrowUsage(e.what());
  }
  return EncoderReadingWarnings(
      {o.ecs_rate_hz, o.twin_rate_hz, TopCountsPerSecond(params), "--ecs-rate"});
}

}  // namespace

std::vector<NamedFile> HilFiles(const HilRunOptions& o) {
  std::vector<NamedFile> files = {
      ProfileFile("--setpoint", o.setpoint, BuiltinSetpointNames()),
      ProfileFile("--input", o.input, BuiltinProfileNames()),
      {"--controller-map", o.controller_map_path, false},
      {"--gains", o.gains_path, false},
      {"--config", o.config_path, false},
      {"--report", o.report_path, true}};
  if (o.log_dir.empty()) return files;  // a fresh temporary folder: nothing there to clobber
  for (const char* side : {"twin", "ecs"}) {
    for (const char* suffix : {kReport, kLog, kOutput}) {
      files.push_back({"--log-dir", SideFile(o.log_dir, side, suffix), true});
    }
  }
  return files;
}

int RunHil(const HilRunOptions& o) {
  const std::string& name = o.wire;
  const std::string wire = "wire:" + name;
  // Before anything is created: a stop signal from here on ends the pair cleanly, never
  // leaving a half-made report or work folder (docs/reliability.md, row M13).
  kernel_glue::InstallStopSignalHandlers();
  const std::vector<std::string> warnings = PairWarnings(o);  // exit 2 before anything exists
  // First: the report may go into it. The two processes' output, reports and logs go here.
  const WorkFolder dir(o.log_dir, "--log-dir", "hiltwin-hil");
  ReportFile report_file(o.report_path);
  std::printf("hiltwin hil: twin at %s Hz and ECS at %s Hz (%s) on %s for %s s, %s\n",
              Num(o.twin_rate_hz).c_str(), Num(o.ecs_rate_hz).c_str(), o.mode.c_str(), wire.c_str(),
              Num(o.duration_s).c_str(),
              o.clock == "virtual" ? "in lockstep on one virtual clock" : "in real time");
  std::fflush(stdout);
  PrintWarnings("hil", warnings);
  Child twin = Start("twin", TwinArgv(o, wire, dir.path()), dir.path());
  Child ecs = Start("ecs", EcsArgv(o, wire, dir.path()), dir.path());
  WaitForBoth(twin, ecs, o.duration_s, !o.no_progress && isatty(STDERR_FILENO) == 1);
  io::WireBus::Unlink(name);  // both are gone: nothing may be left in /dev/shm
  ShowOutputOf(twin, dir.path());
  ShowOutputOf(ecs, dir.path());
  HilResult result =
      CombineHil(wire, o.mode,
                 HilSide{"twin", *twin.status, ReadReportFile(SideFile(dir.path(), "twin", kReport))},
                 HilSide{"ecs", *ecs.status, ReadReportFile(SideFile(dir.path(), "ecs", kReport))});
  result.warnings = warnings;
  std::fputs(FormatHilSummary(result).c_str(), stdout);
  std::fflush(stdout);
  return report_file.WriteAtEnd(ToJson(result).dump(2) + '\n', "hil", result.exit_code);
}

}  // namespace hiltwin::app
