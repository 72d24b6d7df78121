// Closed-loop HiL on one machine with two real processes (issue 10): `hiltwin hil` end to end,
// and `hiltwin run` + `hiltwin ecs` side by side on a wire, where a stop, an abort or a crash on
// one side must end the other within a second with a clear message, safe outputs and a report,
// and no shared memory may be left behind. HilCli: wall-clock runs on a shared machine, whose
// verdicts may be FLAGGED (exit 3), so they assert the orchestration, not PASS nor tracking.
// HilLockstep: the tracking judged on `hil --clock virtual` (issue 33), exactly; the rest of
// lockstep is tests/integration/cli/lockstep_cli_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/wire_scratch.h"
#include "hand_started_pair.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

class HilCli : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_FALSE(fs::exists(scratch_.SegmentPath())) << "shared memory left behind: "
                                                     << scratch_.SegmentPath();
  }

  std::string Path(const std::string& name) const { return scratch_.Path(name); }
  std::string Wire() const { return scratch_.Wire(); }

  static hiltwin::test::RunResult Hiltwin(std::vector<std::string> args) {
    args.insert(args.begin(), HILTWIN_BINARY);
    return hiltwin::test::Run(args, 120'000);
  }
  static nlohmann::json ReadJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }
  static std::string ReadFile(const std::string& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  /// Waits until `path` contains `text`; false after `timeout`.
  static bool WaitForText(const std::string& path, const std::string& text,
                          std::chrono::milliseconds timeout) {
    const auto end = Clock::now() + timeout;
    while (Clock::now() < end) {
      if (ReadFile(path).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  /// `hiltwin run` (twin) and `hiltwin ecs` on this test's wire, each with a report; returns
  /// once both have found each other.
  void StartPair(std::vector<std::string> twin_extra = {}, std::vector<std::string> ecs_extra = {}) {
    std::vector<std::string> twin = {HILTWIN_BINARY, "run", "--io", Wire(), "--duration", "30",
                                     "--no-progress", "--report", Path("twin.json")};
    twin.insert(twin.end(), twin_extra.begin(), twin_extra.end());
    std::vector<std::string> ecs = {HILTWIN_BINARY, "ecs", "--io", Wire(), "--duration", "30",
                                    "--no-progress", "--report", Path("ecs.json")};
    ecs.insert(ecs.end(), ecs_extra.begin(), ecs_extra.end());
    twin_.emplace(hiltwin::test::Spawn(twin, Path("twin.out")));
    ecs_.emplace(hiltwin::test::Spawn(ecs, Path("ecs.out")));
    ASSERT_TRUE(WaitForText(Path("twin.out.err"), "is up; starting", std::chrono::seconds(10)))
        << ReadFile(Path("twin.out.err"));
    ASSERT_TRUE(WaitForText(Path("ecs.out.err"), "is up; starting", std::chrono::seconds(10)))
        << ReadFile(Path("ecs.out.err"));
  }
  /// Waits for `process` to end; returns its status and how long after `since` it ended.
  static std::pair<hiltwin::kernel_glue::ExitStatus, double> EndOf(
      hiltwin::kernel_glue::Process& process, Clock::time_point since) {
    const auto status = process.WaitFor(std::chrono::milliseconds(20'000));
    const double after_s = std::chrono::duration<double>(Clock::now() - since).count();
    return {status.value_or(hiltwin::kernel_glue::ExitStatus{}), after_s};
  }

  hiltwin::test::WireScratch scratch_{"hiltest"};
  std::optional<hiltwin::kernel_glue::Process> twin_;
  std::optional<hiltwin::kernel_glue::Process> ecs_;
};

// The tests that judge tracking run the pair in lockstep (hil --clock virtual, issue 33): both
// processes on one virtual time base, so the figures are exact and repeatable and the bounds
// are the thesis's own, with no allowance for a stall of this machine. Their suite is not
// labelled rt.
class HilLockstep : public HilCli {};

/// One encoder count in metres (WheelGeometryOf(DefaultRelbotParams()): 0.0785 mm).
constexpr double kCountM = 7.85e-5;

// Thesis §7.2 and appendix E: the 2.5 m setpoint; each wheel's error stays below 3 mm and the
// run ends without steady-state error.
TEST_F(HilLockstep, ClosedLoopTracksTheThesisSetpointWithinThreeMillimetres) {
  const auto r = Hiltwin({"hil", "--clock", "virtual", "--wire", scratch_.WireName(),
                          "--no-progress", "--report", Path("hil.json"), "--log-dir",
                          Path("logs")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;  // virtual time: no deadline is ever missed
  const auto hil = ReadJson(Path("hil.json"));
  EXPECT_EQ(hil["exit_code"], 0);
  EXPECT_EQ(hil["link_errors"], 0) << hil["link_error_parts"].dump();
  EXPECT_GT(hil["tracking_error_rms_m"].get<double>(), 0.0);
  EXPECT_LT(hil["tracking_error_max_m"]["left"].get<double>(), 3e-3) << hil.dump(1);
  EXPECT_LT(hil["tracking_error_max_m"]["right"].get<double>(), 3e-3);
  EXPECT_LT(hil["tracking_error_rms_m"].get<double>(), 1e-3);
  EXPECT_LT(hil["final_error_m"].get<double>(), kCountM);  // rests on the count nearest 2.5 m
  EXPECT_EQ(hil["ecs"]["clock"], "virtual");
  EXPECT_EQ(hil["twin"]["clock"], "virtual");
  EXPECT_EQ(hil["ecs"]["stop_reason"], "finished");
  EXPECT_EQ(hil["ecs"]["cycles_run"], 12'000);
  EXPECT_EQ(hil["twin"]["stop_reason"], "peer_stopped");
  EXPECT_EQ(hil["twin"]["peer_stopped"], "wire: the ECS finished its run");
  EXPECT_EQ(hil["twin"]["cycles_run"], 48'000);  // stopped at the ECS's 12 s exactly
  EXPECT_EQ(hil["twin"]["peer_absent_cycles"], 0);
  // The twin really drove forward 2.5 m: its last logged wheel positions (the model's, not
  // the encoder's) within one count of it.
  std::ifstream twin_log(Path("logs/twin.csv"));
  std::string header;
  std::string line;
  std::string last;
  std::getline(twin_log, header);
  while (std::getline(twin_log, line)) last = line;
  std::stringstream cells(last);
  std::vector<double> row;
  for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
  ASSERT_GE(row.size(), 5U) << header;
  EXPECT_NEAR(row[3], 2.5, kCountM) << header;  // wheel_left_m
  EXPECT_NEAR(row[4], 2.5, kCountM) << header;  // wheel_right_m
  EXPECT_NE(r.out.find("tracking  max |error| left"), std::string::npos) << r.out;
}

// Thesis §5.2–5.3: the ECS plays `openloop` to the twin and logs duty and measured positions;
// the logged duty replayed into the reference (virtual time, same model) must match the
// twin's positions, with the twin's delay estimated and compensated. In lockstep the delay is
// the loop's own (below one ECS period), the same in every run, and what is left once it is
// compensated is the encoder's quantisation: less than one count.
TEST_F(HilLockstep, OpenLoopTwinMatchesTheReferenceReplayOfTheLoggedDuty) {
  auto r = Hiltwin({"hil", "--clock", "virtual", "--wire", scratch_.WireName(), "--no-progress",
                    "--mode", "openloop", "--duration", "12", "--log-dir", Path("logs")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = Hiltwin({"run", "--clock", "virtual", "--io", "mock", "--input", Path("logs/ecs.csv"),
               "--input-rate", "1000", "--rate", "4000", "--duration", "12", "--no-progress",
               "--log", Path("ref.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = Hiltwin({"assess", "--sim", Path("ref.csv") + ":wheel_right_m", "--exp",
               Path("logs/ecs.csv") + ":wheel_right_m", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto a = nlohmann::json::parse(r.out);
  const double delay_s = a["delay_s"].get<double>();
  EXPECT_GT(delay_s, 0.0) << a.dump(1);  // the twin lags the reference ...
  EXPECT_LT(delay_s, 1e-3);              // ... by less than one ECS period (measured 0.25 ms)
  const double raw_m = a["time_domain"]["e_t"].get<double>();
  const double compensated_m = a["time_domain_compensated"]["e_t"].get<double>();
  EXPECT_LT(compensated_m, raw_m);
  EXPECT_LT(compensated_m, kCountM);  // measured 0.043 mm: the encoder's quantisation
  EXPECT_GE(a["time_domain_compensated"]["eta"].get<double>(), 0.99999);
  EXPECT_GE(a["time_domain"]["eta"].get<double>(), 0.99999);
}

// In real time the pair is not judged on tracking (a stall of a shared machine holds either
// loop): both sides run their cycles at their rates, the twin stops when the controller
// finishes, within a second of it, and the wire's segment is gone.
TEST_F(HilCli, InRealTimeBothSidesRunTheirCyclesAndStopTogether) {
  const auto r = Hiltwin({"hil", "--wire", scratch_.WireName(), "--no-progress", "--duration",
                          "2", "--report", Path("hil.json"), "--log-dir", Path("logs")});
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.out << r.err;
  const auto hil = ReadJson(Path("hil.json"));
  const auto& twin = hil["twin"];
  const auto& ecs = hil["ecs"];
  EXPECT_EQ(twin["clock"], "realtime");
  EXPECT_EQ(ecs["clock"], "realtime");
  EXPECT_EQ(ecs["stop_reason"], "finished");
  EXPECT_EQ(ecs["cycles_run"], 2'000);
  EXPECT_EQ(ecs["log_rows_written"], 2'000);
  EXPECT_EQ(ecs["peer_absent_cycles"], 0);
  EXPECT_EQ(twin["stop_reason"], "peer_stopped");
  EXPECT_EQ(twin["peer_stopped"], "wire: the ECS finished its run");
  // 4 kHz while the controller's 2 s ran (about 8000), well short of its own 4 s.
  EXPECT_GE(twin["cycles_run"].get<int>(), 6'000);
  EXPECT_LT(twin["cycles_run"].get<int>(), 12'000);
  EXPECT_EQ(twin["log_rows_written"], twin["cycles_run"]);
  // The twin followed the controller's finish within a second.
  EXPECT_LT(twin["wall_time_s"].get<double>(), ecs["wall_time_s"].get<double>() + 1.0);
  EXPECT_EQ(twin["outputs_safe"], true);
  EXPECT_EQ(ecs["outputs_safe"], true);
  EXPECT_EQ(hil["link_errors"], 0) << hil["link_error_parts"].dump();
}

TEST_F(HilCli, AKilledControllerEndsTheTwinWithinASecondAsAnIoFault) {
  StartPair();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto killed_at = Clock::now();
  ecs_->Kill(SIGKILL);
  const auto [status, after_s] = EndOf(*twin_, killed_at);
  EXPECT_EQ(status.code, 5) << ReadFile(Path("twin.out.err"));
  EXPECT_LT(after_s, 1.0);
  const auto report = ReadJson(Path("twin.json"));
  EXPECT_EQ(report["stop_reason"], "io_fault");
  EXPECT_NE(report["fault"]["reason"].get<std::string>().find("stopped updating its heartbeat"),
            std::string::npos)
      << report["fault"];
  EXPECT_EQ(report["outputs_safe"], true);
  EXPECT_NE(ReadFile(Path("twin.out.err")).find("I/O fault"), std::string::npos);
}

// Issue 34, "zombie": the controller is killed by a parent that reaps it only after the twin
// has ended (this test), and a zombie still answers kill(pid, 0). The twin ends as above and,
// the controller being dead, it is the last one out: it removes the segment.
TEST_F(HilCli, AKilledControllerItsParentHasNotReapedYetLeavesNoSharedMemory) {
  StartPair();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto killed_at = Clock::now();
  ASSERT_EQ(::kill(ecs_->pid(), SIGKILL), 0);  // not reaped: ecs_ waits for it at the end
  const auto [status, after_s] = EndOf(*twin_, killed_at);
  EXPECT_EQ(status.code, 5) << ReadFile(Path("twin.out.err"));
  EXPECT_LT(after_s, 1.0);
  EXPECT_FALSE(fs::exists(scratch_.SegmentPath()))
      << "the twin left the segment beside its dead, unreaped controller";
  EXPECT_EQ(ecs_->Wait().signal, SIGKILL);
}

TEST_F(HilCli, AStoppedTwinEndsTheControllerCleanlyWithinASecond) {
  StartPair();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto stopped_at = Clock::now();
  twin_->Kill(SIGTERM);
  const auto [status, after_s] = EndOf(*ecs_, stopped_at);
  EXPECT_TRUE(status.code == 0 || status.code == 3) << status.Describe();
  EXPECT_LT(after_s, 1.0);
  const auto report = ReadJson(Path("ecs.json"));
  EXPECT_EQ(report["stop_reason"], "peer_stopped");
  EXPECT_EQ(report["peer_stopped"], "wire: the twin was stopped (signal or stop command)");
  EXPECT_EQ(report["outputs_safe"], true);
  EXPECT_EQ(ReadJson(Path("twin.json"))["stop_reason"], "stop_requested");
}

TEST_F(HilCli, EitherSideMayStartFirst) {
  // The controller first, the twin 1.5 s later: both wait in ready, then run.
  std::vector<std::string> ecs = {HILTWIN_BINARY, "ecs", "--io", Wire(), "--duration", "1",
                                  "--no-progress", "--report", Path("ecs.json")};
  auto ecs_process = hiltwin::test::Spawn(ecs, Path("ecs.out"));
  ASSERT_TRUE(WaitForText(Path("ecs.out.err"), "waiting for the twin on " + Wire(),
                          std::chrono::seconds(10)));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto twin = Hiltwin({"run", "--io", Wire(), "--duration", "3", "--no-progress",
                             "--report", Path("twin.json")});
  const auto ecs_status = ecs_process.Wait();
  EXPECT_TRUE(ecs_status.code == 0 || ecs_status.code == 3) << ReadFile(Path("ecs.out.err"));
  EXPECT_TRUE(twin.exit_code == 0 || twin.exit_code == 3) << twin.err;
  EXPECT_EQ(ReadJson(Path("ecs.json"))["stop_reason"], "finished");
  EXPECT_EQ(ReadJson(Path("ecs.json"))["peer_absent_cycles"], 0);
  EXPECT_EQ(ReadJson(Path("twin.json"))["stop_reason"], "peer_stopped");
}

// Issue 34, 1: README's pair started by hand, each order a few times. The second side comes
// up beside a first side that already waits for it; its INIT exchange used to count it as
// present, so the first started at once and called it dead 250 ms later, while it was still in
// its real-time set-up (most tries on a loaded machine). The long run beside stress-ng, 20 of
// each order, is WireStartUnderLoad (wire_start_load_test.cpp).
TEST_F(HilCli, HandStartedPairsComeUpInEitherOrder) {
  for (int run = 0; run < 6; ++run) {
    const hiltwin::test::HandStartedPair pair{run % 2 == 0, 2.0, 0.3};
    EXPECT_EQ(hiltwin::test::RunHandStartedPair(HILTWIN_BINARY, scratch_,
                                                "pair" + std::to_string(run), pair),
              "")
        << "run " << run;
  }
}

TEST_F(HilCli, AQosAbortOnTheTwinEndsThePairWithExitFour) {
  const auto r = Hiltwin({"hil", "--wire", scratch_.WireName(), "--no-progress", "--duration", "4",
                          "--twin-arg=--on-violation", "--twin-arg=abort",
                          "--twin-arg=--inject-overrun",
                          "--twin-arg=at=4000,count=20,extra-us=600", "--report",
                          Path("hil.json")});
  EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
  const auto hil = ReadJson(Path("hil.json"));
  EXPECT_EQ(hil["twin"]["verdict"], "ABORTED");
  EXPECT_EQ(hil["ecs"]["stop_reason"], "peer_stopped");
  EXPECT_EQ(hil["ecs"]["peer_stopped"], "wire: the twin aborted its run on its QoS policy");
}

TEST_F(HilCli, MismatchedImagesStopAtInitWithTheThesisMessage) {
  const auto r = Hiltwin({"hil", "--wire", scratch_.WireName(), "--no-progress", "--duration", "2",
                          "--ecs-arg=--board-image", "--ecs-arg=icoboard_inverse", "--report",
                          Path("hil.json")});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("Failed to initialise FPGA: found icoboard_inverse"), std::string::npos)
      << r.err;
  const auto hil = ReadJson(Path("hil.json"));
  EXPECT_TRUE(hil["ecs"].is_null());
  EXPECT_EQ(hil["ecs_exit"]["exit_code"], 5);
}

TEST_F(HilCli, AWireNobodyServesCountsDownThenExitsFiveNamingTheTwinsCommand) {
  const auto r = Hiltwin({"ecs", "--io", Wire(), "--wait-peer", "1", "--no-progress",
                          "--report", Path("ecs.json")});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("waiting for the twin on " + Wire() + ": 1 s left"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("no twin came up on " + Wire() + " within 1 s"), std::string::npos);
  EXPECT_NE(r.err.find("start it with: hiltwin run --io " + Wire()), std::string::npos);
  EXPECT_EQ(ReadJson(Path("ecs.json"))["stop_reason"], "io_fault");
}

TEST_F(HilCli, BadGainsAndProfilesExitTwoNamingFileAndLine) {
  std::ofstream(Path("gains.toml")) << "[pid]\nkp_duty_per_m = 60.0\nki_duty_per_m_s = -1\n"
                                       "kd_duty_s_per_m = 1.0\nderivative_filter_s = 0.004\n"
                                       "[output]\nduty_limit = 1.0\n";
  auto r = Hiltwin({"ecs", "--gains", Path("gains.toml"), "--no-progress"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(Path("gains.toml") + ":3"), std::string::npos) << r.err;
  std::ofstream(Path("set.csv")) << "time,left_m,right_m\n0,0,0\n1,abc,0\n";
  r = Hiltwin({"ecs", "--setpoint", Path("set.csv"), "--no-progress"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(Path("set.csv") + ":3"), std::string::npos) << r.err;
  r = Hiltwin({"hil", "--setpoint", Path("set.csv"), "--no-progress"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(Path("set.csv") + ":3"), std::string::npos) << r.err;
  r = Hiltwin({"ecs", "--mode", "openloop", "--input", Path("missing.csv"), "--no-progress"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("missing.csv"), std::string::npos) << r.err;
}

// Issue 34, 4: a /dev/shm without room for the segment (a tmpfs of its own in a mount
// namespace, filled up) used to kill the side with SIGBUS at its first write into
// the mapping (exit 135, an empty report, the segment left behind). The pages are reserved
// before the mapping is used: an I/O error, exit 5, naming the segment and what to do, and
// nothing left behind. LTTng-UST, when built in, keeps two pages of its own in /dev/shm (and
// itself dies of SIGBUS without them): a first hiltwin process makes them before the filling.
TEST(WireShm, AFullDevShmIsAnIoErrorNotABusError) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root for a mount namespace with its own /dev/shm";
  if (!fs::exists("/usr/bin/unshare")) GTEST_SKIP() << "needs unshare (util-linux)";
  hiltwin::test::WireScratch scratch("shm");
  const std::string segment = scratch.SegmentPath();
  const std::string script =
      "mount -t tmpfs -o size=64k tmpfs /dev/shm || exit 99\n"
      "\"$0\" --version >/dev/null\n"
      "cat /dev/zero >/dev/shm/filler 2>/dev/null\n"  // until the file system is full
      "\"$0\" run --io \"$1\" --wait-peer 1 --no-progress --report \"$2\"\n"
      "echo \"exit $?\"\n"
      "if [ -e \"$3\" ]; then echo \"segment left\"; fi\n"
      "if [ -s \"$2\" ]; then echo \"report written\"; fi\n";
  const auto r = hiltwin::test::Run({"/usr/bin/unshare", "-m", "sh", "-c", script,
                                     HILTWIN_BINARY, scratch.Wire(), scratch.Path("r.json"),
                                     segment},
                                    60'000);
  if (r.exit_code == 99) GTEST_SKIP() << "cannot mount a tmpfs here: " << r.err;
  EXPECT_NE(r.out.find("exit 5\n"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("--io " + scratch.Wire() + ": cannot reserve"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(segment), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("segment left"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("report written"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(scratch.Path("r.json")))
      << "an empty report is left where none was written";
}

}  // namespace
