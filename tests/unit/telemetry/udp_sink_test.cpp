// The UDP stream as PlotJuggler's UDP server receives it: one JSON object per datagram, the
// record under its namespace, a top-level timestamp in seconds, below 2 KB even for the
// longest namespace and four joints.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "fakes/udp_listener.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

TEST(UdpSink, SendsOneJsonObjectPerRecordKeyedByNamespaceBelowTwoKilobytes) {
  const test::UdpListener listener;
  const auto sink = MakeUdpSink({"127.0.0.1", listener.port()});
  const std::string ns = std::string(50, 'a') + "/" + std::string(49, 'b');  // 100 characters
  sink->Open({"twin", true, {"j0_long_joint_name", "j1_long_joint_name", "j2", "j3"}}, ns);
  runtime::TelemetryRecord r;
  r.ns = ns;
  r.role = "twin";
  r.time_s = 2.5;
  r.task.has_pose = true;
  r.task.x_m = -1.0e-300;  // the longest doubles
  r.task.y_m = 1.2345678901234567e-200;
  r.task.joint_count = 4;
  r.joint_names = {"j0_long_joint_name", "j1_long_joint_name", "j2", "j3"};
  r.task.joint_position_rad.fill(-1.2345678901234567e-200);
  r.task.joint_position_m.fill(-1.2345678901234567e-200);
  r.distance_to_violation = 4'000'000'000U;
  r.cycle = ~std::uint64_t{0};
  sink->Publish(r);
  const std::string datagram = listener.Receive(2000);
  ASSERT_FALSE(datagram.empty());
  EXPECT_LT(datagram.size(), 2048U);
  const auto j = nlohmann::json::parse(datagram);
  EXPECT_DOUBLE_EQ(j["timestamp"].get<double>(), 2.5);
  ASSERT_TRUE(j.contains(ns));
  EXPECT_FALSE(j[ns].contains("timestamp"));  // once, at the top, where PlotJuggler looks
  EXPECT_DOUBLE_EQ(j[ns]["pose"]["x"].get<double>(), -1.0e-300);
  EXPECT_EQ(j[ns]["wheels"].size(), 4U);
}

TEST(UdpSink, RefusesAHostThatIsNotANumericAddress) {
  try {
    static_cast<void>(MakeUdpSink({"plotjuggler.local", 9870}));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("numeric IPv4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hiltwin::telemetry
