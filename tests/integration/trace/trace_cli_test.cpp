// End-to-end tests of `hiltwin trace`: the real binary, a real lttng-sessiond (started by the
// command itself when none runs), the kernel's tracefs for --kernel. What is asserted holds on a
// noisy machine: the trace's report must agree with the run's own report exactly (cycles,
// misses) and to the histogram's resolution (percentiles), whatever the timing was; the cause
// test plants a competitor whose name must come out as the cause.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class TraceCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_trace_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static hiltwin::test::RunResult Hiltwin(std::vector<std::string> args, int timeout_ms = 120'000) {
    args.insert(args.begin(), HILTWIN_BINARY);
    return hiltwin::test::Run(args, timeout_ms);
  }

  static json ReadJson(const std::string& path) {
    std::ifstream in(path);
    return json::parse(in);
  }

  /// The trace's report agrees with the run's: same cycles and misses, every percentile within
  /// one bucket of the shared log-linear histogram.
  static void ExpectAgreement(const json& run, const json& jitter) {
    EXPECT_EQ(jitter["cycles"].get<std::uint64_t>(), run["cycles_run"].get<std::uint64_t>());
    EXPECT_EQ(jitter["deadline_misses"].get<std::uint64_t>(),
              run["deadline_misses"].get<std::uint64_t>());
    for (const char* key : {"latency_ns", "compute_ns", "response_ns", "period_jitter_ns"}) {
      for (const char* figure : {"min", "p50", "p99", "p999", "max"}) {
        const auto a = run[key][figure].get<std::int64_t>();
        const auto b = jitter[key][figure].get<std::int64_t>();
        EXPECT_LE(std::llabs(a - b), std::max<std::int64_t>(1, std::max(a, b) / 128))
            << key << " " << figure << ": run " << a << ", trace " << b;
      }
    }
  }

  fs::path dir_;
};

#if defined(HILTWIN_WITH_LTTNG)

TEST_F(TraceCli, ARecordedRunHasTheRunsVerdictAndAReportThatAgreesWithIt) {
  const std::string out = Path("trace");
  const auto r = Hiltwin({"trace", "--output", out, "--duration", "1", "--rate", "4000",
                          "--no-progress", "--report", Path("run.json")});
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.out << r.err;
  const json run = ReadJson(Path("run.json"));
  EXPECT_EQ(run, ReadJson(out + "/run_report.json"));
  const json jitter = ReadJson(out + "/jitter_report.json");
  ExpectAgreement(run, jitter);
  EXPECT_EQ(r.exit_code, run["verdict"] == "PASS" ? 0 : 3);
  EXPECT_EQ(jitter["discarded_events"].get<std::uint64_t>(), 0U);
  for (const char* file : {"jitter_report.txt", "jitter_report.html", "perfetto_trace.json",
                           "jitter_latency_histogram.png"}) {
    EXPECT_TRUE(fs::exists(out + "/" + file)) << file;
  }
  EXPECT_NE(r.out.find("causes were not recorded"), std::string::npos) << r.out;
}

TEST_F(TraceCli, AnalyzeReadsTheRecordingAgainAndSaysTheSame) {
  const std::string out = Path("trace");
  ASSERT_LE(Hiltwin({"trace", "--output", out, "--duration", "0.5", "--no-progress", "--clock",
                     "virtual"})
                .exit_code,
            3);
  const json first = ReadJson(out + "/jitter_report.json");
  const auto again = Hiltwin({"trace", "--analyze", out, "--output", Path("again")});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const json second = ReadJson(Path("again") + "/jitter_report.json");
  EXPECT_EQ(first["cycles"], second["cycles"]);
  EXPECT_EQ(first["deadline_misses"], second["deadline_misses"]);
  EXPECT_EQ(first["latency_ns"], second["latency_ns"]);
}

TEST_F(TraceCli, AnalyzeReadsATraceRecordedByHandWithTheLttngCommand) {
  // What a user does without `hiltwin trace`: their own session around `hiltwin run`.
  const std::string session = "hiltwin_by_hand_" + std::to_string(getpid());
  const std::string out = Path("by_hand");
  const auto lttng = [](std::vector<std::string> args) {
    args.insert(args.begin(), "lttng");
    return hiltwin::test::Run(args, 30'000);
  };
  if (lttng({"list"}).exit_code != 0 &&
      hiltwin::test::Run({"lttng-sessiond", "--daemonize", "--no-kernel"}).exit_code != 0) {
    GTEST_SKIP() << "no lttng-sessiond can run here";
  }
  ASSERT_EQ(lttng({"create", session, "--output=" + out}).exit_code, 0);
  ASSERT_EQ(lttng({"enable-event", "--userspace", "--session=" + session, "hiltwin:*"}).exit_code,
            0);
  // Only the run's own process: other suites run hiltwin meanwhile. The shell writes its pid,
  // waits until it is tracked, then becomes `hiltwin run` (same pid).
  const std::string pid_file = Path("run.pid");
  auto run = hiltwin::test::Spawn(
      {"sh", "-c",
       "echo $$ > '" + pid_file + "'; while [ ! -e '" + pid_file +
           ".go' ]; do sleep 0.05; done; "
           "exec '" + std::string(HILTWIN_BINARY) +
           "' run --duration 0.5 --clock virtual --no-progress --report '" +
           Path("run.json") + "'"},
      Path("run.out"));
  std::string pid;
  for (int i = 0; i < 200 && pid.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ifstream(pid_file) >> pid;
  }
  ASSERT_FALSE(pid.empty());
  ASSERT_EQ(lttng({"track", "--userspace", "--session=" + session, "--vpid=" + pid}).exit_code, 0);
  ASSERT_EQ(lttng({"start", session}).exit_code, 0);
  std::ofstream(pid_file + ".go") << "go\n";
  const auto status = run.WaitFor(std::chrono::seconds(60));
  ASSERT_EQ(lttng({"stop", session}).exit_code, 0);
  ASSERT_EQ(lttng({"destroy", session}).exit_code, 0);
  ASSERT_TRUE(status.has_value());
  ASSERT_TRUE(status->exited && status->code >= 0 && status->code <= 3) << status->Describe();
  const auto analysis = Hiltwin({"trace", "--analyze", out});
  ASSERT_EQ(analysis.exit_code, 0) << analysis.err;
  ExpectAgreement(ReadJson(Path("run.json")), ReadJson(out + "/jitter_report.json"));
}

// The competitor of the cause test: SCHED_FIFO 95 on CPU 1, 3 ms of spinning every 100 ms,
// above the loop's 80, beside a 2 s recording at 4 kHz.
constexpr int kSpinMs = 3;
constexpr int kSleepMs = 97;
constexpr int kTraceSeconds = 2;
constexpr int kRateHz = 4000;
// The cycles the bursts cover: 2 s at 4 kHz, 3 ms in every 100 ms (240).
constexpr std::size_t kHogCycles =
    std::size_t{kTraceSeconds} * kRateHz * kSpinMs / (kSpinMs + kSleepMs);

/// Records `hiltwin trace --kernel` into `out` beside the cause test's competitor (a
/// SCHED_FIFO thread above the loop, on its CPU) and reads its jitter report into `jitter`.
/// Skips when the machine refuses SCHED_FIFO or the kernel's tracer.
void RecordBesideTheHog(const std::string& out, json& jitter) {
  // The hog must outlive the trace's set-up, however slow: beside other tests under ASan the
  // command took 25.7 s, and a hog that ran 20 s had gone before the loop began (CI refused
  // stop 46 on this test). It runs until this test stops it; its limit only bounds it should
  // the test die.
  constexpr int kHogLimitS = 290;
  const std::string hog_out = out + ".hog";
  auto hog = hiltwin::test::Spawn({HILTWIN_HOG, "hiltwin-hog", "1", "95", std::to_string(kSpinMs),
                                   std::to_string(kSleepMs), std::to_string(kHogLimitS)},
                                  hog_out);
  // "ready" once it spins at its priority; it exits 3 when the OS refuses. A loaded machine
  // may take seconds to start it (beside CI builds it took longer than the 1.1 s this waited
  // once, and the test skipped): only a refusal skips.
  std::string word;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (word != "ready" && std::chrono::steady_clock::now() < give_up) {
    if (const auto ended = hog.WaitFor(std::chrono::milliseconds(20))) {
      GTEST_SKIP() << "SCHED_FIFO refused (" << ended->Describe() << "): no competitor";
    }
    std::ifstream ready(hog_out);
    ready >> word;
  }
  ASSERT_EQ(word, "ready") << "the hog did not start within 30 s";
  const auto r =
      hiltwin::test::Run({HILTWIN_BINARY, "trace", "--kernel", "--output", out, "--duration",
                          std::to_string(kTraceSeconds), "--rate", std::to_string(kRateHz), "--cpu",
                          "1", "--priority", "80", "--no-progress"},
                         120'000);
  if (r.exit_code == 5 && r.err.find("--kernel") != std::string::npos) {
    GTEST_SKIP() << "the kernel cannot be recorded here: " << r.err;
  }
  ASSERT_LE(r.exit_code, 4) << r.out << r.err;
  // Still spinning when the trace ended, so it competed for the whole recorded run.
  ASSERT_FALSE(hog.WaitFor(std::chrono::milliseconds(0)).has_value())
      << "the hog ended before the trace did: " << hiltwin::test::ReadOutput(hog_out + ".err");
  hog.Kill(SIGKILL);
  std::ifstream report(out + "/jitter_report.json");
  jitter = json::parse(report);
  ASSERT_TRUE(jitter["kernel_recorded"].get<bool>());
}

/// The class order is the hog's ("preempted" on top) unless the guest itself lost its CPU for
/// longer than a burst (hypervisor steal: one 27 ms stall at 4 kHz leaves 108 catch-up cycles
/// behind it, seen beside five other helpers' builds), or many short unseen stalls add up to
/// more cycles than half the hog's bursts (2026-11-30, a VM whose wake-up latency had risen
/// tenfold: 156 invisible cycles of their own against the hog's 250, beside Chromium tests).
/// The cycles the loop catches up after each burst (on a slower machine more than the burst's
/// own: CI, stop 40, 321 against 232) count with the burst ("backlog behind k=N (preempted by
/// hiltwin-hog ...)"), not as "invisible".
bool TheHostDecidesTheClassOrder(const json& jitter) {
  std::int64_t longest_invisible_ns = 0;
  std::int64_t invisible_own_cycles = 0;
  for (const json& cause : jitter["causes"]) {
    if (cause["class"] != "invisible") continue;
    invisible_own_cycles =
        cause["cycles"].get<std::int64_t>() - cause["backlog_cycles"].get<std::int64_t>();
  }
  for (const json& cycle : jitter["notable"]) {
    if (cycle["cause"]["class"] != "invisible") continue;
    longest_invisible_ns =
        std::max(longest_invisible_ns, cycle["cause"]["duration_ns"].get<std::int64_t>());
  }
  return longest_invisible_ns > std::int64_t{kSpinMs} * 1'000'000 ||
         invisible_own_cycles > static_cast<std::int64_t>(kHogCycles / 2);
}

/// What one recording beside the hog says against the cause test's checks: a line for each
/// check that failed, none when all held. "preempted" is the top class (unless the host
/// decides the order) and the hog its first culprit, covering half its bursts at least and
/// outweighing every other named culprit of every class; the misses it caused name it, with
/// its policy and priority, and the releases caught up after its bursts name it too.
std::vector<std::string> CulpritFindings(const json& jitter) {
  std::vector<std::string> findings;
  const auto finding = [&findings](const std::string& what) { findings.push_back(what); };
  if (jitter["causes"].empty()) return {"no causes recorded"};
  if (!TheHostDecidesTheClassOrder(jitter) && jitter["causes"][0]["class"] != "preempted") {
    finding("top class " + jitter["causes"][0]["class"].get<std::string>() + ", not preempted");
  }
  std::int64_t hog_cycles = 0;
  std::int64_t other_named_max = 0;
  std::string other_named;
  for (const json& cause : jitter["causes"]) {
    if (cause["class"] == "invisible") continue;
    for (const json& culprit : cause["culprits"]) {
      const auto name = culprit["name"].get<std::string>();
      const auto cycles = culprit["cycles"].get<std::int64_t>();
      if (cause["class"] == "preempted" && name.find("hiltwin-hog") != std::string::npos) {
        hog_cycles = cycles;
      } else if (cycles > other_named_max) {
        other_named_max = cycles;
        other_named = name;
      }
    }
  }
  if (hog_cycles < static_cast<std::int64_t>(kHogCycles / 2)) {
    finding("the hog preempted " + std::to_string(hog_cycles) + " cycles, fewer than " +
            std::to_string(kHogCycles / 2));
  }
  if (hog_cycles <= other_named_max) {
    finding("the hog's " + std::to_string(hog_cycles) + " cycles do not outweigh " + other_named +
            "'s " + std::to_string(other_named_max));
  }
  int named = 0;
  int backlog = 0;
  for (const json& cycle : jitter["notable"]) {
    const json& cause = cycle["cause"];
    const auto k = cycle["k"].get<std::uint64_t>();
    if (cause["class"] == "backlog" && cause["inherited"] == "preempted" &&
        cause["thread"] == "hiltwin-hog") {
      ++backlog;
      if (cause["behind_cycle"].get<std::uint64_t>() >= k) {
        finding("cycle " + std::to_string(k) + " is backlog behind a later cycle");
      }
    }
    if (cause["class"] != "preempted" || cause["thread"] != "hiltwin-hog") continue;
    ++named;
    if (cause["policy"] != "SCHED_FIFO" || cause["priority"] != 95 ||
        cause["duration_ns"].get<std::int64_t>() <= 0) {
      finding("cycle " + std::to_string(k) + " names the hog as " + cause.dump());
    }
  }
  if (named == 0) finding("no notable miss names the hog");
  // Each 3 ms burst leaves a dozen releases (at 4 kHz) to catch up.
  if (backlog == 0) finding("no notable miss is backlog behind the hog");
  return findings;
}

TEST_F(TraceCli, KernelNamesACompetingHigherPriorityThreadAsTheCauseOfTheMisses) {
  if (sysconf(_SC_NPROCESSORS_ONLN) < 2) GTEST_SKIP() << "needs two CPUs";
  // CTest runs this test alone (tests/integration/trace/CMakeLists.txt); what it cannot keep
  // out, the hypervisor taking the guest's CPU during the recording, a second recording
  // answers: the checks must hold in one of two, and the first one's findings are printed.
  constexpr int kRecordings = 2;
  std::vector<std::string> findings;
  json jitter;
  for (int recording = 1; recording <= kRecordings; ++recording) {
    RecordBesideTheHog(Path("trace" + std::to_string(recording)), jitter);
    if (IsSkipped() || HasFatalFailure()) return;
    findings = CulpritFindings(jitter);
    if (findings.empty()) return;
    std::string said;
    for (const std::string& line : findings) said += line + "; ";
    std::cout << "recording " << recording << " of " << kRecordings << ": " << said << "\n";
    RecordProperty("recording_" + std::to_string(recording) + "_findings", said);
  }
  for (const std::string& line : findings) ADD_FAILURE() << line;
  ADD_FAILURE() << "the causes of the last recording: " << jitter["causes"].dump();
}

TEST_F(TraceCli, KernelWithoutThePermissionExitsFiveWithTheReasonAndTheFix) {
  // A real unprivileged user, not a mock: setpriv drops to nobody for the one command.
  if (geteuid() != 0) GTEST_SKIP() << "needs root to drop to another user";
  fs::permissions(dir_, fs::perms::all);
  const std::string out = Path("trace");
  const auto r = hiltwin::test::Run({"setpriv", "--reuid=nobody", "--regid=nogroup",
                                     "--clear-groups", HILTWIN_BINARY, "trace", "--kernel",
                                     "--output", out, "--duration", "0.1", "--priority", "0"});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("--kernel"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("root"), std::string::npos) << r.err;  // what to do
  EXPECT_FALSE(fs::exists(out + "/jitter_report.json"));
}

#else

TEST_F(TraceCli, WithoutLttngRecordingSaysSoAndExitsFive) {
  const auto r = Hiltwin({"trace", "--output", Path("trace"), "--duration", "0.1"});
  EXPECT_EQ(r.exit_code, 5);
  EXPECT_NE(r.err.find("--timing-log"), std::string::npos) << r.err;
}

#endif

TEST_F(TraceCli, ATimingLogGivesTheSameReportWithoutLttng) {
  const auto run = Hiltwin({"run", "--duration", "1", "--rate", "4000", "--no-progress",
                            "--timing-log", Path("timing.csv"), "--report", Path("run.json")});
  ASSERT_LE(run.exit_code, 3) << run.err;
  const auto analysis = Hiltwin({"trace", "--analyze", Path("timing.csv")});
  ASSERT_EQ(analysis.exit_code, 0) << analysis.err;
  ExpectAgreement(ReadJson(Path("run.json")),
                  ReadJson(Path("timing.csv.jitter") + "/jitter_report.json"));
  EXPECT_NE(analysis.out.find("causes were not recorded"), std::string::npos);
}

// Issue 35, point 3: a rate the median cycle cannot hold is the cause of the misses, said
// first on the console (the report's first line) and last (a warning after the report). Every
// cycle's step takes 1.2 ms at 1 kHz, so the median compute alone is above the deadline.
TEST_F(TraceCli, AnInfeasibleRateIsSaidFirstAndLastOnTheConsole) {
  const auto run = Hiltwin({"run", "--duration", "0.3", "--rate", "1000", "--priority", "0",
                            "--overrun-policy", "skip", "--inject-overrun", "every=1,extra-us=1200",
                            "--no-progress", "--timing-log", Path("timing.csv")});
  ASSERT_LE(run.exit_code, 3) << run.err;
  const auto analysis = Hiltwin({"trace", "--analyze", Path("timing.csv")});
  ASSERT_EQ(analysis.exit_code, 0) << analysis.err;
  const std::string first = analysis.out.substr(0, analysis.out.find('\n'));
  EXPECT_EQ(first.rfind("INFEASIBLE HERE: the median wake-up latency (", 0), 0U) << analysis.out;
  EXPECT_NE(first.find("above the 1.00 ms deadline: 1000 Hz cannot be kept on this machine"),
            std::string::npos)
      << first;
  EXPECT_NE(first.find("find the rate it holds with `hiltwin tune`"), std::string::npos) << first;
  // The console's last line.
  const std::string last_warning = "warning: " + first + "\n";
  ASSERT_GE(analysis.err.size(), last_warning.size()) << analysis.err;
  EXPECT_EQ(analysis.err.substr(analysis.err.size() - last_warning.size()), last_warning)
      << analysis.err;
  const json report = ReadJson(Path("timing.csv.jitter") + "/jitter_report.json");
  EXPECT_FALSE(report["feasibility"]["feasible"].get<bool>());
  EXPECT_GT(report["feasibility"]["compute_p50_ns"].get<std::int64_t>(), 1'000'000);
}

TEST_F(TraceCli, BadInputExitsTwoNamingTheFileAndThePlace) {
  // A folder with no trace.
  auto r = Hiltwin({"trace", "--analyze", dir_.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(dir_.string()), std::string::npos) << r.err;
  // A path that does not exist.
  r = Hiltwin({"trace", "--analyze", Path("nothing_here")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("nothing_here"), std::string::npos) << r.err;
  // A timing log cut in the middle of its last row.
  ASSERT_LE(Hiltwin({"run", "--duration", "0.05", "--clock", "virtual", "--no-progress",
                     "--timing-log", Path("timing.csv")})
                .exit_code,
            3);
  const auto size = fs::file_size(Path("timing.csv"));
  fs::resize_file(Path("timing.csv"), size - 7);
  r = Hiltwin({"trace", "--analyze", Path("timing.csv")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("timing.csv:207"), std::string::npos) << r.err;  // 6 + header + 200
  // Run flags make no sense beside --analyze.
  r = Hiltwin({"trace", "--analyze", Path("timing.csv"), "--rate", "1000"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--rate"), std::string::npos) << r.err;
  // A process id chooses among a trace's processes: not for a timing log, not for a recording.
  r = Hiltwin({"trace", "--analyze", Path("timing.csv"), "--pid", "42"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("timing log holds one process"), std::string::npos) << r.err;
  r = Hiltwin({"trace", "--output", Path("new"), "--pid", "42", "--duration", "0.1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--pid goes with --analyze"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("new")));
}

TEST_F(TraceCli, ARecordingIntoAFolderThatHoldsFilesIsRefusedBeforeAnythingRuns) {
  std::ofstream(Path("old.txt")) << "keep me\n";
  const auto r = Hiltwin({"trace", "--output", dir_.string(), "--duration", "0.1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("already holds files"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(Path("old.txt")));
}

}  // namespace
