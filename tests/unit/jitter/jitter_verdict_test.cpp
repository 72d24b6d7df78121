// What the report says before any per-cycle cause (issue 35, point 3): a rate this machine
// cannot hold in the median cycle is the cause of the misses, on the first line; and the
// kernel's preemption model the recording named (point 2).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "hiltwin/jitter/jitter_outputs.h"
#include "jitter_fixtures.h"

namespace hiltwin::analysis {
namespace {

std::string FirstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

// 20 kHz (deadline = period = 50 µs) with a median wake-up of 40 µs and 20 µs of compute:
// every cycle misses whatever else happens.
testing::RunSpec InfeasibleRun() {
  testing::RunSpec spec;
  spec.releases = 2'000;
  spec.latency_ns = [](std::uint64_t) { return 40'000; };
  spec.compute_ns = [](std::uint64_t) { return 20'000; };
  return spec;
}

TEST(JitterVerdict, AnInfeasibleRateIsTheReportsFirstLine) {
  const TimingTrace trace = testing::MakeTrace(InfeasibleRun());
  const KernelTrace kernel = testing::MakeKernel(trace, {});
  const JitterReport r = AnalyzeJitter(trace, &kernel);
  const std::string first = FirstLine(FormatJitterText(r));
  EXPECT_EQ(first,
            "INFEASIBLE HERE: the median wake-up latency (40 us) plus the median compute (20 us) "
            "is 60 us, above the 50 us deadline: 20000 Hz cannot be kept on this machine (its "
            "medians allow at most 16666 Hz); find the rate it holds with `hiltwin tune --cpu 1 "
            "--priority 80`")
      << first;
  const nlohmann::ordered_json json = JitterToJson(r);
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(json.begin().key(), "feasibility");
  const nlohmann::ordered_json& f = json["feasibility"];
  EXPECT_EQ(f["feasible"], false);
  EXPECT_EQ(f["latency_p50_ns"], 40'000);
  EXPECT_EQ(f["compute_p50_ns"], 20'000);
  EXPECT_EQ(f["max_rate_hz"], 16'666);
  EXPECT_EQ(f["deadline_ns"], 50'000);
  EXPECT_EQ(f["advice"], "hiltwin tune --cpu 1 --priority 80");
  EXPECT_EQ(f["verdict"], first);
}

TEST(JitterVerdict, AFeasibleRateKeepsTheUsualFirstLine) {
  testing::RunSpec spec = InfeasibleRun();
  spec.latency_ns = [](std::uint64_t) { return 25'000; };  // 45.1 µs: tight, but it holds
  const JitterReport r = AnalyzeJitter(testing::MakeTrace(spec), nullptr);
  EXPECT_EQ(FirstLine(FormatJitterText(r)), "hiltwin jitter report: synthetic (lttng)");
  const nlohmann::ordered_json json = JitterToJson(r);
  EXPECT_EQ(json.begin().key(), "feasibility");
  EXPECT_EQ(json["feasibility"]["feasible"], true);
  EXPECT_EQ(json["feasibility"]["verdict"], "");
}

TEST(JitterVerdict, TheReportNamesTheKernelsPreemptionModel) {
  const TimingTrace trace = testing::MakeTrace(testing::RunSpec{});
  KernelTrace kernel = testing::MakeKernel(trace, {});
  kernel.preemption_model = "PREEMPT_NONE";
  kernel.preemption_source = "kernel config default; debugfs not mounted";
  const JitterReport r = AnalyzeJitter(trace, &kernel);
  const nlohmann::ordered_json json = JitterToJson(r);
  EXPECT_EQ(json["kernel_preemption"]["model"], "PREEMPT_NONE");
  EXPECT_EQ(json["kernel_preemption"]["source"], "kernel config default; debugfs not mounted");
  EXPECT_NE(FormatJitterText(r).find("kernel preemption model: PREEMPT_NONE (kernel config "
                                     "default; debugfs not mounted)\n"),
            std::string::npos);
  // A recording that did not say (made before the model was recorded): unknown, and why.
  kernel.preemption_model.clear();
  kernel.preemption_source.clear();
  const JitterReport old = AnalyzeJitter(trace, &kernel);
  EXPECT_EQ(JitterToJson(old)["kernel_preemption"]["model"], "unknown");
  EXPECT_NE(FormatJitterText(old).find("kernel preemption model: unknown (the recording does "
                                       "not name it)\n"),
            std::string::npos);
}

}  // namespace
}  // namespace hiltwin::analysis
