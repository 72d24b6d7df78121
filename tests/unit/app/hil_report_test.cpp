// The combined HiL result: figures are read from the ECS's and the twin's reports, a missing
// report is "no figures" rather than an error, and the exit code is the worse of the two
// (unless one side only echoes its failed peer).
#include "hiltwin/runs/hil_report.h"

#include <gtest/gtest.h>

#include <optional>
#include <utility>

namespace hiltwin::app {
namespace {

using Json = nlohmann::ordered_json;

kernel_glue::ExitStatus Exited(int code) {
  kernel_glue::ExitStatus status;
  status.exited = true;
  status.code = code;
  return status;
}

Json TwinReport() {
  return Json{{"verdict", "PASS"}, {"stop_reason", "peer_stopped"}, {"io_errors", 2}};
}

Json EcsReport() {
  return Json{{"verdict", "FLAGGED"},
              {"stop_reason", "finished"},
              {"io_errors", 1},
              {"tracking",
               {{"max_abs_error_m", {{"left", 0.0021}, {"right", 0.0019}}},
                {"rms_error_m", 0.0008},
                {"final_error_m", {{"left", -0.00004}, {"right", 0.00002}}}}},
              {"encoder_lines",
               {{"illegal_transitions", 3}, {"too_fast_edges", 0}, {"resyncs", 4}}}};
}

TEST(HilReport, FiguresComeFromBothReports) {
  const HilResult r = CombineHil("wire:x", "closedloop", {"twin", Exited(0), TwinReport()},
                                 {"ecs", Exited(3), EcsReport()});
  ASSERT_TRUE(r.tracking.has_value());
  EXPECT_DOUBLE_EQ(r.tracking->max_left_m, 0.0021);
  EXPECT_DOUBLE_EQ(r.tracking->max_right_m, 0.0019);
  EXPECT_DOUBLE_EQ(r.tracking->rms_m, 0.0008);
  EXPECT_DOUBLE_EQ(r.tracking->final_m, 0.00004);  // the larger magnitude of the two wheels
  EXPECT_EQ(r.link.twin_frames, 2U);
  EXPECT_EQ(r.link.ecs_frames, 1U);
  EXPECT_EQ(r.link.encoder_line_errors, 7U);
  EXPECT_EQ(r.exit_code, 3);
  const Json json = ToJson(r);
  EXPECT_EQ(json["link_errors"], 10);
  EXPECT_DOUBLE_EQ(json["tracking_error_max_m"]["left"].get<double>(), 0.0021);
  EXPECT_DOUBLE_EQ(json["final_error_m"].get<double>(), 0.00004);
  EXPECT_EQ(json["twin"]["stop_reason"], "peer_stopped");
  EXPECT_EQ(json["ecs"]["verdict"], "FLAGGED");
  EXPECT_EQ(json["ecs_exit"]["exit_code"], 3);
  const std::string summary = FormatHilSummary(r);
  EXPECT_NE(summary.find("max |error| left 2.100 mm, right 1.900 mm"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("exit 3 (the worse of twin 0 and ECS 3)"), std::string::npos) << summary;
}

TEST(HilReport, AMissingReportLeavesTheFiguresOutAndACrashIsInternal) {
  kernel_glue::ExitStatus killed;
  killed.signal = 9;
  const HilResult r = CombineHil("wire:x", "closedloop", {"twin", Exited(5), TwinReport()},
                                 {"ecs", killed, std::nullopt});
  EXPECT_FALSE(r.tracking.has_value());
  EXPECT_EQ(r.exit_code, 1);
  const Json json = ToJson(r);
  EXPECT_TRUE(json["ecs"].is_null());
  EXPECT_TRUE(json["tracking_error_rms_m"].is_null());
  EXPECT_NE(FormatHilSummary(r).find("ecs   no report"), std::string::npos);
}

// 143: a side stopped by SIGTERM before any cycle was judged (no verdict, nothing failed).
TEST(HilReport, WorseExitCodeOrdersPassFlaggedAbortedStoppedIoUsageInternal) {
  const int order[] = {0, 3, 4, 143, 5, 2, 1};
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 7; ++j) {
      EXPECT_EQ(WorseExitCode(order[i], order[j]), order[std::max(i, j)]) << i << "," << j;
    }
  }
}

// The twin aborted on its QoS rule in its first cycles (a loaded start), before the ECS judged
// one: the ECS's NONE/exit 5 only echoes that, and the pair's code is the twin's 4, which says
// why. When the side that went first did not fail, the echo is still the worse code.
/// The pair's exit code for two sides that exited with these codes and wrote these reports.
int PairCode(int twin_code, std::optional<Json> twin, int ecs_code, std::optional<Json> ecs) {
  return CombineHil("wire:w", "closedloop", HilSide{"twin", Exited(twin_code), std::move(twin)},
                    HilSide{"ecs", Exited(ecs_code), std::move(ecs)})
      .exit_code;
}

TEST(HilReport, ASideThatOnlyEchoesItsFailedPeerLeavesThePairsCodeToThePeer) {
  const Json echo{{"verdict", "NONE"}, {"stop_reason", "peer_stopped"}};
  const Json aborted{{"verdict", "ABORTED"}, {"stop_reason", "qos_abort"}};
  const Json passed{{"verdict", "PASS"}, {"stop_reason", "finished"}};
  EXPECT_EQ(PairCode(4, aborted, 5, echo), 4);
  EXPECT_EQ(PairCode(5, echo, 1, std::nullopt), 1);
  EXPECT_EQ(PairCode(0, passed, 5, echo), 5);
  EXPECT_EQ(PairCode(5, echo, 5, echo), 5);
}

}  // namespace
}  // namespace hiltwin::app
