// Lockstep (issue 33): `--clock virtual` on a wire runs the twin (`hiltwin run`) and the
// controller (`hiltwin ecs`) as two real processes on one virtual time base shared through the
// wire's segment; `hiltwin hil --clock virtual` starts both. What the issue asks, each checked
// on values:
// - exact and repeatable: five `hil --clock virtual` runs beside a CPU hog give byte-identical
//   logs and reports apart from wall_time_s, the one wall-clock field (LockstepHil);
// - the closed loop's tracking figures are exactly those of the in-process virtual rig
//   (tests/unit/app/in_process_hil.h, as tests/unit/app/closed_loop_test.cpp runs it);
// - a hand-started pair works in either start order and runs exactly what hil runs; a side on
//   the other clock is refused (LockstepPair);
// - a clean stop on either side ends the other with peer_stopped at an exactly predicted
//   virtual instant (LockstepStop);
// - a peer that is killed, hangs (SIGSTOP) or never comes ends the other side as an I/O fault
//   (exit 5), outputs safe, a report, within 1 s of the event (LockstepFault, label rt: the
//   only wall-clock bounds here).
// Every test ends with the wire's segment gone from /dev/shm.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../../unit/app/in_process_hil.h"
#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/wire_scratch.h"
#include "hiltwin/relbot/ecs_gains.h"
#include "hiltwin/relbot/setpoint_profile.h"

namespace {

namespace fs = std::filesystem;
using SteadyClock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;
using hiltwin::kernel_glue::ExitStatus;
using hiltwin::kernel_glue::Process;

// hil's defaults: the ECS at 1 kHz, the twin at 4 kHz.
constexpr std::int64_t kEcsPeriodNs = 1'000'000;
constexpr std::int64_t kTwinPeriodNs = 250'000;

Json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Erases every "wall_time_s" in `json`, at any depth; returns how many it erased.
int EraseWallTime(Json& json) {
  int erased = 0;
  if (json.is_object()) {
    erased += static_cast<int>(json.erase("wall_time_s"));
    for (auto& [key, value] : json.items()) erased += EraseWallTime(value);
  } else if (json.is_array()) {
    for (auto& value : json) erased += EraseWallTime(value);
  }
  return erased;
}

/// Where two texts first differ, as "line N: 'a' vs 'b'" (a failure message that fits a screen).
std::string FirstDifference(const std::string& a, const std::string& b) {
  std::istringstream in_a(a);
  std::istringstream in_b(b);
  std::string line_a;
  std::string line_b;
  for (int line = 1;; ++line) {
    const bool more_a = static_cast<bool>(std::getline(in_a, line_a));
    const bool more_b = static_cast<bool>(std::getline(in_b, line_b));
    if (!more_a && !more_b) {
      return "no line differs (sizes " + std::to_string(a.size()) + " and " +
             std::to_string(b.size()) + ")";
    }
    if (!more_a || !more_b || line_a != line_b) {
      return "line " + std::to_string(line) + ": '" + (more_a ? line_a : "<end>") + "' vs '" +
             (more_b ? line_b : "<end>") + "'";
    }
  }
}

/// What a side's command line may change from hil's.
struct SideArgs {
  std::string duration_s{};  ///< empty: hil's (the twin 14 s, the controller 12 s)
  std::string clock{"virtual"};
  std::string wait_peer_s{"30"};
  std::vector<std::string> extra{};
};

class Lockstep : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_FALSE(fs::exists(scratch_.SegmentPath()))
        << "shared memory left behind: " << scratch_.SegmentPath();
  }

  std::string Path(const std::string& name) const { return scratch_.Path(name); }
  std::string Wire() const { return scratch_.Wire(); }

  static hiltwin::test::RunResult Hiltwin(std::vector<std::string> args) {
    args.insert(args.begin(), HILTWIN_BINARY);
    return hiltwin::test::Run(args, 120'000);
  }
  /// `hiltwin hil --clock virtual` on this test's wire, its report in DIR.json and its logs in
  /// DIR/ (both removed first, so nothing of an earlier run can stand in for this one's).
  hiltwin::test::RunResult Hil(const std::string& dir,
                               const std::vector<std::string>& extra = {}) const {
    std::error_code ignored;
    fs::remove_all(Path(dir), ignored);
    fs::remove(Path(dir + ".json"), ignored);
    std::vector<std::string> args = {"hil",      "--clock",  "virtual",
                                     "--wire",   scratch_.WireName(),
                                     "--no-progress", "--report", Path(dir + ".json"),
                                     "--log-dir", Path(dir)};
    args.insert(args.end(), extra.begin(), extra.end());
    return Hiltwin(args);
  }
  /// The twin's command line as hil builds it (the default rate, the ECS's 12 s + 2 s,
  /// --clock virtual), without the program; its report in NAME.json.
  std::vector<std::string> TwinArgs(const std::string& name, const SideArgs& a = {}) const {
    std::vector<std::string> argv = {"run", "--io", Wire(), "--rate", "4000"};
    argv.insert(argv.end(), {"--duration", a.duration_s.empty() ? "14" : a.duration_s});
    argv.insert(argv.end(), {"--wait-peer", a.wait_peer_s, "--clock", a.clock});
    argv.insert(argv.end(), {"--no-progress", "--report", Path(name + ".json")});
    argv.insert(argv.end(), a.extra.begin(), a.extra.end());
    return argv;
  }
  /// The controller's command line as hil builds it (closed loop on the built-in profile, 12 s).
  std::vector<std::string> EcsArgs(const std::string& name, const SideArgs& a = {}) const {
    std::vector<std::string> argv = {"ecs", "--io", Wire(), "--rate", "1000"};
    argv.insert(argv.end(), {"--duration", a.duration_s.empty() ? "12" : a.duration_s});
    argv.insert(argv.end(), {"--mode", "closedloop", "--setpoint", "closedloop"});
    argv.insert(argv.end(), {"--wait-peer", a.wait_peer_s, "--clock", a.clock});
    argv.insert(argv.end(), {"--no-progress", "--report", Path(name + ".json")});
    argv.insert(argv.end(), a.extra.begin(), a.extra.end());
    return argv;
  }
  /// Starts hiltwin with `args`, its output in NAME.out and NAME.out.err.
  Process Start(std::vector<std::string> args, const std::string& name) const {
    args.insert(args.begin(), HILTWIN_BINARY);
    return hiltwin::test::Spawn(args, Path(name + ".out"));
  }
  /// Waits until the stderr of NAME contains `text`; false after `timeout`.
  bool WaitForText(const std::string& name, const std::string& text,
                   std::chrono::milliseconds timeout = std::chrono::seconds(20)) const {
    const auto end = SteadyClock::now() + timeout;
    while (SteadyClock::now() < end) {
      if (ReadFile(Path(name + ".out.err")).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }
  /// Both sides started and past their wait for each other.
  void ExpectBothUp(const std::string& twin, const std::string& ecs) const {
    ASSERT_TRUE(WaitForText(twin, "is up; starting")) << ReadFile(Path(twin + ".out.err"));
    ASSERT_TRUE(WaitForText(ecs, "is up; starting")) << ReadFile(Path(ecs + ".out.err"));
  }
  /// Waits (at most 60 s) for `process` to end; its status and the wall seconds since `since`.
  static std::pair<ExitStatus, double> EndOf(Process& process, SteadyClock::time_point since) {
    const auto status = process.WaitFor(std::chrono::seconds(60));
    const double after_s = std::chrono::duration<double>(SteadyClock::now() - since).count();
    return {status.value_or(ExitStatus{}), after_s};
  }
  /// A side's virtual time at its end: its last cycle's release. The session's first release
  /// is one period after its start, so cycle k is released at (k + 1) x period.
  static std::int64_t EndNs(const Json& report) {
    return report["cycles_run"].get<std::int64_t>() * report["period_ns"].get<std::int64_t>();
  }

  hiltwin::test::WireScratch scratch_{"lockstep"};
};

// --- hil --clock virtual: exact, repeatable, and the in-process rig's figures ---------------

class LockstepHil : public Lockstep {};

// Issue 33, 2: five runs with the same wire, report and log folder, while stress-ng keeps both
// cores busy, give byte-identical logs and byte-identical reports once wall_time_s (the
// report's one wall-clock field, one per side) is taken out. The .out files are not compared:
// a side that comes up before its peer prints a wall-clock countdown there.
TEST_F(LockstepHil, FiveRunsBesideACpuHogAreByteIdenticalButForWallTime) {
  ASSERT_TRUE(fs::exists("/usr/bin/stress-ng")) << "stress-ng is missing: scripts/setup.sh";
  auto hog =
      hiltwin::test::Spawn({"/usr/bin/stress-ng", "--cpu", "2", "--timeout", "600", "--quiet"});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  struct Outcome {
    int exit_code;
    std::string out;
    std::string twin_csv;
    std::string ecs_csv;
    Json twin;
    Json ecs;
    Json hil;
  };
  std::vector<Outcome> runs;
  for (int run = 0; run < 5; ++run) {
    const auto r = Hil("logs");
    ASSERT_EQ(r.exit_code, 0) << "run " << run << ": " << r.out << r.err;
    Outcome o{r.exit_code,
              r.out,
              ReadFile(Path("logs/twin.csv")),
              ReadFile(Path("logs/ecs.csv")),
              ReadJson(Path("logs/twin.json")),
              ReadJson(Path("logs/ecs.json")),
              ReadJson(Path("logs.json"))};
    // wall_time_s is there, once per side, and nothing else is taken out.
    EXPECT_EQ(EraseWallTime(o.twin), 1);
    EXPECT_EQ(EraseWallTime(o.ecs), 1);
    EXPECT_EQ(EraseWallTime(o.hil), 2);
    runs.push_back(std::move(o));
  }
  // The hog ran beside all five (its --timeout is far off); then it is stopped.
  EXPECT_FALSE(hog.WaitFor(std::chrono::milliseconds(0)).has_value())
      << "stress-ng ended before the runs did";
  hog.Kill(SIGTERM);

  const Outcome& first = runs.front();
  EXPECT_EQ(first.hil["tracking_error_max_m"]["left"].get<double>(),
            first.ecs["tracking"]["max_abs_error_m"]["left"].get<double>());
  EXPECT_FALSE(first.twin_csv.empty());
  EXPECT_FALSE(first.ecs_csv.empty());
  for (std::size_t run = 1; run < runs.size(); ++run) {
    const Outcome& other = runs[run];
    EXPECT_EQ(other.out, first.out) << "run " << run;
    EXPECT_TRUE(other.twin_csv == first.twin_csv)
        << "run " << run << " twin.csv: " << FirstDifference(first.twin_csv, other.twin_csv);
    EXPECT_TRUE(other.ecs_csv == first.ecs_csv)
        << "run " << run << " ecs.csv: " << FirstDifference(first.ecs_csv, other.ecs_csv);
    EXPECT_EQ(other.twin.dump(2), first.twin.dump(2))
        << "run " << run << " twin.json: " << Json::diff(first.twin, other.twin).dump();
    EXPECT_EQ(other.ecs.dump(2), first.ecs.dump(2))
        << "run " << run << " ecs.json: " << Json::diff(first.ecs, other.ecs).dump();
    EXPECT_EQ(other.hil.dump(2), first.hil.dump(2))
        << "run " << run << " hil report: " << Json::diff(first.hil, other.hil).dump();
  }
  // The run itself: the 12 s closed loop, whole, on the virtual clock.
  EXPECT_EQ(first.ecs["clock"], "virtual");
  EXPECT_EQ(first.ecs["cycles_run"], 12'000);
  EXPECT_EQ(first.twin["cycles_run"], 48'000);
  EXPECT_EQ(first.ecs["log_rows_written"], 12'000);
  EXPECT_EQ(first.twin["log_rows_written"], 48'000);
}

// Issue 33, 2: the closed loop of two processes in lockstep tracks exactly as the in-process
// virtual rig (ECS 1 kHz, twin 4 kHz, the default gains, the built-in closedloop profile): every
// TrackingStats figure equal as a double, in the ECS's report and in hil's combined one.
TEST_F(LockstepHil, TracksExactlyAsTheInProcessRig) {
  namespace app = hiltwin::app;
  static const app::SetpointProfile profile = app::ClosedLoopProfile();
  app::test::HilConfig config;  // default rates: ECS 1 kHz, twin 4 kHz
  config.gains = app::DefaultEcsGains();
  config.setpoints = &profile;
  config.rest_window_s = 1.0;
  app::test::InProcessHil rig(config);
  app::test::RunInProcess(rig);
  const app::TrackingStats& want = rig.ecs().tracking();
  const app::test::HilObservations seen = rig.observations();
  ASSERT_EQ(seen.ecs_cycles, 12'000U);
  ASSERT_EQ(seen.twin_cycles, 48'000U);

  const auto r = Hil("logs");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const Json hil = ReadJson(Path("logs.json"));
  const Json& ecs = hil["ecs"];
  const Json& got = ecs["tracking"];
  EXPECT_EQ(got["samples"].get<std::uint64_t>(), want.samples);
  EXPECT_EQ(got["max_abs_error_m"]["left"].get<double>(), want.max_abs_error_left_m);
  EXPECT_EQ(got["max_abs_error_m"]["right"].get<double>(), want.max_abs_error_right_m);
  EXPECT_EQ(got["rms_error_m"].get<double>(), want.rms_error_m);
  EXPECT_EQ(got["rms_error_wheel_m"]["left"].get<double>(), want.rms_error_left_m);
  EXPECT_EQ(got["rms_error_wheel_m"]["right"].get<double>(), want.rms_error_right_m);
  EXPECT_EQ(got["final_error_m"]["left"].get<double>(), want.final_error_left_m);
  EXPECT_EQ(got["final_error_m"]["right"].get<double>(), want.final_error_right_m);
  EXPECT_EQ(got["saturated_cycles"].get<std::uint64_t>(), want.saturated_cycles);
  EXPECT_EQ(got["max_abs_duty"].get<double>(), want.max_abs_duty);
  // hil's own summary of them.
  EXPECT_EQ(hil["tracking_error_max_m"]["left"].get<double>(), want.max_abs_error_left_m);
  EXPECT_EQ(hil["tracking_error_max_m"]["right"].get<double>(), want.max_abs_error_right_m);
  EXPECT_EQ(hil["tracking_error_rms_m"].get<double>(), want.rms_error_m);
  EXPECT_EQ(hil["final_error_m"].get<double>(),
            std::max(std::abs(want.final_error_left_m), std::abs(want.final_error_right_m)));
  // The same cycles, and a clean link on both.
  EXPECT_EQ(ecs["cycles_run"].get<std::uint64_t>(), seen.ecs_cycles);
  EXPECT_EQ(hil["twin"]["cycles_run"].get<std::uint64_t>(), seen.twin_cycles);
  EXPECT_EQ(seen.link_errors + seen.line_errors, 0U);
  EXPECT_EQ(hil["link_errors"], 0) << hil["link_error_parts"].dump();
  // The figure the issue quotes (1.06 mm), so a change of the loop shows up here by name.
  EXPECT_NEAR(want.max_abs_error_left_m, 1.059e-3, 0.5e-6);
}

// --- A pair started by hand ------------------------------------------------------------------

// Issue 37: the built-in PID as `--controller pid` on the RELbot's controller map given as a
// file runs the default run exactly: the same 2.5 m tracking figures as doubles and the same
// ECS log, byte for byte; and the combined report names the controller.
TEST_F(LockstepHil, ThePidOnTheShippedControllerMapTracksExactlyAsTheDefault) {
  const auto plain = Hil("plain");
  ASSERT_EQ(plain.exit_code, 0) << plain.out << plain.err;
  const auto mapped =
      Hil("mapped", {"--controller", "pid", "--controller-map", HILTWIN_ECS_CONTROLLER_MAP_TOML});
  ASSERT_EQ(mapped.exit_code, 0) << mapped.out << mapped.err;
  const Json a = ReadJson(Path("plain.json"));
  const Json b = ReadJson(Path("mapped.json"));
  EXPECT_EQ(a["ecs"]["tracking"], b["ecs"]["tracking"]);  // every figure, as doubles
  for (const char* key : {"tracking_error_max_m", "tracking_error_rms_m", "final_error_m"}) {
    EXPECT_EQ(a[key], b[key]) << key;
  }
  EXPECT_NEAR(b["tracking_error_max_m"]["left"].get<double>(), 1.059e-3, 0.5e-6);
  EXPECT_EQ(ReadFile(Path("plain/ecs.csv")), ReadFile(Path("mapped/ecs.csv")));
  EXPECT_EQ(ReadFile(Path("plain/twin.csv")), ReadFile(Path("mapped/twin.csv")));
  EXPECT_EQ(b["controller"]["spec"], "pid");
  EXPECT_EQ(b["controller"]["kind"], "built-in");
  EXPECT_EQ(b["ecs"]["controller_map"], HILTWIN_ECS_CONTROLLER_MAP_TOML);
  EXPECT_EQ(a["ecs"]["controller_map"], "the built-in RELbot controller map");
  EXPECT_THAT(mapped.out, ::testing::HasSubstr("controller pid (built-in): pid\n"));
}

class LockstepPair : public Lockstep {
 protected:
  /// Starts the side `first` (twin or ecs), waits until it waits for its peer, starts the
  /// other; both must pass. Then runs hil on the same wire: the hand-started pair ran exactly
  /// what hil runs.
  void ExpectTheSameRunAsHil(const std::string& first) {
    const bool twin_first = first == "twin";
    const auto twin_argv = TwinArgs("twin", {.extra = {"--log", Path("twin.csv")}});
    const auto ecs_argv = EcsArgs("ecs", {.extra = {"--log", Path("ecs.csv")}});
    std::optional<Process> twin;
    std::optional<Process> ecs;
    if (twin_first) {
      twin.emplace(Start(twin_argv, "twin"));
      ASSERT_TRUE(WaitForText("twin", "waiting for the controller on " + Wire()))
          << ReadFile(Path("twin.out.err"));
      ecs.emplace(Start(ecs_argv, "ecs"));
    } else {
      ecs.emplace(Start(ecs_argv, "ecs"));
      ASSERT_TRUE(WaitForText("ecs", "waiting for the twin on " + Wire()))
          << ReadFile(Path("ecs.out.err"));
      twin.emplace(Start(twin_argv, "twin"));
    }
    const auto since = SteadyClock::now();
    const auto [twin_status, twin_s] = EndOf(*twin, since);
    const auto [ecs_status, ecs_s] = EndOf(*ecs, since);
    ASSERT_EQ(twin_status.code, 0) << twin_status.Describe() << ReadFile(Path("twin.out.err"));
    ASSERT_EQ(ecs_status.code, 0) << ecs_status.Describe() << ReadFile(Path("ecs.out.err"));
    Json twin_report = ReadJson(Path("twin.json"));
    Json ecs_report = ReadJson(Path("ecs.json"));
    EXPECT_EQ(ecs_report["stop_reason"], "finished");
    EXPECT_EQ(twin_report["stop_reason"], "peer_stopped");
    EXPECT_EQ(twin_report["peer_stopped"], "wire: the ECS finished its run");

    const auto r = Hil("hil");
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_EQ(ReadFile(Path("twin.csv")), ReadFile(Path("hil/twin.csv")))
        << FirstDifference(ReadFile(Path("twin.csv")), ReadFile(Path("hil/twin.csv")));
    EXPECT_EQ(ReadFile(Path("ecs.csv")), ReadFile(Path("hil/ecs.csv")))
        << FirstDifference(ReadFile(Path("ecs.csv")), ReadFile(Path("hil/ecs.csv")));
    Json hil_twin = ReadJson(Path("hil/twin.json"));
    Json hil_ecs = ReadJson(Path("hil/ecs.json"));
    EXPECT_EQ(ecs_report["tracking"].dump(), hil_ecs["tracking"].dump());
    // The whole reports, apart from the wall time and where the log went.
    for (Json* report : {&twin_report, &ecs_report, &hil_twin, &hil_ecs}) {
      EXPECT_EQ(EraseWallTime(*report), 1);
      report->erase("log_path");
    }
    EXPECT_EQ(twin_report.dump(2), hil_twin.dump(2)) << Json::diff(hil_twin, twin_report).dump();
    EXPECT_EQ(ecs_report.dump(2), hil_ecs.dump(2)) << Json::diff(hil_ecs, ecs_report).dump();
  }
};

TEST_F(LockstepPair, TwinFirstRunsExactlyWhatHilRuns) { ExpectTheSameRunAsHil("twin"); }

TEST_F(LockstepPair, ControllerFirstRunsExactlyWhatHilRuns) { ExpectTheSameRunAsHil("ecs"); }

struct Mismatch {
  const char* first;        ///< the side that starts first and waits: "twin" or "ecs"
  const char* first_clock;  ///< its --clock; the second side comes with the other one
  const char* refusal;      ///< what the second side says
};

std::ostream& operator<<(std::ostream& out, const Mismatch& m) {
  return out << m.first << " first on --clock " << m.first_clock;
}

class LockstepClockMismatch : public Lockstep, public ::testing::WithParamInterface<Mismatch> {};

// A side that comes to a wire whose peer waits on the other clock is refused at once: exit 2,
// a message naming --clock, no report, nothing attached. The waiting side is left as it was:
// still waiting for a peer; a virtual one then takes a virtual peer and runs, a real-time one
// is stopped.
TEST_P(LockstepClockMismatch, TheSideThatComesSecondIsRefusedNamingClock) {
  const Mismatch& m = GetParam();
  const bool twin_first = std::string(m.first) == "twin";
  const std::string first_clock = m.first_clock;
  const std::string second_clock = first_clock == "virtual" ? "realtime" : "virtual";
  // Short runs, for the case where the waiting side later takes a matching peer.
  auto side_args = [&](bool twin, const std::string& clock, const std::string& name) {
    return twin ? TwinArgs(name, {.duration_s = "0.5", .clock = clock})
                : EcsArgs(name, {.duration_s = "0.3", .clock = clock});
  };
  auto first = Start(side_args(twin_first, first_clock, "first"), "first");
  ASSERT_TRUE(WaitForText("first", twin_first ? "waiting for the controller on " + Wire()
                                              : "waiting for the twin on " + Wire()))
      << ReadFile(Path("first.out.err"));

  const auto refused = Hiltwin(side_args(!twin_first, second_clock, "second"));
  EXPECT_EQ(refused.exit_code, 2) << refused.out << refused.err;
  EXPECT_NE(refused.err.find(m.refusal), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("start both sides with the same --clock"), std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(Path("second.json")));

  // The first side did not notice: it still waits, and the wire is still its own.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_FALSE(first.WaitFor(std::chrono::milliseconds(0)).has_value())
      << ReadFile(Path("first.out.err"));
  if (first_clock == "virtual") {
    const auto peer = Hiltwin(side_args(!twin_first, "virtual", "peer"));
    EXPECT_EQ(peer.exit_code, 0) << peer.out << peer.err;
    const auto [status, after_s] = EndOf(first, SteadyClock::now());
    EXPECT_EQ(status.code, 0) << status.Describe() << ReadFile(Path("first.out.err"));
    const Json report = ReadJson(Path("first.json"));
    EXPECT_GT(report["cycles_run"].get<int>(), 0);
    EXPECT_EQ(report["peer_absent_cycles"], 0);
  } else {
    first.Kill(SIGTERM);
    const Json report = ReadJson(Path("first.json"));
    EXPECT_EQ(report["stop_reason"], "stop_requested");
    EXPECT_EQ(report["cycles_run"], 0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    BothSidesBothClocks, LockstepClockMismatch,
    ::testing::Values(
        Mismatch{"twin", "realtime",
                 "the twin on this wire runs --clock realtime and this ECS --clock virtual"},
        Mismatch{"twin", "virtual",
                 "the twin on this wire runs --clock virtual and this ECS --clock realtime"},
        Mismatch{"ecs", "realtime",
                 "the ECS on this wire runs --clock realtime and this twin --clock virtual"},
        Mismatch{"ecs", "virtual",
                 "the ECS on this wire runs --clock virtual and this twin --clock realtime"}),
    [](const ::testing::TestParamInfo<Mismatch>& param_info) {
      return std::string(std::string(param_info.param.first) == "twin" ? "Twin" : "Controller") +
             "FirstOn" +
             (std::string(param_info.param.first_clock) == "virtual" ? "Virtual" : "Realtime");
    });

// --- Clean stops: the other side ends with peer_stopped at a predicted virtual instant ------

class LockstepStop : public Lockstep {
 protected:
  struct Ends {
    Json twin;
    Json ecs;
    std::string twin_csv;
    std::string ecs_csv;
  };
  /// A pair with these extra arguments (the later --duration wins), both logging; waits for
  /// both and checks that both passed.
  Ends RunPair(const std::string& twin_s, const std::string& ecs_s) {
    std::error_code ignored;
    for (const char* file : {"twin.json", "ecs.json", "twin.csv", "ecs.csv"}) {
      fs::remove(Path(file), ignored);
    }
    auto twin = Start(
        TwinArgs("twin", {.duration_s = twin_s, .extra = {"--log", Path("twin.csv")}}), "twin");
    auto ecs =
        Start(EcsArgs("ecs", {.duration_s = ecs_s, .extra = {"--log", Path("ecs.csv")}}), "ecs");
    const auto since = SteadyClock::now();
    const auto [twin_status, twin_after_s] = EndOf(twin, since);
    const auto [ecs_status, ecs_after_s] = EndOf(ecs, since);
    EXPECT_EQ(twin_status.code, 0) << twin_status.Describe() << ReadFile(Path("twin.out.err"));
    EXPECT_EQ(ecs_status.code, 0) << ecs_status.Describe() << ReadFile(Path("ecs.out.err"));
    return {ReadJson(Path("twin.json")), ReadJson(Path("ecs.json")), ReadFile(Path("twin.csv")),
            ReadFile(Path("ecs.csv"))};
  }
};

// The controller finishes its 3 s (3000 cycles, the last released at 3.000 s); the twin, set
// for 600 s, ends at its release at that very instant: 12000 cycles x 250 us = 3000 x 1 ms.
// Twice, identically.
TEST_F(LockstepStop, TheControllersFinishEndsTheTwinAtTheSameVirtualInstant) {
  Ends runs[2];
  for (Ends& run : runs) {
    run = RunPair("600", "3");
    EXPECT_EQ(run.ecs["stop_reason"], "finished");
    EXPECT_EQ(run.ecs["cycles_run"], 3'000);
    EXPECT_EQ(run.twin["stop_reason"], "peer_stopped");
    EXPECT_EQ(run.twin["peer_stopped"], "wire: the ECS finished its run");
    EXPECT_EQ(run.twin["cycles_run"], 12'000);
    EXPECT_EQ(run.twin["period_ns"], kTwinPeriodNs);
    EXPECT_EQ(EndNs(run.twin), EndNs(run.ecs));
    EXPECT_EQ(EndNs(run.ecs), 3'000'000'000);
    EXPECT_EQ(run.twin["outputs_safe"], true);
    EXPECT_EQ(run.twin["final_state"], "stopped");
    EXPECT_EQ(run.twin["log_rows_written"], 12'000);
    EXPECT_EQ(EraseWallTime(run.twin), 1);
    EXPECT_EQ(EraseWallTime(run.ecs), 1);
  }
  EXPECT_EQ(runs[1].twin.dump(2), runs[0].twin.dump(2));
  EXPECT_EQ(runs[1].ecs.dump(2), runs[0].ecs.dump(2));
  EXPECT_TRUE(runs[1].twin_csv == runs[0].twin_csv)
      << FirstDifference(runs[0].twin_csv, runs[1].twin_csv);
  EXPECT_TRUE(runs[1].ecs_csv == runs[0].ecs_csv)
      << FirstDifference(runs[0].ecs_csv, runs[1].ecs_csv);
}

// The twin finishes its 3 s (12000 cycles, the last released at 3.000 s). At 3.000 s the
// controller runs first (at equal times the ECS samples first), so its cycle released then
// still runs; it sees the twin's finish at its next release, 3.001 s: 3001 cycles.
TEST_F(LockstepStop, TheTwinsFinishEndsTheControllerAtItsNextRelease) {
  for (int run = 0; run < 2; ++run) {
    const Ends ends = RunPair("3", "600");
    EXPECT_EQ(ends.twin["stop_reason"], "finished");
    EXPECT_EQ(ends.twin["cycles_run"], 12'000);
    EXPECT_EQ(ends.ecs["stop_reason"], "peer_stopped");
    EXPECT_EQ(ends.ecs["peer_stopped"], "wire: the twin finished its run");
    EXPECT_EQ(ends.ecs["cycles_run"], 3'001);
    EXPECT_EQ(EndNs(ends.ecs), EndNs(ends.twin) + kEcsPeriodNs);
    EXPECT_EQ(ends.ecs["outputs_safe"], true);
    EXPECT_EQ(ends.ecs["final_state"], "stopped");
  }
}

class LockstepSigterm : public LockstepStop, public ::testing::WithParamInterface<std::string> {};

// SIGTERM mid-run to one side: it stops at its last release S (stop_requested); the other ends
// with peer_stopped at its first release that comes after S in the lockstep's order: the twin
// at S itself (its release at S follows the ECS's), the controller at the next whole
// millisecond after S (at S it would run first). So the other side ends within one ECS period
// of S, at an instant known exactly.
TEST_P(LockstepSigterm, TheOtherSideEndsAtItsFirstReleaseAfterTheStop) {
  const bool stop_twin = GetParam() == "twin";
  auto twin = Start(TwinArgs("twin", {.duration_s = "600"}), "twin");
  auto ecs = Start(EcsArgs("ecs", {.duration_s = "600"}), "ecs");
  ExpectBothUp("twin", "ecs");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  (stop_twin ? twin : ecs).Kill(SIGTERM);
  const auto since = SteadyClock::now();
  const auto [status, after_s] = EndOf(stop_twin ? ecs : twin, since);
  EXPECT_EQ(status.code, 0) << status.Describe();
  const Json twin_report = ReadJson(Path("twin.json"));
  const Json ecs_report = ReadJson(Path("ecs.json"));
  const Json& stopped = stop_twin ? twin_report : ecs_report;
  const Json& other = stop_twin ? ecs_report : twin_report;
  EXPECT_EQ(stopped["stop_reason"], "stop_requested");
  EXPECT_EQ(other["stop_reason"], "peer_stopped");
  EXPECT_EQ(other["peer_stopped"], stop_twin
                                       ? "wire: the twin was stopped (signal or stop command)"
                                       : "wire: the ECS was stopped (signal or stop command)");
  EXPECT_EQ(other["outputs_safe"], true);
  EXPECT_GT(stopped["cycles_run"].get<int>(), 0);  // stopped mid-run, not before it began
  const std::int64_t stop_ns = EndNs(stopped);
  const std::int64_t end_ns = EndNs(other);
  if (stop_twin) {
    EXPECT_EQ(end_ns, (stop_ns / kEcsPeriodNs + 1) * kEcsPeriodNs) << "twin stopped at " << stop_ns;
  } else {
    EXPECT_EQ(end_ns, stop_ns);
  }
  EXPECT_GT(end_ns - stop_ns, -1);
  EXPECT_LE(end_ns - stop_ns, kEcsPeriodNs);
}

INSTANTIATE_TEST_SUITE_P(EitherSide, LockstepSigterm, ::testing::Values("twin", "ecs"),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           return param_info.param == "twin" ? std::string("Twin")
                                                             : std::string("Controller");
                         });

// --- Faults: wall-clock bounds, as the issue asks (label rt) ---------------------------------

class LockstepFault : public LockstepStop, public ::testing::WithParamInterface<std::string> {
 protected:
  bool FaultTheTwin() const { return GetParam() == "twin"; }
  /// The survivor's report: an I/O fault with safe outputs and `reason` in its text.
  void ExpectIoFault(const std::string& name, const std::string& reason) const {
    const Json report = ReadJson(Path(name + ".json"));
    EXPECT_EQ(report["stop_reason"], "io_fault");
    EXPECT_EQ(report["final_state"], "safe_stop");
    EXPECT_EQ(report["outputs_safe"], true);
    EXPECT_NE(report["fault"]["reason"].get<std::string>().find(reason), std::string::npos)
        << report["fault"];
    EXPECT_NE(ReadFile(Path(name + ".out.err")).find("I/O fault"), std::string::npos);
  }
};

// kill -9 one side mid-run: the other ends as an I/O fault within 1 s of the kill, naming the
// process as gone.
TEST_P(LockstepFault, AKilledPeerEndsTheOtherWithinASecondAsAnIoFault) {
  auto twin = Start(TwinArgs("twin", {.duration_s = "600"}), "twin");
  auto ecs = Start(EcsArgs("ecs", {.duration_s = "600"}), "ecs");
  ExpectBothUp("twin", "ecs");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto killed_at = SteadyClock::now();
  (FaultTheTwin() ? twin : ecs).Kill(SIGKILL);
  const auto [status, after_s] = EndOf(FaultTheTwin() ? ecs : twin, killed_at);
  EXPECT_EQ(status.code, 5) << status.Describe();
  EXPECT_LT(after_s, 1.0);
  ExpectIoFault(FaultTheTwin() ? "ecs" : "twin",
                FaultTheTwin() ? "lockstep: the twin process is gone (killed or crashed)"
                               : "lockstep: the ECS process is gone (killed or crashed)");
}

// SIGSTOP one side mid-run: it holds the turn forever; the other ends as an I/O fault within
// 1 s (a lockstep peer's heartbeat goes stale after 500 ms), saying the peer stopped taking its
// turns. Continued, the stopped side ends as well (below), and the segment goes with it.
TEST_P(LockstepFault, AHungPeerEndsTheOtherWithinASecondAsAnIoFault) {
  auto twin = Start(TwinArgs("twin", {.duration_s = "600"}), "twin");
  auto ecs = Start(EcsArgs("ecs", {.duration_s = "600"}), "ecs");
  ExpectBothUp("twin", "ecs");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  Process& hung = FaultTheTwin() ? twin : ecs;
  const auto stopped_at = SteadyClock::now();
  ASSERT_EQ(::kill(hung.pid(), SIGSTOP), 0);
  const auto [status, after_s] = EndOf(FaultTheTwin() ? ecs : twin, stopped_at);
  EXPECT_EQ(status.code, 5) << status.Describe();
  EXPECT_LT(after_s, 1.0);
  ExpectIoFault(FaultTheTwin() ? "ecs" : "twin",
                FaultTheTwin() ? "lockstep: the twin stopped taking its turns"
                               : "lockstep: the ECS stopped taking its turns");
  // Continued, the hung side finds its peer ended and ends as well, outputs safe, the last one
  // out removing the segment (killed instead, it could not, and the segment would stay): with
  // peer_stopped, the peer having stopped on a fault. Whenever SIGSTOP caught it, even in the
  // middle of the lockstep wait, it reads the peer's announced stop before the peer's pid.
  ASSERT_EQ(::kill(hung.pid(), SIGCONT), 0);
  const auto continued_at = SteadyClock::now();
  const auto [hung_status, hung_after_s] = EndOf(hung, continued_at);
  EXPECT_LT(hung_after_s, 1.0);
  const Json report = ReadJson(Path(FaultTheTwin() ? "twin.json" : "ecs.json"));
  EXPECT_EQ(report["outputs_safe"], true);
  EXPECT_EQ(hung_status.code, 0) << hung_status.Describe() << report;
  EXPECT_EQ(report["stop_reason"], "peer_stopped");
  EXPECT_EQ(report["peer_stopped"], FaultTheTwin()
                                        ? "wire: the ECS stopped on a fault (see its report)"
                                        : "wire: the twin stopped on a fault (see its report)");
}

// A peer that never comes: one side alone with --wait-peer 1 ends as an I/O fault within 1 s
// of that second, naming the command that starts its peer (with --clock virtual).
TEST_P(LockstepFault, APeerThatNeverComesEndsTheSideAloneAsAnIoFault) {
  const bool twin_alone = !FaultTheTwin();  // the twin is the one that never comes
  const auto started_at = SteadyClock::now();
  const auto r = Hiltwin(twin_alone ? TwinArgs("alone", {.wait_peer_s = "1"})
                                    : EcsArgs("alone", {.wait_peer_s = "1"}));
  const double after_s = std::chrono::duration<double>(SteadyClock::now() - started_at).count();
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_GE(after_s, 1.0);
  EXPECT_LT(after_s, 2.0);  // within 1 s of the wait's end
  const std::string peer = twin_alone ? "controller" : "twin";
  EXPECT_NE(r.err.find("no " + peer + " came up on " + Wire() + " within 1 s"), std::string::npos)
      << r.err;
  const std::string command = twin_alone ? "hiltwin ecs" : "hiltwin run";
  EXPECT_NE(r.err.find("start it with: " + command + " --io " + Wire() + " --clock virtual"),
            std::string::npos)
      << r.err;
  const Json report = ReadJson(Path("alone.json"));
  EXPECT_EQ(report["stop_reason"], "io_fault");
  EXPECT_EQ(report["outputs_safe"], true);
  EXPECT_EQ(report["cycles_run"], 0);
  EXPECT_NE(report["fault"]["reason"].get<std::string>().find("no " + peer + " came up"),
            std::string::npos);
}

// The parameter is the side the fault hits (killed, stopped, or the one that never comes).
INSTANTIATE_TEST_SUITE_P(EitherSide, LockstepFault, ::testing::Values("ecs", "twin"),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           return param_info.param == "twin" ? std::string("OnTheTwin")
                                                             : std::string("OnTheController");
                         });

}  // namespace
