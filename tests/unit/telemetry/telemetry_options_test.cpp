// The telemetry flags: what each spec means, and what a mistake is told.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "hiltwin/telemetry/record_json.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

/// The message of the std::invalid_argument `f` throws ("" if it does not).
template <typename F>
std::string Refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

/// Sets an environment variable for one scope (unset: nullptr), then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): tests, one thread
    if (old != nullptr) old_ = old;
    Set(value);
  }
  ~ScopedEnv() { Set(old_ ? old_->c_str() : nullptr); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  void Set(const char* value) const {
    // NOLINTNEXTLINE(concurrency-mt-unsafe): tests, one thread
    value != nullptr ? ::setenv(name_, value, 1) : ::unsetenv(name_);
  }
  const char* name_;
  std::optional<std::string> old_;
};

TEST(TelemetryOptions, DdsSpecsTakeADomainOrDefaultToZero) {
  const ScopedEnv env("ROS_DOMAIN_ID", nullptr);
  const auto dds = ParseDdsSpecs({"dds", "udp", "dds:7"});
  ASSERT_EQ(dds.size(), 2U);
  EXPECT_EQ(dds[0].domain, 0U);
  EXPECT_EQ(dds[1].domain, 7U);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseDdsSpecs({"dds:233"})); }).find("0 to 232"),
            std::string::npos);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseDdsSpecs({"dds:x"})); }).find("'dds:x'"),
            std::string::npos);
  EXPECT_NE(Refusal([] {
              static_cast<void>(ParseDdsSpecs({"dds:3", "dds:3"}));
            }).find("twice"),
            std::string::npos);
}

// As for every ROS 2 tool, ROS_DOMAIN_ID is the domain when the flag names none.
TEST(TelemetryOptions, RosDomainIdIsTheDefaultDomainAndTheFlagsDomainWins) {
  const ScopedEnv env("ROS_DOMAIN_ID", "42");
  const auto dds = ParseDdsSpecs({"dds", "dds:7"});
  ASSERT_EQ(dds.size(), 2U);
  EXPECT_EQ(dds[0].domain, 42U);
  EXPECT_EQ(dds[1].domain, 7U);
  const ScopedEnv empty("ROS_DOMAIN_ID", "");  // ROS 2 reads an empty variable as unset
  EXPECT_EQ(ParseDdsSpecs({"dds"})[0].domain, 0U);
}

// Not silently 0: a domain the user did not mean would show nothing, with no word why.
TEST(TelemetryOptions, AnInvalidRosDomainIdIsRefusedNamingTheVariable) {
  for (const char* value : {"233", "abc", "-1", "4x", " 5", "99999999999"}) {
    SCOPED_TRACE(value);
    const ScopedEnv env("ROS_DOMAIN_ID", value);
    const std::string why = Refusal([] { static_cast<void>(ParseDdsSpecs({"dds"})); });
    EXPECT_NE(why.find("ROS_DOMAIN_ID='" + std::string(value) + "'"), std::string::npos) << why;
    EXPECT_NE(why.find("0 to 232"), std::string::npos) << why;
    EXPECT_NE(why.find("--telemetry dds"), std::string::npos) << why;
    // A domain given with the flag does not read the variable.
    EXPECT_EQ(ParseDdsSpecs({"dds:3"})[0].domain, 3U);
  }
}

TEST(TelemetryOptions, UdpSpecsDefaultToPlotJugglersPort) {
  const auto udp = ParseUdpSpecs({"udp", "udp:10.0.0.2:9999", "dds"});
  ASSERT_EQ(udp.size(), 2U);
  EXPECT_EQ(udp[0].host, "127.0.0.1");
  EXPECT_EQ(udp[0].port, 9870);
  EXPECT_EQ(udp[1].host, "10.0.0.2");
  EXPECT_EQ(udp[1].port, 9999);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseUdpSpecs({"udp:host"})); }).find("HOST:PORT"),
            std::string::npos);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseUdpSpecs({"udp:1.2.3.4:0"})); }).find("1 to 65535"),
            std::string::npos);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseUdpSpecs({"plotjuggler"})); }).find("unknown kind"),
            std::string::npos);
}

TEST(TelemetryOptions, WebTakesAddressAndPortOrAPort) {
  EXPECT_EQ(ParseWebSpec("0.0.0.0:8081").address, "0.0.0.0");
  EXPECT_EQ(ParseWebSpec("0.0.0.0:8081").port, 8081);
  EXPECT_EQ(ParseWebSpec("9000").address, "127.0.0.1");
  EXPECT_EQ(ParseWebSpec("9000").port, 9000);
  EXPECT_NE(Refusal([] { static_cast<void>(ParseWebSpec("99999")); }).find("--web '99999'"),
            std::string::npos);
}

TEST(TelemetryOptions, NamespacesAreRos2Names) {
  EXPECT_NO_THROW(CheckNamespace("twin"));
  EXPECT_NO_THROW(CheckNamespace("lab_2/bench1/twin"));
  for (const char* bad : {"", "/twin", "twin/", "a//b", "1twin", "a/2b", "be nch", "tw-in"}) {
    EXPECT_NE(Refusal([bad] { CheckNamespace(bad); }).find("--namespace"), std::string::npos)
        << bad;
  }
  EXPECT_NE(Refusal([] { CheckNamespace("tw-in"); }).find("character 3 ('-')"), std::string::npos);
  EXPECT_NE(Refusal([] { CheckNamespace(std::string(101, 'a')); }).find("longer than 100"),
            std::string::npos);
}

TEST(TelemetryOptions, NoFlagMeansNoSinksAndNothingChecked) {
  TelemetryOptions options;
  options.ns = "not checked when off";
  EXPECT_TRUE(MakeTelemetryConfig(options).sinks.empty());
  options.specs = {"udp:127.0.0.1:9"};
  options.ns = "twin";
  options.rate_hz = 0.0;
  EXPECT_NE(
      Refusal([&] { static_cast<void>(MakeTelemetryConfig(options)); }).find("--telemetry-rate"),
      std::string::npos);
  options.rate_hz = 20.0;
  const runtime::TelemetryConfig config = MakeTelemetryConfig(options);
  ASSERT_EQ(config.sinks.size(), 1U);
  EXPECT_EQ(config.sinks[0]->Describe(), "PlotJuggler UDP 127.0.0.1:9");
  EXPECT_DOUBLE_EQ(config.rate_hz, 20.0);
  EXPECT_EQ(config.ns, "twin");
}

TEST(TelemetryOptions, AcceptCommandsNeedsADdsSpec) {
  TelemetryOptions options;
  options.ns = "twin";
  options.accept_commands = true;
  options.specs = {"udp"};
  const std::string why = Refusal([&] { CheckAcceptCommands(options); });
  EXPECT_NE(why.find("--accept-commands"), std::string::npos) << why;
  EXPECT_NE(why.find("--telemetry dds"), std::string::npos) << why;
  EXPECT_NE(Refusal([&] { static_cast<void>(MakeTelemetryConfig(options)); })
                .find("--accept-commands"),
            std::string::npos);
  options.specs = {"udp", "dds:3"};
  EXPECT_NO_THROW(CheckAcceptCommands(options));
}

TEST(RecordJson, HasEveryDocumentedKeyAndNullForADistanceThatCannotFail) {
  runtime::TelemetryRecord r;
  r.ns = "twin";
  r.role = "twin";
  r.rate_hz = 4000.0;
  r.time_s = 1.25;
  r.cycle = 5000;
  r.state = lifecycle::State::kRun;
  r.task.has_pose = true;
  r.task.x_m = 0.5;
  r.task.theta_rad = -0.25;
  r.task.joint_count = 2;
  r.task.joint_position_rad = {2.0, 4.0};
  r.task.joint_position_m = {0.1, 0.2};
  r.joint_names = {"wheel_left_joint", "wheel_right_joint"};
  r.latency_p99_us = 12.5;
  nlohmann::ordered_json j = ToJson(r);
  EXPECT_DOUBLE_EQ(j["timestamp"].get<double>(), 1.25);
  EXPECT_EQ(j["state"], "run");
  EXPECT_DOUBLE_EQ(j["pose"]["theta"].get<double>(), -0.25);
  EXPECT_DOUBLE_EQ(j["wheels"]["wheel_right_joint"]["rad"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(j["wheels"]["wheel_left_joint"]["m"].get<double>(), 0.1);
  EXPECT_TRUE(j["timing"]["distance_to_violation"].is_null());
  EXPECT_EQ(j["timing"]["verdict"], "PASS");
  // Numbers beside the strings, which PlotJuggler drops (codes.h; docs/telemetry.md's table).
  EXPECT_EQ(j["state_code"], 2);
  EXPECT_EQ(j["timing"]["verdict_code"], 0);
  EXPECT_DOUBLE_EQ(j["timing"]["latency_p99_us"].get<double>(), 12.5);
  r.distance_to_violation = 3;
  r.task.has_pose = false;
  r.verdict_so_far = qos::Verdict::kFlagged;
  r.state = lifecycle::State::kSafeStop;
  j = ToJson(r);
  EXPECT_EQ(j["state_code"], 7);
  EXPECT_EQ(j["timing"]["verdict_code"], 1);
  EXPECT_EQ(j["timing"]["distance_to_violation"], 3);
  EXPECT_FALSE(j.contains("pose"));  // a controller has none
}

// A closed-loop controller's setpoint, per joint as wheel travel (m), beside its wheels; a
// record without one (a twin, an open loop) has no "setpoint" at all.
TEST(RecordJson, CarriesTheSetpointPerJointOnlyWhenTheTaskHasOne) {
  runtime::TelemetryRecord r;
  r.role = "controller";
  r.task.joint_count = 2;
  r.task.joint_position_m = {0.1, 0.2};
  r.joint_names = {"wheel_left_joint", "wheel_right_joint"};
  EXPECT_FALSE(ToJson(r).contains("setpoint"));
  r.task.has_setpoint = true;
  r.task.joint_setpoint_m = {0.125, -0.25};
  const nlohmann::ordered_json j = ToJson(r);
  ASSERT_TRUE(j.contains("setpoint")) << j.dump();
  EXPECT_EQ(j["setpoint"].size(), 2U) << j.dump();
  EXPECT_EQ(j["setpoint"]["wheel_left_joint"]["m"].get<double>(), 0.125);
  EXPECT_EQ(j["setpoint"]["wheel_right_joint"]["m"].get<double>(), -0.25);
  EXPECT_EQ(j["wheels"]["wheel_left_joint"]["m"].get<double>(), 0.1);  // still the measured
}

}  // namespace
}  // namespace hiltwin::telemetry
