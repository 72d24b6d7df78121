// The monitor's DDS side (dds_monitor.h) against real sinks in the same process: discovery
// through DCPSPublication, the latest timing record per namespace, commands to one task.
#include "hiltwin/telemetry/dds_monitor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "dds_test_support.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

using runtime::RemoteCommand;
using test::WaitFor;

class DdsMonitorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::UseLoopbackDds(); }
};

runtime::TelemetryRecord Record(const std::string& ns, const std::string& role,
                                std::uint64_t cycle) {
  runtime::TelemetryRecord r;
  r.ns = ns;
  r.role = role;
  r.rate_hz = 500.0;
  r.time_s = static_cast<double>(cycle) / 500.0;
  r.cycle = cycle;
  r.cycles_planned = 5000;
  r.state = lifecycle::State::kRun;
  r.deadline_misses = 2;
  r.latency_p99_us = 55.5;
  r.distance_to_violation = 4;
  r.verdict_so_far = qos::Verdict::kPass;
  return r;
}

const MonitorEntry* Find(const std::vector<MonitorEntry>& entries, const std::string& ns) {
  const auto it = std::find_if(entries.begin(), entries.end(),
                               [&](const MonitorEntry& e) { return e.ns == ns; });
  return it == entries.end() ? nullptr : &*it;
}

TEST_F(DdsMonitorTest, ListsEveryTaskWithItsLatestRecord) {
  constexpr std::uint32_t kDomain = 207;
  const std::string twin_ns = test::UniqueNamespace("bench1/twin");
  const std::string ecs_ns = test::UniqueNamespace("bench1/controller");
  runtime::TelemetryShape twin_shape;
  twin_shape.role = "twin";
  twin_shape.has_pose = true;
  runtime::TelemetryShape ecs_shape;
  ecs_shape.role = "controller";
  const auto twin = MakeDdsSink({kDomain});
  twin->Open(twin_shape, twin_ns);
  const auto ecs = MakeDdsSink({kDomain});
  ecs->Open(ecs_shape, ecs_ns);
  twin->Publish(Record(twin_ns, "twin", 100));
  twin->Publish(Record(twin_ns, "twin", 200));  // only the latest counts
  runtime::TelemetryRecord last = Record(ecs_ns, "controller", 300);
  last.distance_to_violation = std::nullopt;
  last.final = true;
  ecs->Publish(last);

  DdsMonitor monitor(kDomain);
  std::vector<MonitorEntry> entries;
  ASSERT_TRUE(WaitFor([&] {
    entries = monitor.Poll();
    return Find(entries, twin_ns) != nullptr && Find(entries, ecs_ns) != nullptr;
  }));
  const MonitorEntry& t = *Find(entries, twin_ns);
  EXPECT_EQ(t.role, "twin");
  EXPECT_EQ(t.cycle, 200u);
  EXPECT_EQ(t.cycles_planned, 5000u);
  EXPECT_EQ(t.rate_hz, 500.0);
  EXPECT_EQ(t.deadline_misses, 2u);
  EXPECT_EQ(t.latency_p99_us, 55.5);
  EXPECT_EQ(t.distance_to_violation, std::optional<std::uint32_t>(4));
  EXPECT_EQ(t.verdict, "PASS");
  EXPECT_EQ(t.state, lifecycle::ToString(lifecycle::State::kRun));
  EXPECT_FALSE(t.final);
  EXPECT_GE(t.age_s, 0.0);
  const MonitorEntry& c = *Find(entries, ecs_ns);
  EXPECT_EQ(c.role, "controller");
  EXPECT_EQ(c.distance_to_violation, std::nullopt);
  EXPECT_TRUE(c.final);
  EXPECT_TRUE(std::is_sorted(entries.begin(), entries.end(),
                             [](const auto& a, const auto& b) { return a.ns < b.ns; }));
  const std::vector<std::string> names = monitor.Namespaces();
  EXPECT_NE(std::find(names.begin(), names.end(), twin_ns), names.end());
}

TEST_F(DdsMonitorTest, SendsACommandToOneTask) {
  constexpr std::uint32_t kDomain = 208;
  const std::string ns = test::UniqueNamespace("twin");
  const auto sink = MakeDdsSink({kDomain, true});  // --accept-commands
  sink->Open(runtime::TelemetryShape{}, ns);
  DdsMonitor monitor(kDomain);
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(monitor.SendCommand(ns, RemoteCommand::kStop, 10.0), "");
  std::vector<RemoteCommand> seen;
  EXPECT_TRUE(WaitFor([&] {
    sink->PollCommands([&](RemoteCommand c, std::string&) {
      seen.push_back(c);
      return true;
    });
    return !seen.empty();
  }));
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(seen, std::vector<RemoteCommand>{RemoteCommand::kStop});
}

// The task's command reader says in its user data whether it takes commands, so the sender
// learns of a refusal at once, not from the task's stderr on another machine.
TEST_F(DdsMonitorTest, ACommandToATaskWithoutAcceptCommandsIsReportedRefused) {
  constexpr std::uint32_t kDomain = 212;
  const std::string ns = test::UniqueNamespace("twin");
  const auto sink = MakeDdsSink({kDomain});  // as started without --accept-commands
  sink->Open(runtime::TelemetryShape{}, ns);
  DdsMonitor monitor(kDomain);
  ::testing::internal::CaptureStderr();
  const std::string why = monitor.SendCommand(ns, RemoteCommand::kStop, 10.0);
  bool offered = false;
  sink->PollCommands([&](RemoteCommand, std::string&) { return offered = true; });
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(why.find("the task refused STOP"), std::string::npos) << why;
  EXPECT_NE(why.find("--accept-commands"), std::string::npos) << why;
  EXPECT_FALSE(offered);
  EXPECT_NE(err.find("ignored STOP"), std::string::npos) << "the task says so too: " << err;
}

TEST_F(DdsMonitorTest, ACommandToNobodyTimesOutWithAReason) {
  DdsMonitor monitor(209);
  const std::string why = monitor.SendCommand("nobody/here", RemoteCommand::kStop, 0.2);
  EXPECT_NE(why.find("no reader on rt/nobody/here/command"), std::string::npos) << why;
}

TEST_F(DdsMonitorTest, ADomainAbove232IsRefused) {
  EXPECT_THROW(DdsMonitor(400), std::invalid_argument);
}

}  // namespace
}  // namespace hiltwin::telemetry
