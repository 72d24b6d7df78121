#include "fakes/lttng_fixture.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <exception>
#include <fstream>
#include <iterator>
#include <optional>
#include <system_error>
#include <thread>

#include "hiltwin/kernel_glue/process.h"

namespace hiltwin::test {
namespace {

namespace fs = std::filesystem;

constexpr int kLttngTimeoutMs = 30'000;
constexpr int kTracedTimeoutMs = 60'000;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Gone, or a zombie (its parent, not us, reaps it): either way it no longer serves.
bool ProcessGone(pid_t pid) {
  if (::kill(pid, 0) != 0) return true;
  const std::string stat = ReadFile("/proc/" + std::to_string(pid) + "/stat");
  const std::size_t paren = stat.rfind(')');
  return paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] == 'Z';
}

}  // namespace

LttngFixture::LttngFixture(const std::string& tag)
    : home_(fs::temp_directory_path() /
            ("hiltwin_lttng_" + tag + "_" + std::to_string(::getpid()))),
      session_("hiltwin_" + tag + "_" + std::to_string(::getpid())) {
  fs::remove_all(home_);
  fs::create_directories(home_);
}

LttngFixture::~LttngFixture() {
  try {
    DestroySession();
    StopOwnDaemon();
    std::error_code error;
    fs::remove_all(home_, error);
  } catch (const std::exception&) {
    // A destructor must not throw; a failed clean-up leaves a folder in /tmp at worst.
  }
}

std::vector<std::string> LttngFixture::LoggedCommand(const std::vector<std::string>& argv) {
  std::vector<std::string> command = {"env", "LTTNG_HOME=" + home_.string()};
  command.insert(command.end(), argv.begin(), argv.end());
  log_ += "$";
  for (const std::string& word : argv) log_ += " " + word;
  log_ += "\n";
  return command;
}

int LttngFixture::Run(const std::vector<std::string>& argv, int timeout_ms) {
  const std::vector<std::string> command = LoggedCommand(argv);
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::Capture();
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  try {
    const kernel_glue::ProcessResult result =
        kernel_glue::RunProcess(command, options, std::chrono::milliseconds(timeout_ms));
    log_ += result.out;
    if (!result.status.Success()) log_ += "(" + result.status.Describe() + ")\n";
    return result.status.exited ? result.status.code : -1;
  } catch (const kernel_glue::SpawnError& e) {
    log_ += std::string("(cannot start: ") + e.what() + ")\n";
    return -1;
  }
}

int LttngFixture::Lttng(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {"lttng"};
  argv.insert(argv.end(), args.begin(), args.end());
  return Run(argv, kLttngTimeoutMs);
}

bool LttngFixture::EnsureDaemon() {
  if (Lttng({"list"}) == 0) return true;
  // --daemonize closes its standard streams; its output before that goes to a file, never to
  // a pipe it would hold open.
  std::vector<std::string> command = {"env", "LTTNG_HOME=" + home_.string(), "lttng-sessiond",
                                      "--daemonize", "--no-kernel"};
  log_ += "$ lttng-sessiond --daemonize --no-kernel\n";
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::File(home_ / "sessiond.log");
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  try {
    const kernel_glue::ProcessResult result =
        kernel_glue::RunProcess(command, options, std::chrono::milliseconds(kLttngTimeoutMs));
    if (!result.status.Success()) {
      log_ += "(" + result.status.Describe() + ")\n";
      return false;
    }
  } catch (const kernel_glue::SpawnError& e) {
    log_ += std::string("(cannot start: ") + e.what() + ")\n";
    return false;
  }
  // Its pid now, not at the end: by then another suite may run a daemon of its own. The file
  // is under /var/run/lttng for root and $LTTNG_HOME/.lttng otherwise.
  for (const fs::path& pid_file :
       {fs::path("/var/run/lttng/lttng-sessiond.pid"), home_ / ".lttng" / "lttng-sessiond.pid"}) {
    std::ifstream in(pid_file);
    pid_t pid = 0;
    if (in >> pid && pid > 0) {
      own_daemon_pid_ = pid;
      break;
    }
  }
  return Lttng({"list"}) == 0;
}

void LttngFixture::StopOwnDaemon() {
  if (own_daemon_pid_ <= 0) return;
  // Another suite (another checkout's ctest) may have found our daemon and still record on it.
  std::vector<std::string> list = {"env", "LTTNG_HOME=" + home_.string(), "lttng", "--mi", "xml",
                                   "list"};
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::Capture();
  options.err = kernel_glue::OutputTarget::Discard();
  const kernel_glue::ProcessResult sessions =
      kernel_glue::RunProcess(list, options, std::chrono::milliseconds(kLttngTimeoutMs));
  if (sessions.out.find("<session>") != std::string::npos) {
    log_ += "(left the daemon running: another session is on it)\n";
    return;
  }
  ::kill(own_daemon_pid_, SIGTERM);
  // Wait for it to go, so a following test does not find a daemon that is dying.
  for (int i = 0; i < 200 && !ProcessGone(own_daemon_pid_); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  own_daemon_pid_ = -1;
}

bool LttngFixture::StartSession(const std::string& trace_dir, const SessionOptions& options) {
  if (Lttng({"create", session_, "--output=" + trace_dir}) != 0) return false;
  session_created_ = true;
  std::vector<std::string> channel;  // the default channel unless asked otherwise
  if (options.subbuf_bytes != 0) {
    channel = {"--channel=test"};
    if (Lttng({"enable-channel", "--userspace", "--session=" + session_,
               "--subbuf-size=" + std::to_string(options.subbuf_bytes),
               "--num-subbuf=" + std::to_string(options.subbuffers), "test"}) != 0) {
      return false;
    }
  }
  std::vector<std::string> enable = {"enable-event", "--userspace", "--session=" + session_};
  enable.insert(enable.end(), channel.begin(), channel.end());
  enable.push_back(options.events);
  if (Lttng(enable) != 0) return false;
  if (options.vpid) {
    std::vector<std::string> context = {"add-context", "--userspace", "--session=" + session_,
                                        "--type=vpid"};
    context.insert(context.end(), channel.begin(), channel.end());
    if (Lttng(context) != 0) return false;
  }
  only_traced_ = options.only_traced;
  // `untrack --all` leaves the inclusion set empty: nothing is recorded until RunTraced adds a pid.
  if (only_traced_ &&
      Lttng({"untrack", "--userspace", "--session=" + session_, "--vpid", "--all"}) != 0) {
    return false;
  }
  return Lttng({"start", session_}) == 0;
}

pid_t LttngFixture::RunTraced(const std::vector<std::string>& argv) {
  // `env` (and the holding shell) exec the program, so the pid is the traced process's (its
  // vpid in the trace).
  std::vector<std::string> command = LoggedCommand(argv);
  const fs::path go = home_ / ("go_" + std::to_string(++traced_count_));
  if (only_traced_) {
    // The shell waits for the go file, then becomes the command; its words stay arguments
    // ("$@"), never shell text.
    command.insert(command.begin(), {"sh", "-c",
                                     "while [ ! -e \"$0\" ]; do sleep 0.01; done; exec \"$@\"",
                                     go.string()});
  }
  kernel_glue::ProcessOptions options;
  options.out = kernel_glue::OutputTarget::Capture();
  options.err = kernel_glue::OutputTarget::SameAsStdout();
  try {
    kernel_glue::Process process = kernel_glue::Process::Start(command, options);
    const pid_t pid = process.pid();
    if (only_traced_) {
      const bool tracked = Lttng({"track", "--userspace", "--session=" + session_,
                                  "--vpid=" + std::to_string(pid)}) == 0;
      std::ofstream(go) << "go\n";
      if (!tracked) return -1;  // `process` kills its child as it goes
    }
    const std::optional<kernel_glue::ExitStatus> status =
        process.WaitFor(std::chrono::milliseconds(kTracedTimeoutMs));
    log_ += process.out();
    if (!status || !status->Success()) {
      log_ += "(" + (status ? status->Describe() : std::string("timed out")) + ")\n";
      return -1;
    }
    return pid;
  } catch (const kernel_glue::SpawnError& e) {
    log_ += std::string("(cannot start: ") + e.what() + ")\n";
    return -1;
  }
}

bool LttngFixture::StopSession() { return Lttng({"stop", session_}) == 0; }

bool LttngFixture::DestroySession() {
  if (!session_created_) return true;
  session_created_ = false;
  return Lttng({"destroy", session_}) == 0;
}

LttngFixture::Recording LttngFixture::Record(const std::string& trace_dir,
                                             const std::vector<std::vector<std::string>>& commands,
                                             const SessionOptions& options) {
  // Root shares one daemon with every checkout's tests on the machine; another suite's
  // clean-up may stop it under us (lock `lttng` orders only one ctest run), so a recording
  // that failed is made once more on a daemon that answers.
  Recording recording;
  for (int attempt = 0; attempt < 2 && !recording.ok; ++attempt) {
    if (attempt > 0) {
      log_ += "(recording again)\n";
      DestroySession();
      std::error_code error;
      fs::remove_all(trace_dir, error);
      if (!EnsureDaemon()) break;
    }
    recording = Recording{};
    if (!StartSession(trace_dir, options)) continue;
    bool ran = true;
    for (const std::vector<std::string>& command : commands) {
      const pid_t pid = RunTraced(command);
      ran = ran && pid > 0;
      recording.pids.push_back(pid);
    }
    recording.ok = StopSession() && ran;
  }
  // A test may record several times: each recording's session goes when it is done.
  recording.ok = DestroySession() && recording.ok;
  return recording;
}

std::string LttngFixture::CommandLog() const {
  std::string log = log_;
  const fs::path daemon_log = home_ / "sessiond.log";
  std::error_code error;
  if (fs::exists(daemon_log, error)) log += "--- lttng-sessiond output:\n" + ReadFile(daemon_log);
  return log;
}

}  // namespace hiltwin::test
