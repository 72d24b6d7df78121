// The typed run report: the exit code is a pure function of it, and the JSON and the summary
// are derived from the same fields, so they cannot disagree.
#include "hiltwin/runtime/run_report.h"

#include <gtest/gtest.h>

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
  r.misses.releases = 40'000;
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
  const std::vector<std::string> contract = {
      "verdict",         "stop_reason",      "rate_hz",
      "period_ns",       "cycles_planned",   "cycles_run",
      "deadline_misses", "miss_pct",         "max_consecutive_misses",
      "constraints",     "latency_ns",       "compute_ns",
      "response_ns",     "log_rows_written", "log_rows_dropped"};
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
