// What RViz, Foxglove and PlotJuggler read from the DDS sink: nav_msgs/Odometry on rt/NS/odom,
// tf2_msgs/TFMessage on rt/tf, rosgraph_msgs/Clock on rt/clock (virtual clock), stamps in ROS
// time, the numeric codes of the verdict and the state, a first joint_states sample with its
// names, and the ROS 2 default QoS of each writer. Read back by an in-process reader.
#include <gtest/gtest.h>
#include <time.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dds_test_support.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

using test::WaitFor;

class DdsRosTopicsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { test::UseLoopbackDds(); }
};

// The shared twin record, paused and FLAGGED, heading 1 rad (a quaternion of half-angle 0.5).
runtime::TelemetryRecord Record(const std::string& ns) {
  runtime::TelemetryRecord r = test::TwinRecord(ns);
  r.state = lifecycle::State::kPaused;
  r.verdict_so_far = qos::Verdict::kFlagged;
  r.task.theta_rad = 1.0;
  return r;
}

double Seconds(const builtin_interfaces_msg_dds__Time_& t) { return t.sec + t.nanosec * 1e-9; }

double SystemNow() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

struct Frame {
  double stamp_s = -1.0;
  std::string frame_id, child_frame_id;
  std::array<double, 3> position{};
  std::array<double, 4> rotation{};  // x, y, z, w
};

struct Seen {
  std::vector<Frame> odom, tf;
  std::vector<double> twist_vx, covariance_sums;
  std::vector<double> clock_s;
  std::vector<double> joints_stamp_s;
  std::vector<std::size_t> joint_names;
  int verdict_code = -1, state_code = -1;
};

// Readers of every ROS topic the sink of `ns` writes, and a loop that takes what arrived.
class RosReaders {
 public:
  RosReaders(const test::Peer& peer, const std::string& ns)
      : odom_(peer.Reader(&nav_msgs_msg_dds__Odometry__desc, "rt/" + ns + "/odom")),
        tf_(peer.Reader(&tf2_msgs_msg_dds__TFMessage__desc, "rt/tf")),
        clock_(peer.Reader(&rosgraph_msgs_msg_dds__Clock__desc, "rt/clock")),
        joints_(peer.Reader(&sensor_msgs_msg_dds__JointState__desc, "rt/" + ns + "/joint_states")),
        timing_(peer.Reader(&hiltwin_msgs_msg_dds__Timing__desc, "rt/" + ns + "/timing", true)) {}

  [[nodiscard]] bool AllMatched() const {
    for (const dds_entity_t r : {odom_, tf_, joints_, timing_}) {
      dds_subscription_matched_status_t status{};
      if (dds_get_subscription_matched_status(r, &status) < 0 || status.current_count == 0) {
        return false;
      }
    }
    return true;
  }

  void Take(Seen& seen) const {
    while (test::TakeOne<nav_msgs_msg_dds__Odometry_>(odom_, [&](const auto& s) {
      const auto& p = s.pose.pose;
      seen.odom.push_back({Seconds(s.header.stamp),
                           s.header.frame_id,
                           s.child_frame_id,
                           {p.position.x, p.position.y, p.position.z},
                           {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w}});
      seen.twist_vx.push_back(s.twist.twist.linear.x);
      double sum = 0.0;
      for (const double c : s.pose.covariance) sum += std::abs(c);
      for (const double c : s.twist.covariance) sum += std::abs(c);
      seen.covariance_sums.push_back(sum);
    })) {
    }
    while (test::TakeOne<tf2_msgs_msg_dds__TFMessage_>(tf_, [&](const auto& s) {
      for (std::uint32_t i = 0; i < s.transforms._length; ++i) {
        const auto& t = s.transforms._buffer[i];
        const auto& v = t.transform.translation;
        const auto& q = t.transform.rotation;
        seen.tf.push_back({Seconds(t.header.stamp),
                           t.header.frame_id,
                           t.child_frame_id,
                           {v.x, v.y, v.z},
                           {q.x, q.y, q.z, q.w}});
      }
    })) {
    }
    while (test::TakeOne<rosgraph_msgs_msg_dds__Clock_>(
        clock_, [&](const auto& s) { seen.clock_s.push_back(Seconds(s.clock)); })) {
    }
    while (test::TakeOne<sensor_msgs_msg_dds__JointState_>(joints_, [&](const auto& s) {
      seen.joints_stamp_s.push_back(Seconds(s.header.stamp));
      seen.joint_names.push_back(s.name._length);
    })) {
    }
    while (test::TakeOne<hiltwin_msgs_msg_dds__Timing_>(timing_, [&](const auto& s) {
      seen.verdict_code = s.verdict_code;
      seen.state_code = s.state_code;
    })) {
    }
  }

 private:
  dds_entity_t odom_, tf_, clock_, joints_, timing_;
};

// Publishes `record` until every reader has a sample (matching takes a moment).
Seen PublishUntilSeen(runtime::TelemetrySink& sink, const RosReaders& readers,
                      const runtime::TelemetryRecord& record, bool want_clock) {
  Seen seen;
  EXPECT_TRUE(WaitFor([&] {
    sink.Publish(record);
    readers.Take(seen);
    return !seen.odom.empty() && !seen.tf.empty() && !seen.joints_stamp_s.empty() &&
           seen.verdict_code >= 0 && (!want_clock || !seen.clock_s.empty());
  }));
  return seen;
}

// A twin's sink on `domain`, opened, and the test's own readers of every topic it writes.
struct TwinOnDds {
  TwinOnDds(std::uint32_t domain, bool virtual_clock)
      : ns(test::UniqueNamespace("twin")), sink(MakeDdsSink({domain})), peer(domain) {
    sink->Open(test::TwinShape(virtual_clock), ns);
  }
  const std::string ns;
  const std::shared_ptr<runtime::TelemetrySink> sink;
  const test::Peer peer;
  const RosReaders readers{peer, ns};
};

void ExpectPoseFrame(const Frame& f, const std::string& ns) {
  EXPECT_EQ(f.frame_id, ns + "/odom");
  EXPECT_EQ(f.child_frame_id, ns + "/base_link");
  EXPECT_EQ(f.position, (std::array<double, 3>{0.5, -0.25, 0.0}));
  // Heading 1 rad about z: (0, 0, sin 0.5, cos 0.5).
  EXPECT_EQ(f.rotation[0], 0.0);
  EXPECT_EQ(f.rotation[1], 0.0);
  EXPECT_NEAR(f.rotation[2], std::sin(0.5), 1e-15);
  EXPECT_NEAR(f.rotation[3], std::cos(0.5), 1e-15);
}

TEST_F(DdsRosTopicsTest, OnTheVirtualClockOdometryTfAndClockCarryTheTasksTime) {
  const TwinOnDds twin(213, true);
  const std::string& ns = twin.ns;
  EXPECT_EQ(twin.sink->Describe(),
            "DDS domain 213 rt/" + ns + "/{odom,pose,joint_states,timing,command} rt/tf rt/clock");
  const Seen seen = PublishUntilSeen(*twin.sink, twin.readers, Record(ns), true);

  ASSERT_FALSE(seen.odom.empty());
  ExpectPoseFrame(seen.odom.front(), ns);
  ExpectPoseFrame(seen.tf.front(), ns);
  EXPECT_EQ(seen.covariance_sums.front(), 0.0) << "the twin's pose is the model's, exact";
  EXPECT_EQ(seen.odom.front().stamp_s, 12.25);
  EXPECT_EQ(seen.tf.front().stamp_s, 12.25);
  EXPECT_EQ(seen.joints_stamp_s.front(), 12.25);
  EXPECT_EQ(seen.clock_s.front(), 12.25);
  // PlotJuggler's numbers: FLAGGED 1, paused 3 (codes.h).
  EXPECT_EQ(seen.verdict_code, 1);
  EXPECT_EQ(seen.state_code, 3);
}

TEST_F(DdsRosTopicsTest, OnTheRealClockStampsAreSystemTimeAndThereIsNoClockTopic) {
  const TwinOnDds twin(214, false);
  EXPECT_EQ(twin.sink->Describe(),
            "DDS domain 214 rt/" + twin.ns + "/{odom,pose,joint_states,timing,command} rt/tf");
  const double before_s = SystemNow();
  const Seen seen = PublishUntilSeen(*twin.sink, twin.readers, Record(twin.ns), false);
  const double after_s = SystemNow();
  ASSERT_FALSE(seen.odom.empty());
  for (const double stamp_s :
       {seen.odom.front().stamp_s, seen.tf.front().stamp_s, seen.joints_stamp_s.front()}) {
    EXPECT_GE(stamp_s, before_s - 1e-6);
    EXPECT_LE(stamp_s, after_s + 1e-6);
  }
  EXPECT_EQ(seen.odom.front().stamp_s, seen.tf.front().stamp_s) << "one stamp per record";
  EXPECT_TRUE(seen.clock_s.empty()) << "/clock is the virtual clock's";
}

// The twist is the pose's change between two records over their task time, in base_link.
TEST_F(DdsRosTopicsTest, TwistIsTheBodyFrameVelocityBetweenRecords) {
  const TwinOnDds twin(215, true);
  const std::string& ns = twin.ns;
  const auto& sink = twin.sink;
  const RosReaders& readers = twin.readers;
  ASSERT_TRUE(WaitFor([&] { return readers.AllMatched(); }));
  runtime::TelemetryRecord r = Record(ns);
  sink->Publish(r);
  // In 0.5 s a 0.2 rad turn (1 to 1.2 rad) and a 0.1 m chord, which points along the heading
  // halfway through the arc (1.1 rad): 0.2 m/s forward, 0.4 rad/s.
  r.time_s += 0.5;
  r.task.x_m += 0.1 * std::cos(1.1);
  r.task.y_m += 0.1 * std::sin(1.1);
  r.task.theta_rad += 0.2;
  sink->Publish(r);
  Seen seen;
  ASSERT_TRUE(WaitFor([&] {
    readers.Take(seen);
    return seen.twist_vx.size() >= 2;
  }));
  EXPECT_EQ(seen.twist_vx[0], 0.0) << "no earlier record: no velocity";
  EXPECT_NEAR(seen.twist_vx[1], 0.2, 1e-12);
  EXPECT_EQ(seen.twist_vx.size(), 2U);
}

// Before the loop's first cycle the record has no values yet (joint_count 0): a JointState
// then had no names, and the first sample a subscriber got was empty.
TEST_F(DdsRosTopicsTest, TheFirstJointStateHasTheNamesAndValues) {
  const TwinOnDds twin(216, true);
  const std::string& ns = twin.ns;
  const auto& sink = twin.sink;
  const RosReaders& readers = twin.readers;
  ASSERT_TRUE(WaitFor([&] { return readers.AllMatched(); }));
  runtime::TelemetryRecord before_first_cycle = Record(ns);
  before_first_cycle.task = {};  // the mailbox's value before the loop wrote it
  sink->Publish(before_first_cycle);
  sink->Publish(Record(ns));
  Seen seen;
  ASSERT_TRUE(WaitFor([&] {
    readers.Take(seen);
    return !seen.joint_names.empty() && !seen.odom.empty();
  }));
  EXPECT_EQ(seen.joint_names.front(), 2U);
  EXPECT_EQ(seen.odom.front().position[0], 0.5) << "no pose of zeros before the first cycle";
}

// ROS 2's defaults, so a ROS 2 subscriber with its defaults matches: tf reliable, volatile,
// keep last 100 (tf2_ros's DynamicBroadcasterQoS); odometry reliable, volatile, keep last 10;
// /clock keep last 1 as rclcpp's ClockQoS, but reliable: it serves ClockQoS's best-effort
// subscribers and reliable ones alike.
TEST_F(DdsRosTopicsTest, WritersHaveRos2DefaultQos) {
  constexpr std::uint32_t kDomain = 217;
  const std::string ns = test::UniqueNamespace("twin");
  const auto sink = MakeDdsSink({kDomain});
  sink->Open(test::TwinShape(true), ns);
  const test::Peer peer(kDomain);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"  // Cyclone's pseudo-handle macro
  const dds_entity_t publications =
      dds_create_reader(peer.participant(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
#pragma GCC diagnostic pop
  struct Qos {
    dds_reliability_kind_t reliability{};
    dds_durability_kind_t durability{};
    std::int32_t depth = 0;
  };
  std::map<std::string, Qos> found;
  const std::map<std::string, std::string> types = {
      {"rt/tf", "tf2_msgs::msg::dds_::TFMessage_"},
      {"rt/clock", "rosgraph_msgs::msg::dds_::Clock_"},
      {"rt/" + ns + "/odom", "nav_msgs::msg::dds_::Odometry_"}};
  ASSERT_TRUE(WaitFor([&] {
    while (test::TakeOne<dds_builtintopic_endpoint_t>(publications, [&](const auto& ep) {
      const auto type = types.find(ep.topic_name);
      if (type == types.end() || type->second != ep.type_name) return;
      Qos q;
      dds_history_kind_t history{};
      dds_duration_t blocking = 0;
      dds_qget_reliability(ep.qos, &q.reliability, &blocking);
      dds_qget_durability(ep.qos, &q.durability);
      dds_qget_history(ep.qos, &history, &q.depth);
      found[ep.topic_name] = q;
    })) {
    }
    return found.size() == types.size();
  }));
  EXPECT_EQ(found["rt/tf"].reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(found["rt/tf"].durability, DDS_DURABILITY_VOLATILE);
  EXPECT_EQ(found["rt/tf"].depth, 100);
  EXPECT_EQ(found["rt/" + ns + "/odom"].reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(found["rt/" + ns + "/odom"].durability, DDS_DURABILITY_VOLATILE);
  EXPECT_EQ(found["rt/" + ns + "/odom"].depth, 10);
  EXPECT_EQ(found["rt/clock"].reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(found["rt/clock"].depth, 1);
}

// The controller of a lockstep pair shares its twin's virtual time: only the twin publishes
// /clock, or ROS time would step back and forth between the two (and tf2 clears its buffer).
TEST_F(DdsRosTopicsTest, ALockstepControllerPublishesNoClock) {
  constexpr std::uint32_t kDomain = 218;
  const std::string ns = test::UniqueNamespace("controller");
  const auto sink = MakeDdsSink({kDomain});
  runtime::TelemetryShape shape = test::TwinShape(true);
  shape.role = "controller";
  shape.has_pose = false;
  shape.lockstep = true;
  sink->Open(shape, ns);
  EXPECT_EQ(sink->Describe(), "DDS domain 218 rt/" + ns + "/{joint_states,timing,command}");
}

}  // namespace
}  // namespace hiltwin::telemetry
