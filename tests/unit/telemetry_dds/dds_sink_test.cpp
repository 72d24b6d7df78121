// The DDS sink (sinks.h MakeDdsSink): what it publishes, read back by an in-process reader of
// the test's own, and what it does with commands written on rt/<ns>/command.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "dds_test_support.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

using runtime::RemoteCommand;
using test::TwinRecord;
using test::TwinShape;
using test::WaitFor;

class DdsSinkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::UseLoopbackDds(); }
};

struct Joints {
  std::int32_t sec = -1;
  std::uint32_t nanosec = 0;
  std::vector<std::string> names;
  std::vector<double> position;
  std::size_t velocity = 99;
};

TEST_F(DdsSinkTest, PublishesExactlyTheRecordsValues) {
  constexpr std::uint32_t kDomain = 201;
  const std::string ns = test::UniqueNamespace("twin");
  const auto sink = MakeDdsSink({kDomain});
  sink->Open(TwinShape(), ns);
  EXPECT_EQ(sink->Describe(),
            "DDS domain 201 rt/" + ns + "/{odom,pose,joint_states,timing,command} rt/tf rt/clock");
  test::Peer peer(kDomain);
  const dds_entity_t pose_reader =
      peer.Reader(&geometry_msgs_msg_dds__Pose2D__desc, "rt/" + ns + "/pose");
  const dds_entity_t joints_reader =
      peer.Reader(&sensor_msgs_msg_dds__JointState__desc, "rt/" + ns + "/joint_states");
  const dds_entity_t timing_reader =
      peer.Reader(&hiltwin_msgs_msg_dds__Timing__desc, "rt/" + ns + "/timing", true);
  const runtime::TelemetryRecord record = TwinRecord(ns);

  geometry_msgs_msg_dds__Pose2D_ pose{};
  Joints joints;
  hiltwin_msgs_msg_dds__Timing_ timing{};
  std::string role, verdict, state;
  bool got_pose = false, got_joints = false, got_timing = false;
  ASSERT_TRUE(WaitFor([&] {
    sink->Publish(record);  // again until each reader has one (matching may take a moment)
    got_pose = got_pose || test::TakeOne<geometry_msgs_msg_dds__Pose2D_>(
                               pose_reader, [&](const auto& s) { pose = s; });
    got_joints =
        got_joints ||
        test::TakeOne<sensor_msgs_msg_dds__JointState_>(joints_reader, [&](const auto& s) {
          joints.sec = s.header.stamp.sec;
          joints.nanosec = s.header.stamp.nanosec;
          for (std::uint32_t i = 0; i < s.name._length; ++i) {
            joints.names.emplace_back(s.name._buffer[i]);
          }
          joints.position.assign(s.position._buffer, s.position._buffer + s.position._length);
          joints.velocity = s.velocity._length;
        });
    got_timing = got_timing ||
                 test::TakeOne<hiltwin_msgs_msg_dds__Timing_>(timing_reader, [&](const auto& s) {
                   timing = s;
                   role = s.role;
                   verdict = s.verdict;
                   state = s.state;
                 });
    return got_pose && got_joints && got_timing;
  }));

  EXPECT_EQ(pose.x, 0.5);
  EXPECT_EQ(pose.y, -0.25);
  EXPECT_EQ(pose.theta, 1.125);
  EXPECT_EQ(joints.sec, 12);
  EXPECT_EQ(joints.nanosec, 250'000'000u);
  EXPECT_EQ(joints.names, (std::vector<std::string>{"left_wheel_joint", "right_wheel_joint"}));
  EXPECT_EQ(joints.position, (std::vector<double>{3.5, -1.75}));  // rad, not metres
  EXPECT_EQ(joints.velocity, 0u);
  EXPECT_EQ(role, "twin");
  EXPECT_EQ(timing.rate_hz, 1000.0);
  EXPECT_EQ(timing.time_s, 12.25);
  EXPECT_EQ(timing.cycle, 12'250u);
  EXPECT_EQ(timing.cycles_planned, 20'000u);
  EXPECT_EQ(timing.deadline_misses, 3u);
  EXPECT_EQ(timing.latency_p99_us, 41.5);
  EXPECT_EQ(timing.latency_max_us, 97.25);
  EXPECT_EQ(timing.distance_to_violation, -1);  // nullopt: no rule can fail
  EXPECT_EQ(verdict, "PASS");
  EXPECT_EQ(state, lifecycle::ToString(lifecycle::State::kRun));
  EXPECT_FALSE(timing.final);
}

TEST_F(DdsSinkTest, TimingCarriesDistanceVerdictAndFinalToALateReader) {
  constexpr std::uint32_t kDomain = 202;
  const std::string ns = test::UniqueNamespace("ctl");
  const auto sink = MakeDdsSink({kDomain});
  runtime::TelemetryShape shape;
  shape.role = "controller";
  sink->Open(shape, ns);
  EXPECT_EQ(sink->Describe(), "DDS domain 202 rt/" + ns + "/{joint_states,timing,command}");
  runtime::TelemetryRecord record = TwinRecord(ns);
  record.distance_to_violation = 7;
  record.verdict_so_far = qos::Verdict::kFlagged;
  record.state = lifecycle::State::kStopped;
  record.final = true;
  sink->Publish(record);  // before the reader exists: transient-local keeps it

  test::Peer peer(kDomain);
  const dds_entity_t timing_reader =
      peer.Reader(&hiltwin_msgs_msg_dds__Timing__desc, "rt/" + ns + "/timing", true);
  hiltwin_msgs_msg_dds__Timing_ timing{};
  std::string verdict;
  ASSERT_TRUE(WaitFor([&] {
    return test::TakeOne<hiltwin_msgs_msg_dds__Timing_>(timing_reader, [&](const auto& s) {
      timing = s;
      verdict = s.verdict;
    });
  }));
  EXPECT_EQ(timing.distance_to_violation, 7);
  EXPECT_EQ(verdict, "FLAGGED");
  EXPECT_TRUE(timing.final);
}

// Writes `codes` on rt/<ns>/command to a sink that takes commands when `accept`
// (--accept-commands), waits until its reader has them all, and polls the sink until the port
// was offered `offers` commands or 5 s passed; returns what the port took.
std::vector<RemoteCommand> SendAndPoll(std::uint32_t domain, const std::vector<int>& codes,
                                       std::size_t offers, const runtime::CommandPort& refuse,
                                       bool accept = true) {
  const std::string ns = test::UniqueNamespace("cmd");
  const auto sink = MakeDdsSink({domain, accept});
  sink->Open(TwinShape(), ns);
  test::Peer peer(domain);
  const dds_entity_t writer = peer.Writer(&std_msgs_msg_dds__Int32__desc, "rt/" + ns + "/command");
  EXPECT_TRUE(WaitFor([&] { return test::Matched(writer); }));
  for (const int code : codes) {
    const std_msgs_msg_dds__Int32_ sample{code};
    EXPECT_EQ(dds_write(writer, &sample), DDS_RETCODE_OK);
  }
  EXPECT_EQ(dds_wait_for_acks(writer, DDS_SECS(5)), DDS_RETCODE_OK);
  std::vector<RemoteCommand> seen;
  std::size_t offered = 0;
  const runtime::CommandPort port = [&](RemoteCommand c, std::string& why) {
    ++offered;
    if (refuse && !refuse(c, why)) return false;
    seen.push_back(c);
    return true;
  };
  WaitFor([&] {
    sink->PollCommands(port);
    return offered >= offers;
  });
  sink->PollCommands(port);  // nothing more may arrive
  return seen;
}

// Any participant on the domain could stop or pause a task. Without --accept-commands the
// task takes none, known codes or not, and says so once on stderr: whoever watches it learns
// that someone tried, and how to allow it.
TEST_F(DdsSinkTest, WithoutAcceptCommandsNothingReachesThePortAndTheTaskSaysSoOnce) {
  ::testing::internal::CaptureStderr();
  const auto seen = SendAndPoll(210, {3, 5, 42}, 0, {}, false);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(seen.empty());
  EXPECT_NE(err.find("hiltwin: ignored STOP on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("started without --accept-commands"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << "once: " << err;
}

TEST_F(DdsSinkTest, TwoTasksWithOneNamespaceAreEachWarnedOnce) {
  constexpr std::uint32_t kDomain = 211;
  const std::string shared = test::UniqueNamespace("shared");
  const std::string alone = test::UniqueNamespace("alone");
  const test::StderrFile err;
  const auto first = MakeDdsSink({kDomain});
  first->Open(TwinShape(), shared);
  const auto other = MakeDdsSink({kDomain});
  other->Open(TwinShape(), alone);
  const auto second = MakeDdsSink({kDomain});
  second->Open(TwinShape(), shared);
  const auto warnings = [&] {
    const std::string text = err.Text();
    std::size_t count = 0;
    for (std::size_t at = text.find("warning: another task"); at != std::string::npos;
         at = text.find("warning: another task", at + 1)) {
      ++count;
    }
    return count;
  };
  const auto poll_all = [&] {  // as each task's telemetry thread does, once per record
    for (const auto& sink : {first, other, second}) {
      sink->PollCommands([](RemoteCommand, std::string&) { return true; });
    }
  };
  EXPECT_TRUE(WaitFor([&] {
    poll_all();
    return warnings() >= 2;
  })) << err.Text();
  for (int i = 0; i < 20; ++i) poll_all();
  const std::string text = err.Text();
  EXPECT_EQ(warnings(), 2u) << "each of the two, once: " << text;
  EXPECT_NE(text.find("rt/" + shared + "/timing on DDS domain 211"), std::string::npos) << text;
  EXPECT_NE(text.find("give each task its own --namespace"), std::string::npos) << text;
  EXPECT_EQ(text.find(alone), std::string::npos) << text;
}

TEST_F(DdsSinkTest, CommandsReachThePortInOrder) {
  ::testing::internal::CaptureStderr();
  const auto seen = SendAndPoll(203, {3, 5, 2, 6}, 4, {});
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(seen, (std::vector<RemoteCommand>{RemoteCommand::kStop, RemoteCommand::kPause,
                                              RemoteCommand::kStart, RemoteCommand::kQuit}));
  EXPECT_NE(err.find("hiltwin: STOP received on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("/cmd/command"), std::string::npos) << err;
}

TEST_F(DdsSinkTest, UnknownCodesAndRefusedCommandsAreNotPassedOn) {
  const runtime::CommandPort refuse_reset = [](RemoteCommand c, std::string& why) {
    if (c != RemoteCommand::kReset) return true;
    why = "RESET applies only when stopped";
    return false;
  };
  ::testing::internal::CaptureStderr();
  const auto seen = SendAndPoll(204, {42, 4, 0, 3}, 2, refuse_reset);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(seen, (std::vector<RemoteCommand>{RemoteCommand::kStop}));
  EXPECT_NE(err.find("ignored command code 42 on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("ignored command code 0 on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("RESET on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("refused: RESET applies only when stopped"), std::string::npos) << err;
}

TEST_F(DdsSinkTest, APortThatThrowsDoesNotEscapePollCommands) {
  const runtime::CommandPort throws = [](RemoteCommand, std::string&) -> bool {
    throw std::runtime_error("queue broken");
  };
  ::testing::internal::CaptureStderr();
  const auto seen = SendAndPoll(205, {3}, 1, throws);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(seen.empty());
  EXPECT_NE(err.find("STOP on rt/"), std::string::npos) << err;
  EXPECT_NE(err.find("failed: queue broken"), std::string::npos) << err;
}

TEST_F(DdsSinkTest, ADomainAbove232IsABadFlag) {
  try {
    static_cast<void>(MakeDdsSink({233}));
    FAIL() << "domain 233 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--telemetry dds:233"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0..232"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(static_cast<void>(MakeDdsSink({232})));
}

TEST_F(DdsSinkTest, PublishBeforeOpenDoesNothing) {
  const auto sink = MakeDdsSink({206});
  EXPECT_EQ(sink->Describe(),
            "DDS domain 206 rt/<namespace>/{odom,pose,joint_states,timing,command}");
  sink->Publish(TwinRecord("x"));
  sink->PollCommands([](RemoteCommand, std::string&) { return true; });
}

}  // namespace
}  // namespace hiltwin::telemetry
