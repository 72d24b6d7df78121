// The typed run report: the exit code is a pure function of it, and the JSON and the summary
// are derived from the same fields, so they cannot disagree.
#include "hiltwin/runtime/run_report.h"

#include <gtest/gtest.h>

#include <csignal>
#include <string>

namespace hiltwin::runtime {
namespace {

using lifecycle::StopReason;

RunReport Finished(qos::Verdict verdict) {
  RunReport r;
  r.task_name = "test";
  r.io = "mock";
  r.verdict = verdict;
  r.stop_reason = StopReason::kFinished;
  r.final_state = lifecycle::State::kStopped;
  r.rate_hz = 4000.0;
  r.cycles_planned = r.cycles_run = r.releases = 40'000;
  r.misses.releases = r.misses.cycles_judged = 40'000;
  return r;
}

/// A run that ended before its first judged cycle.
RunReport Unjudged(StopReason stop, int signal_number = 0) {
  RunReport r = Finished(qos::Verdict::kPass);  // the monitor's verdict over nothing
  r.stop_reason = stop;
  r.stop_signal = signal_number;
  r.cycles_run = r.releases = r.misses.releases = r.misses.cycles_judged = 0;
  return r;
}

TEST(ExitCodeFor, FollowsTheVerdictWhenNothingFailed) {
  EXPECT_EQ(ExitCodeFor(Finished(qos::Verdict::kPass)), ExitCode::kPass);
  EXPECT_EQ(ExitCodeFor(Finished(qos::Verdict::kFlagged)), ExitCode::kFlagged);
  EXPECT_EQ(ExitCodeFor(Finished(qos::Verdict::kAborted)), ExitCode::kAborted);
}

TEST(ExitCodeFor, FaultsAndAnIncompleteLogOutrankTheVerdict) {
  RunReport io = Finished(qos::Verdict::kFlagged);
  io.stop_reason = StopReason::kIoFault;
  EXPECT_EQ(ExitCodeFor(io), ExitCode::kIo);
  RunReport late_io = Finished(qos::Verdict::kPass);
  late_io.fault_while_stopping = StopReason::kIoFault;  // finished, then the link failed
  EXPECT_EQ(ExitCodeFor(late_io), ExitCode::kIo);
  RunReport model = Finished(qos::Verdict::kPass);
  model.stop_reason = StopReason::kModelFault;
  EXPECT_EQ(ExitCodeFor(model), ExitCode::kInternal);
  RunReport log = Finished(qos::Verdict::kPass);
  log.log = LogFigures{"run.csv", 10, 0, 5, "write 'run.csv': No space left on device",
                       "No space left on device"};
  EXPECT_EQ(ExitCodeFor(log), ExitCode::kIo);
  log.log->error.clear();
  EXPECT_EQ(ExitCodeFor(log), ExitCode::kPass);
}

// Issue 34: a twin that ran 0 cycles, or an ECS stopped while it waited for its peer, said PASS
// and exit 0. No judged cycle: no verdict, and an exit code that is not a pass.
TEST(ExitCodeFor, NoJudgedCycleIsNoVerdict) {
  // Stopped on request: what the shell shows for a command that signal ended.
  EXPECT_EQ(static_cast<int>(ExitCodeFor(Unjudged(StopReason::kStopRequested, SIGTERM))), 143);
  EXPECT_EQ(static_cast<int>(ExitCodeFor(Unjudged(StopReason::kStopRequested, SIGINT))), 130);
  EXPECT_EQ(static_cast<int>(ExitCodeFor(Unjudged(StopReason::kStopRequested, SIGHUP))), 129);
  // A stop command stands for SIGTERM (docs/telemetry.md).
  EXPECT_EQ(static_cast<int>(ExitCodeFor(Unjudged(StopReason::kStopRequested))), 143);
  // The peer went before the first judged cycle: the link failed, as a peer that never came.
  EXPECT_EQ(ExitCodeFor(Unjudged(StopReason::kPeerStopped)), ExitCode::kIo);
  // A fault still says which.
  RunReport model = Unjudged(StopReason::kModelFault);
  model.fault = RunFault{StopReason::kModelFault, 0, "NaN"};
  EXPECT_EQ(ExitCodeFor(model), ExitCode::kInternal);
  // Cycles inside the grace period only are not judged either.
  RunReport grace = Unjudged(StopReason::kStopRequested, SIGINT);
  grace.cycles_run = grace.misses.releases = grace.misses.grace_cycles = 200;
  EXPECT_EQ(static_cast<int>(ExitCodeFor(grace)), 130);
}

TEST(ConclusionOf, NoJudgedCycleSaysSoWithTheStopReasonInTheSummaryAndTheJson) {
  RunReport r = Unjudged(StopReason::kStopRequested, SIGTERM);
  const Conclusion c = ConclusionOf(r);
  EXPECT_FALSE(c.verdict.has_value());
  EXPECT_FALSE(c.complete);
  EXPECT_EQ(c.text, "NONE (no cycle was judged: stopped by SIGTERM before the first judged cycle)");
  const std::string summary = FormatSummary(r);
  EXPECT_NE(summary.find("verdict    " + c.text + "\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("stop: stop_requested by SIGTERM\n"), std::string::npos) << summary;
  const auto json = ToJson(r);
  EXPECT_EQ(json["verdict"], "NONE");
  EXPECT_EQ(json["complete"], false);
  EXPECT_EQ(json["verdict_text"], c.text);
  EXPECT_EQ(json["stop_signal"], "SIGTERM");

  RunReport lost = Unjudged(StopReason::kPeerStopped);
  lost.link.peer_name = "controller";
  EXPECT_EQ(ConclusionOf(lost).text,
            "NONE (no cycle was judged: the controller stopped before the first judged cycle)");
  EXPECT_TRUE(ToJson(lost)["stop_signal"].is_null());
  RunReport fault = Unjudged(StopReason::kIoFault);
  fault.fault = RunFault{StopReason::kIoFault, 0, "no controller came up"};
  EXPECT_EQ(ConclusionOf(fault).text,
            "NONE (no cycle was judged; the run did NOT finish: I/O fault at cycle 0)");
}

// Issue 34: a model fault halfway gave "verdict": "PASS" in the JSON while the summary said the
// run did NOT finish. Both now come from ConclusionOf.
TEST(ConclusionOf, AFaultedRunsJsonVerdictCarriesWhatTheSummarySays) {
  RunReport r = Finished(qos::Verdict::kPass);
  r.stop_reason = StopReason::kModelFault;
  r.cycles_run = r.misses.cycles_judged = 2001;
  r.fault = RunFault{StopReason::kModelFault, 2000, "the plant's output became non-finite"};
  const auto json = ToJson(r);
  EXPECT_EQ(json["verdict"], "PASS");  // the timing of the cycles run
  EXPECT_EQ(json["complete"], false);  // but not the run asked for
  const std::string text = json["verdict_text"];
  EXPECT_EQ(text,
            "PASS for the timing of the 2001 cycles run; the run did NOT finish: model "
            "fault at cycle 2000");
  EXPECT_NE(FormatSummary(r).find("verdict    " + text + "\n"), std::string::npos);
  EXPECT_EQ(ToJson(Finished(qos::Verdict::kPass))["complete"], true);
  EXPECT_EQ(ToJson(Finished(qos::Verdict::kPass))["verdict_text"], "PASS");
}

TEST(FormatSummary, WarningsAreInTheSummaryAndTheJson) {
  RunReport r = Finished(qos::Verdict::kPass);
  EXPECT_TRUE(ToJson(r)["warnings"].empty());
  r.warnings = {"the controller reads too rarely"};
  EXPECT_NE(FormatSummary(r).find("warning    the controller reads too rarely\nverdict    PASS\n"),
            std::string::npos)
      << FormatSummary(r);
  EXPECT_EQ(ToJson(r)["warnings"], nlohmann::ordered_json::array({r.warnings[0]}));
}

TEST(FormatSummary, AnAbortedRunClaimsSafeOutputsOnlyWhenTheyWereWritten) {
  RunReport r = Finished(qos::Verdict::kAborted);
  r.stop_reason = StopReason::kQosAbort;
  r.outputs_safe = true;
  EXPECT_NE(FormatSummary(r).find("outputs put in their safe state"), std::string::npos);
  r.outputs_safe = false;
  const std::string summary = FormatSummary(r);
  EXPECT_EQ(summary.find("outputs put in their safe state"), std::string::npos) << summary;
  EXPECT_NE(summary.find("the safe outputs could NOT be written"), std::string::npos) << summary;
  EXPECT_FALSE(ToJson(r)["outputs_safe"].get<bool>());
}

TEST(FormatSummary, MissFiguresAreTheLedgersAndSayWhatWasJudged) {
  RunReport r = Finished(qos::Verdict::kPass);
  r.misses.deadline_misses = 71;
  r.misses.miss_pct = 71.0 * 100.0 / 40'000.0;
  r.misses.max_consecutive_misses = 71;
  r.misses.grace_cycles = 200;
  r.misses.grace_misses = 71;
  r.misses.cycles_judged = 39'800;
  const std::string summary = FormatSummary(r);
  EXPECT_NE(summary.find("misses     71 of 40000 releases (0.177 %)"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("judged     0 misses of 39800 releases"), std::string::npos) << summary;
  const auto json = ToJson(r);
  EXPECT_EQ(json["deadline_misses"], 71);
  EXPECT_EQ(json["qos"]["grace_misses"], 71);
  EXPECT_EQ(json["qos"]["misses_judged"], 0);
  EXPECT_TRUE(json["miss_counts_include_grace"].get<bool>());
}

TEST(ToJson, KeepsTheContractKeysFirstAndInOrder) {
  const auto json = ToJson(Finished(qos::Verdict::kPass));
  const std::vector<std::string> contract = {"verdict",
                                             "complete",
                                             "verdict_text",
                                             "stop_reason",
                                             "rate_hz",
                                             "period_ns",
                                             "cycles_planned",
                                             "cycles_run",
                                             "deadline_misses",
                                             "miss_pct",
                                             "max_consecutive_misses",
                                             "constraints",
                                             "latency_ns",
                                             "compute_ns",
                                             "response_ns",
                                             "log_rows_written",
                                             "log_rows_dropped"};
  std::vector<std::string> first;
  for (auto it = json.begin(); it != json.end() && first.size() < contract.size(); ++it) {
    first.push_back(it.key());
  }
  EXPECT_EQ(first, contract);
  EXPECT_TRUE(json.contains("io_ns"));      // I/O time beside compute time
  EXPECT_TRUE(json["rt_setup"].is_null());  // virtual clock: no RT set-up was made
}

TEST(FormatSummary, AFaultedRunsVerdictSaysItJudgesOnlyTheTimingOfAnUnfinishedRun) {
  RunReport r = Finished(qos::Verdict::kPass);
  EXPECT_NE(FormatSummary(r).find("verdict    PASS\n"), std::string::npos);  // a full run: plain
  r.stop_reason = StopReason::kModelFault;
  r.cycles_run = 2001;
  r.fault = RunFault{StopReason::kModelFault, 2000, "the plant's output became non-finite"};
  EXPECT_NE(FormatSummary(r).find("verdict    PASS for the timing of the 2001 cycles run; the "
                                  "run did NOT finish: model fault at cycle 2000\n"),
            std::string::npos)
      << FormatSummary(r);
  r.fault->kind = StopReason::kIoFault;
  EXPECT_NE(FormatSummary(r).find("did NOT finish: I/O fault at cycle 2000"), std::string::npos);
}

TEST(Problems, LinkErrorsAreAWarningThatTheInputsWereHeld) {
  RunReport r = Finished(qos::Verdict::kPass);
  r.link.io_errors = 3;
  const auto lines = Problems(r);
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0], "warning: 3 frames on the link were corrupted or missed; the inputs were "
                      "held over those cycles, so the results there rest on stale inputs");
}

TEST(Problems, NameTheFaultTheAbsentPeerAndTheIncompleteLog) {
  RunReport r = Finished(qos::Verdict::kPass);
  EXPECT_TRUE(Problems(r).empty());
  r.fault = RunFault{StopReason::kIoFault, 12, "wire peer lost"};
  r.link.peer_name = "controller";
  r.link.peer_absent_cycles = 400;
  r.io = "wire:lab";
  r.log = LogFigures{"run.csv", 1, 0, 0, "disk full", ""};
  const auto lines = Problems(r);
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0], "I/O fault at cycle 12: wire peer lost");
  EXPECT_NE(lines[1].find("no controller was attached to wire:lab in 400 of 40000 cycles"),
            std::string::npos);
  EXPECT_EQ(lines[2], "the log run.csv is incomplete: disk full");
}

TEST(Problems, ALogEndedByAFullDiskSaysWhatIsInItAndWhatWasLost) {
  RunReport r = Finished(qos::Verdict::kPass);
  r.log = LogFigures{"run.csv", 4'900, 3, 75'062, "write 'run.csv': No space left on device",
                     "No space left on device"};
  const std::string summary = FormatSummary(r);
  EXPECT_NE(summary.find("log        run.csv: 4900 rows written, 3 dropped, 75062 lost (No space "
                         "left on device)\n"),
            std::string::npos)
      << summary;
  const auto lines = Problems(r);
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0],
            "the log run.csv is incomplete: write 'run.csv': No space left on device; it ends "
            "with its last whole row: 4900 rows written, 75062 lost");
  const auto json = ToJson(r);
  EXPECT_EQ(json["log_rows_written"], 4'900);
  EXPECT_EQ(json["log_rows_dropped"], 3);
  EXPECT_EQ(json["log_rows_lost"], 75'062);
  EXPECT_EQ(json["log_error"], "write 'run.csv': No space left on device");
  EXPECT_EQ(ExitCodeFor(r), ExitCode::kIo);
}

TEST(FormatSummary, ACompleteLogNamesNoLoss) {
  RunReport r = Finished(qos::Verdict::kPass);
  r.log = LogFigures{"run.csv", 80'000, 0, 0, "", ""};
  r.timing_log = LogFigures{"t.csv", 80'000, 2, 0, "", ""};
  const std::string summary = FormatSummary(r);
  EXPECT_NE(summary.find("log        run.csv: 80000 rows written, 0 dropped\n"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("timing log t.csv: 80000 rows written, 2 dropped\n"), std::string::npos)
      << summary;
  EXPECT_EQ(summary.find("lost"), std::string::npos) << summary;
  EXPECT_EQ(ToJson(r)["log_rows_lost"], 0);
  EXPECT_EQ(ToJson(r)["timing_log_rows_lost"], 0);
}

}  // namespace
}  // namespace hiltwin::runtime
