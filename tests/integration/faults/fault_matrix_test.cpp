// The fault matrix (issue 16; docs/reliability.md holds each row's observed outcome and the
// command that reproduces it). Every row runs the real binary, injects one fault and checks the
// whole outcome through one coherence check: the exit code follows from the report, the end
// state and the safe outputs follow from the stop reason, and the log is whole (its last byte
// ends a row), parseable to its last row and holds exactly the rows the report counts. Then
// each row asserts what its fault must have done. Virtual-clock rows are exact; wall-clock rows
// (FaultMatrixRealtime) assert only what holds on a noisy shared machine.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/wire_scratch.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A log as the matrix checks it: every row must parse, so this records what did not.
struct LogFile {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::string problem;  ///< empty when whole and parseable
};

LogFile ReadLog(const std::string& path) {
  LogFile log;
  const std::string text = ReadFile(path);
  if (text.empty()) {
    log.problem = "the log " + path + " is empty or missing";
    return log;
  }
  if (text.back() != '\n') log.problem = "the log's last row is torn (no final newline)";
  std::stringstream lines(text);
  std::string line;
  std::getline(lines, line);
  std::stringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) log.columns.push_back(cell);
  for (std::size_t number = 2; std::getline(lines, line); ++number) {
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      char* end = nullptr;
      row.push_back(std::strtod(cell.c_str(), &end));
      if (cell.empty() || *end != '\0') log.problem = "line " + std::to_string(number) + ": '" + cell + "' is no number";
    }
    if (row.size() != log.columns.size() && log.problem.empty()) {
      log.problem = "line " + std::to_string(number) + " has " + std::to_string(row.size()) +
                    " cells, the header " + std::to_string(log.columns.size());
    }
    log.rows.push_back(std::move(row));
  }
  return log;
}

/// The exit code the contract gives a report (docs/architecture.md, "Exit codes"; docs/lifecycle.md
/// for the faults).
int ExpectedExitCode(const Json& report) {
  const std::string stop = report["stop_reason"];
  if (stop == "io_fault" || report.contains("log_error")) return 5;
  if (stop == "model_fault") return 1;
  const std::string verdict = report["verdict"];
  return verdict == "PASS" ? 0 : verdict == "FLAGGED" ? 3 : 4;
}

/// The verdict the constraints imply: any violated rule flags (or aborts) the run.
bool AnyRuleViolated(const Json& report) {
  for (const Json& rule : report["constraints"]) {
    if (rule["violated"].get<bool>()) return true;
  }
  return false;
}

class FaultMatrix : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_FALSE(fs::exists(scratch_.SegmentPath())) << "shared memory left behind: "
                                                     << scratch_.SegmentPath();
  }

  std::string Path(const std::string& name) const { return scratch_.Path(name); }
  std::string Wire() const { return scratch_.Wire(); }

  /// `hiltwin run` with a log and a report in this test's folder, plus `extra`.
  std::vector<std::string> RunArgs(const std::string& name, std::vector<std::string> extra) const {
    std::vector<std::string> argv = {HILTWIN_BINARY, "run",          "--no-progress",
                                     "--log",        Path(name + ".csv"), "--report",
                                     Path(name + ".json")};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  }

  /// The coherence every row must show; returns the report for the row's own assertions.
  Json ExpectCoherent(const std::string& name, int exit_code, const std::string& err) const {
    const Json report = Json::parse(ReadFile(Path(name + ".json")));
    EXPECT_EQ(exit_code, ExpectedExitCode(report)) << err << report.dump(1);
    const std::string stop = report["stop_reason"];
    const bool fault = stop == "io_fault" || stop == "model_fault" || stop == "qos_abort";
    EXPECT_EQ(report["final_state"], fault ? "safe_stop" : "stopped") << stop;
    EXPECT_EQ(report["outputs_safe"], true);
    EXPECT_EQ(report.contains("fault"), stop == "io_fault" || stop == "model_fault");
    if (report["verdict"] == "PASS") {
      EXPECT_FALSE(AnyRuleViolated(report));
    } else if (report["verdict"] == "FLAGGED") {
      EXPECT_TRUE(AnyRuleViolated(report));
    }
    const LogFile log = ReadLog(Path(name + ".csv"));
    EXPECT_EQ(log.problem, "");
    EXPECT_EQ(log.rows.size(), report["log_rows_written"].get<std::size_t>());
    if (!report.contains("log_error")) {
      // Nothing lost: every cycle that completed a step is a row.
      EXPECT_EQ(report["log_rows_dropped"], 0);
    }
    return report;
  }

  /// The log's column `name`.
  static std::size_t Column(const LogFile& log, const std::string& name) {
    for (std::size_t i = 0; i < log.columns.size(); ++i) {
      if (log.columns[i] == name) return i;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }

  hiltwin::test::WireScratch scratch_{"fm"};
};

// --- Overruns (virtual clock: exact) -----------------------------------------------------------

TEST_F(FaultMatrix, M01_ASingleOverrunIsCountedAndJudgedByTheRules) {
  const auto r = hiltwin::test::Run(RunArgs("m01", {"--clock", "virtual", "--duration", "2",
                                                    "--inject-overrun", "at=4000,extra-us=600"}));
  const Json report = ExpectCoherent("m01", r.exit_code, r.err);
  // 600 µs at a 250 µs period: the overrunning cycle and the ones it delays miss.
  EXPECT_GE(report["deadline_misses"].get<int>(), 1);
  EXPECT_EQ(report["stop_reason"], "finished");
  EXPECT_EQ(report["cycles_run"], 8000);
}

TEST_F(FaultMatrix, M02_ABurstOfOverrunsFlagsTheRunAtItsFirstViolation) {
  const auto r = hiltwin::test::Run(RunArgs(
      "m02", {"--clock", "virtual", "--duration", "2", "--inject-overrun",
              "at=4000,count=20,extra-us=600"}));
  const Json report = ExpectCoherent("m02", r.exit_code, r.err);
  EXPECT_EQ(report["verdict"], "FLAGGED");
  EXPECT_EQ(r.exit_code, 3);
  for (const Json& rule : report["constraints"]) {
    if (rule["violated"].get<bool>()) {
      EXPECT_GE(rule["first_violation_cycle"].get<int>(), 4000);
    }
  }
}

TEST_F(FaultMatrix, M03_PeriodicOverrunsAreEachAMiss) {
  const auto r = hiltwin::test::Run(RunArgs(
      "m03", {"--clock", "virtual", "--duration", "2", "--overrun-policy", "skip",
              "--inject-overrun", "every=1000,extra-us=300"}));
  const Json report = ExpectCoherent("m03", r.exit_code, r.err);
  // 8 injections of 300 µs at a 250 µs period: each cycle hit misses its deadline.
  EXPECT_GE(report["deadline_misses"].get<int>(), 8);
}

// --- The link (virtual clock: exact) -----------------------------------------------------------

class FaultMatrixLink : public FaultMatrix,
                        public ::testing::WithParamInterface<const char*> {};

// Exchanges 4000..4002 fail: the openloop input steps from 0 to 0.4 duty at 1 s (exchange 4000),
// so the held inputs show in the log as three more rows at the old duty.
TEST_P(FaultMatrixLink, M05_M08_BrokenFramesAreCountedAndTheInputsHeld) {
  const std::string kind = GetParam();
  const auto clean = hiltwin::test::Run(RunArgs("clean", {"--clock", "virtual", "--duration", "2"}));
  ExpectCoherent("clean", clean.exit_code, clean.err);
  const auto r = hiltwin::test::Run(RunArgs(
      "m05", {"--clock", "virtual", "--duration", "2", "--inject-link-fault",
              kind + ",at=4000,count=3"}));
  const Json report = ExpectCoherent("m05", r.exit_code, r.err);
  EXPECT_EQ(report["io_errors"], 3);
  EXPECT_EQ(report["link faults"], kind + ",at=4000,count=3");
  EXPECT_EQ(report["stop_reason"], "finished");
  EXPECT_NE(r.out.find("3 frames corrupted or missed (inputs held)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("warning: 3 frames on the link were corrupted or missed"),
            std::string::npos)
      << r.err;
  const LogFile with = ReadLog(Path("m05.csv"));
  const LogFile without = ReadLog(Path("clean.csv"));
  const std::size_t duty = Column(with, "duty_left");
  ASSERT_EQ(with.rows.size(), 8000U);
  ASSERT_EQ(without.rows.size(), 8000U);
  EXPECT_NE(without.rows[4000][duty], without.rows[3999][duty]);  // the step the fault hides
  for (std::size_t row = 4000; row < 4003; ++row) {
    EXPECT_EQ(with.rows[row][duty], with.rows[3999][duty]) << "row " << row << " not held";
  }
  EXPECT_EQ(with.rows[4003][duty], without.rows[4003][duty]);  // the link is back
}

INSTANTIATE_TEST_SUITE_P(Frames, FaultMatrixLink,
                         ::testing::Values("corrupt-request", "corrupt-answer", "drop-answer",
                                           "delay-answer"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           name.erase(name.find('-'), 1);
                           return name;
                         });

TEST_F(FaultMatrix, M09_TheWrongFpgaImageStopsAtInitWithExitFive) {
  const auto r = hiltwin::test::Run(RunArgs("m09", {"--clock", "virtual", "--duration", "1",
                                                    "--board-image", "icoboard"}));
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_NE(r.err.find("Failed to initialise FPGA: found icoboard"), std::string::npos) << r.err;
  // Refused before the run: no cycle ran, so there is no report (not even an empty one) and no
  // log to misread.
  EXPECT_FALSE(fs::exists(Path("m09.json")));
  EXPECT_FALSE(fs::exists(Path("m09.csv")) && !ReadLog(Path("m09.csv")).rows.empty());
}

// --- The model ---------------------------------------------------------------------------------

TEST_F(FaultMatrix, M15_AModelProducingNaNIsAModelFaultWithEveryEarlierRowKept) {
  const std::string map = Path("lag.toml");
  std::ofstream(map) << "[[pwm]]\nchannel = 1\ninput = \"u\"\n[[encoder]]\nchannel = 1\n"
                        "output = \"y\"\nunit = \"rad\"\ncounts_per_unit = 1000\n";
  const auto r = hiltwin::test::Run(RunArgs(
      "m15", {"--clock", "virtual", "--rate", "1000", "--duration", "3", "--plant",
              std::string("fmu:") + HILTWIN_TEST_FMU_DIR + "/lag_nan.fmu", "--plant-map", map}));
  const Json report = ExpectCoherent("m15", r.exit_code, r.err);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(report["stop_reason"], "model_fault");
  // lag_nan's output turns NaN in its step 2000 (counting from 0): 2000 finite rows.
  EXPECT_EQ(report["fault"]["cycle"], 2000);
  EXPECT_NE(report["fault"]["reason"].get<std::string>().find("non-finite"), std::string::npos);
  const LogFile log = ReadLog(Path("m15.csv"));
  ASSERT_EQ(log.rows.size(), 2000U);
  for (const double value : log.rows.back()) EXPECT_TRUE(std::isfinite(value));
  EXPECT_NE(r.err.find("model fault at cycle 2000"), std::string::npos) << r.err;
  // The verdict judges timing only; its line says the run did not finish.
  EXPECT_NE(r.out.find("verdict    PASS for the timing of the 2001 cycles run; the run did NOT "
                       "finish: model fault at cycle 2000"),
            std::string::npos)
      << r.out;
}

// --- Wall clock: the machine, the peer, the signals -----------------------------------------------

class FaultMatrixRealtime : public FaultMatrix {};

TEST_F(FaultMatrixRealtime, M04_ACpuHogOnEveryCoreGivesAVerdictThatMatchesTheMisses) {
  auto hog = hiltwin::test::Spawn({"/usr/bin/stress-ng", "--cpu", "0", "--timeout", "20",
                                   "--quiet"});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto r = hiltwin::test::Run(RunArgs("m04", {"--duration", "3"}));
  hog.Kill(SIGTERM);
  const Json report = ExpectCoherent("m04", r.exit_code, r.err);
  EXPECT_EQ(report["stop_reason"], "finished");
  EXPECT_EQ(report["cycles_run"], 12000);
  // Whatever the hog did, the verdict is the rules' judgement of the misses it caused.
  EXPECT_EQ(report["verdict"] == "FLAGGED", AnyRuleViolated(report));
  EXPECT_EQ(report["deadline_misses"].get<int>() == 0, report["miss_pct"].get<double>() == 0.0);
}

/// `hiltwin run` and `hiltwin ecs` on this test's wire; returns once both are running.
struct Pair {
  std::optional<hiltwin::kernel_glue::Process> twin;
  std::optional<hiltwin::kernel_glue::Process> ecs;
};

class FaultMatrixWire : public FaultMatrixRealtime {
 protected:
  Pair StartPair(std::vector<std::string> twin_extra = {}) {
    Pair pair;
    std::vector<std::string> twin = RunArgs("twin", {"--io", Wire(), "--duration", "30"});
    twin.insert(twin.end(), twin_extra.begin(), twin_extra.end());
    const std::vector<std::string> ecs = {HILTWIN_BINARY, "ecs", "--io", Wire(), "--duration",
                                          "30", "--no-progress", "--log", Path("ecs.csv"),
                                          "--report", Path("ecs.json")};
    pair.twin.emplace(hiltwin::test::Spawn(twin, Path("twin.out")));
    pair.ecs.emplace(hiltwin::test::Spawn(ecs, Path("ecs.out")));
    for (const char* side : {"twin.out.err", "ecs.out.err"}) {
      const auto end = Clock::now() + std::chrono::seconds(10);
      while (ReadFile(Path(side)).find("is up; starting") == std::string::npos &&
             Clock::now() < end) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    return pair;
  }
};

TEST_F(FaultMatrixWire, M11_M12_APeerKilledMidRunIsAnIoFaultOnTheOtherSide) {
  for (const bool kill_twin : {false, true}) {
    SCOPED_TRACE(kill_twin ? "the twin killed" : "the controller killed");
    Pair pair = StartPair();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    (kill_twin ? *pair.twin : *pair.ecs).Kill(SIGKILL);
    auto& survivor = kill_twin ? *pair.ecs : *pair.twin;
    const auto status = survivor.WaitFor(std::chrono::seconds(10));
    ASSERT_TRUE(status.has_value()) << "the survivor did not stop";
    const std::string name = kill_twin ? "ecs" : "twin";
    const Json report = ExpectCoherent(name, status->code, ReadFile(Path(name + ".out.err")));
    EXPECT_EQ(status->code, 5);
    EXPECT_EQ(report["stop_reason"], "io_fault");
    EXPECT_NE(report["fault"]["reason"].get<std::string>().find("stopped updating its heartbeat"),
              std::string::npos)
        << report["fault"];
    // The killed side never removed the segment; the survivor, last out, did.
  }
}

TEST_F(FaultMatrixWire, M10_AStuckEncoderLeavesTheControllerBlind) {
  Pair pair = StartPair({"--inject-link-fault", "stuck-encoder,at=0"});
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto twin_status = pair.twin->Kill(SIGTERM);
  const auto ecs_status = pair.ecs->WaitFor(std::chrono::seconds(10));
  ASSERT_TRUE(ecs_status.has_value());
  const Json twin = ExpectCoherent("twin", twin_status.code, ReadFile(Path("twin.out.err")));
  EXPECT_EQ(twin["link faults"], "stuck-encoder,at=0");
  EXPECT_EQ(twin["stop_reason"], "stop_requested");
  const Json ecs = ExpectCoherent("ecs", ecs_status->code, ReadFile(Path("ecs.out.err")));
  EXPECT_EQ(ecs["stop_reason"], "peer_stopped");
  // The twin's wheels turn under the controller's duty; the controller's encoders never move.
  const LogFile twin_log = ReadLog(Path("twin.csv"));
  const LogFile ecs_log = ReadLog(Path("ecs.csv"));
  ASSERT_FALSE(twin_log.rows.empty());
  ASSERT_FALSE(ecs_log.rows.empty());
  EXPECT_NE(twin_log.rows.back()[Column(twin_log, "enc_left")], 0.0);
  for (const auto& row : ecs_log.rows) ASSERT_EQ(row[Column(ecs_log, "enc_left")], 0.0);
}

// SIGINT and SIGTERM at seeded random moments from start-up to past the end: the process ends
// on its own (never killed by the signal once it has opened an output), and whatever it wrote
// is coherent. A signal before the command opened anything may end it at once (default action):
// then it must have left no output behind.
TEST_F(FaultMatrixRealtime, M13_StopSignalsAtRandomMomentsNeverLeaveAHalfWrittenOutcome) {
  std::mt19937 random(20261124);
  std::uniform_int_distribution<int> delay_ms(0, 1600);
  // Start-up (exec, flags, plant, INIT: the first ~60 ms here) densely, then the run and its
  // drain at random.
  for (int trial = 0; trial < 30; ++trial) {
    const int signal = trial % 2 == 0 ? SIGINT : SIGTERM;
    const int after_ms = trial < 20 ? trial * 3 : delay_ms(random);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": signal " + std::to_string(signal) +
                 " after " + std::to_string(after_ms) + " ms");
    const std::string name = "m13_" + std::to_string(trial);
    auto run = hiltwin::test::Spawn(RunArgs(name, {"--duration", "1"}), Path(name + ".out"));
    std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
    const auto status = run.Kill(signal);
    if (!status.exited) {
      EXPECT_EQ(status.signal, signal);
      EXPECT_FALSE(fs::exists(Path(name + ".json"))) << "killed with a report half made";
      EXPECT_FALSE(fs::exists(Path(name + ".csv"))) << "killed with a log half made";
      continue;
    }
    const Json report = ExpectCoherent(name, status.code, ReadFile(Path(name + ".out.err")));
    const std::string stop = report["stop_reason"];
    EXPECT_TRUE(stop == "stop_requested" || stop == "finished") << stop;
    if (stop == "finished") {
      EXPECT_EQ(report["cycles_run"], 4000);
    }
  }
}

}  // namespace
