// `hiltwin run --telemetry udp:127.0.0.1:PORT` received by a real UDP socket, as PlotJuggler's
// UDP server would: every datagram one JSON object below 2 KB with a timestamp in seconds,
// about --telemetry-rate of them per second, and a final record that agrees with the CSV log.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fakes/csv_table.h"
#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/udp_listener.h"

namespace hiltwin {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const char* name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("hiltwin-udp-" + std::string(name) + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// Every datagram until the final record (or 20 s of silence).
std::vector<nlohmann::json> ReceiveUntilFinal(const test::UdpListener& listener,
                                              const std::string& ns) {
  std::vector<nlohmann::json> received;
  for (;;) {
    const std::string datagram = listener.Receive(20'000);
    if (datagram.empty()) break;
    EXPECT_LT(datagram.size(), 2048U);
    received.push_back(nlohmann::json::parse(datagram));
    if (received.back()[ns]["final"].get<bool>()) break;
  }
  return received;
}

TEST(TelemetryUdp, AtTheConfiguredRateEveryDatagramIsJsonAndTheLastAgreesWithTheLog) {
  const fs::path dir = TempDir("rate");
  const test::UdpListener listener;
  constexpr double kSeconds = 3.0, kRateHz = 20.0;
  auto twin =
      test::Spawn({HILTWIN_BINARY, "run", "--rate", "1000", "--duration", "3", "--telemetry",
                   "udp:127.0.0.1:" + std::to_string(listener.port()), "--telemetry-rate", "20",
                   "--namespace", "bench7/twin", "--log", (dir / "twin.csv").string(), "--report",
                   (dir / "twin.json").string(), "--no-progress"},
                  (dir / "out.txt").string());
  const std::vector<nlohmann::json> got = ReceiveUntilFinal(listener, "bench7/twin");
  const int exit_code = twin.Wait().code;
  EXPECT_TRUE(exit_code == 0 || exit_code == 3) << exit_code;  // 3: a loaded machine flags it
  ASSERT_GE(got.size(), 2U);
  // One record per tick from before the first cycle to the end, plus the final one. A loaded
  // machine may skip ticks (they are not made up), never add any.
  const double expected = kSeconds * kRateHz;
  EXPECT_GE(static_cast<double>(got.size()), 0.6 * expected);
  EXPECT_LE(static_cast<double>(got.size()), expected + 3.0);
  for (std::size_t i = 1; i < got.size(); ++i) {
    EXPECT_GE(got[i]["timestamp"].get<double>(), got[i - 1]["timestamp"].get<double>()) << i;
  }
  const nlohmann::json& last = got.back()["bench7/twin"];
  EXPECT_TRUE(last["final"].get<bool>());
  EXPECT_EQ(last["state"], "stopped");
  EXPECT_EQ(last["cycle"], 3000);
  // The last record's verdict is the run's, whatever the machine made of it.
  std::ifstream report_file(dir / "twin.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  EXPECT_EQ(last["timing"]["verdict"], report["verdict"]);
  EXPECT_EQ(last["timing"]["deadline_misses"], report["deadline_misses"]);
  EXPECT_EQ(exit_code, report["verdict"] == "PASS" ? 0 : 3);
  const auto row = test::ReadCsvTable((dir / "twin.csv").string()).LastRow();
  EXPECT_DOUBLE_EQ(got.back()["timestamp"].get<double>(), row.at("time_s"));
  EXPECT_NEAR(last["pose"]["x"].get<double>(), row.at("x_m"), 1e-9);
  EXPECT_NEAR(last["pose"]["theta"].get<double>(), row.at("theta_rad"), 1e-9);
  EXPECT_NEAR(last["wheels"]["wheel_left_joint"]["m"].get<double>(), row.at("wheel_left_m"), 1e-9);
  EXPECT_GT(last["pose"]["x"].get<double>(), 0.1);  // the openloop input moved the robot
  fs::remove_all(dir);
}

// Both sides publish, each under its own namespace; both carry the controller's setpoint (issue
// 35): the controller as it follows it, the twin, which serves the page, because hil passes it
// the profile (--show-setpoint).
TEST(TelemetryUdp, HilPublishesBothSidesUnderItsNamespace) {
  const fs::path dir = TempDir("hil");
  const test::UdpListener listener;
  const fs::path setpoint = dir / "turn.csv";
  std::ofstream(setpoint) << "time,left_m,right_m\n0,0,0\n0.5,0.05,0.1\n";
  const test::RunResult r =
      test::Run({HILTWIN_BINARY, "hil", "--duration", "1", "--setpoint", setpoint.string(),
                 "--telemetry", "udp:127.0.0.1:" + std::to_string(listener.port()), "--namespace",
                 "lab/bench3", "--no-progress", "--log-dir", dir.string()},
                60'000);
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.out << r.err;  // 3: a loaded machine
  std::map<std::string, nlohmann::json> last;  // namespace -> its last record
  for (std::string d = listener.Receive(1000); !d.empty(); d = listener.Receive(200)) {
    const nlohmann::json datagram = nlohmann::json::parse(d);
    for (const auto& [key, value] : datagram.items()) {
      if (key != "timestamp") last[key] = value;
    }
  }
  ASSERT_EQ(last.size(), 2U);
  const nlohmann::json& twin = last["lab/bench3/twin"];
  const nlohmann::json& controller = last["lab/bench3/controller"];
  EXPECT_EQ(twin["role"], "twin");
  EXPECT_TRUE(twin["final"].get<bool>());
  EXPECT_TRUE(twin.contains("pose"));
  EXPECT_EQ(controller["role"], "controller");
  EXPECT_TRUE(controller["final"].get<bool>());
  EXPECT_FALSE(controller.contains("pose"));  // the controller does not know it
  // The controller's wheels are what its encoders read from the twin's: the same travel
  // within a few counts once both have stopped.
  const auto ecs_log = test::ReadCsvTable((dir / "ecs.csv").string()).LastRow();
  EXPECT_NEAR(controller["wheels"]["wheel_left_joint"]["m"].get<double>(),
              ecs_log.at("wheel_left_m"), 1e-9);
  // The setpoint the controller last followed, and the profile's end on the twin (it ran on).
  ASSERT_TRUE(controller.contains("setpoint")) << controller.dump();
  EXPECT_NEAR(controller["setpoint"]["wheel_left_joint"]["m"].get<double>(),
              ecs_log.at("setpoint_left_m"), 1e-9);
  EXPECT_NEAR(controller["setpoint"]["wheel_right_joint"]["m"].get<double>(),
              ecs_log.at("setpoint_right_m"), 1e-9);
  ASSERT_TRUE(twin.contains("setpoint")) << twin.dump();
  EXPECT_EQ(twin["setpoint"]["wheel_left_joint"]["m"].get<double>(), 0.05);
  EXPECT_EQ(twin["setpoint"]["wheel_right_joint"]["m"].get<double>(), 0.1);
  fs::remove_all(dir);
}

// `run --show-setpoint` sends a setpoint profile with the twin's telemetry, sampled at the
// twin's own time: in a run of 0.3 s on the virtual clock the final record's is the ramp's at
// 0.3 s. Without any telemetry it would do nothing: exit 2, as for a profile it cannot read.
TEST(TelemetryUdp, RunShowsTheSetpointAtTheTwinsTimeAndRefusesItWithoutTelemetry) {
  const fs::path dir = TempDir("show");
  const fs::path setpoint = dir / "ramp.csv";
  std::ofstream(setpoint) << "time,left_m,right_m\n0,0,0\n1,0.5,-1\n";
  const test::UdpListener listener;
  const test::RunResult r =
      test::Run({HILTWIN_BINARY, "run", "--clock", "virtual", "--duration", "0.3",
                 "--show-setpoint", setpoint.string(), "--telemetry",
                 "udp:127.0.0.1:" + std::to_string(listener.port()), "--namespace", "t",
                 "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::vector<nlohmann::json> got = ReceiveUntilFinal(listener, "t");
  ASSERT_FALSE(got.empty());
  const nlohmann::json& last = got.back()["t"];
  ASSERT_TRUE(last.contains("setpoint")) << last.dump();
  EXPECT_NEAR(last["setpoint"]["wheel_left_joint"]["m"].get<double>(), 0.15, 1e-12);
  EXPECT_NEAR(last["setpoint"]["wheel_right_joint"]["m"].get<double>(), -0.3, 1e-12);
  EXPECT_DOUBLE_EQ(got.back()["timestamp"].get<double>(), 0.3);

  const test::RunResult alone = test::Run({HILTWIN_BINARY, "run", "--clock", "virtual",
                                           "--duration", "0.1", "--show-setpoint", "closedloop"});
  EXPECT_EQ(alone.exit_code, 2) << alone.out << alone.err;
  EXPECT_NE(alone.err.find("--show-setpoint"), std::string::npos) << alone.err;
  EXPECT_NE(alone.err.find("--web"), std::string::npos) << alone.err;
  const test::RunResult missing =
      test::Run({HILTWIN_BINARY, "run", "--clock", "virtual", "--duration", "0.1",
                 "--show-setpoint", (dir / "missing.csv").string(), "--telemetry", "udp"});
  EXPECT_EQ(missing.exit_code, 2) << missing.out << missing.err;
  EXPECT_NE(missing.err.find("--show-setpoint"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("missing.csv"), std::string::npos) << missing.err;
  fs::remove_all(dir);
}

TEST(TelemetryUdp, ABadSpecIsExitTwoNamingTheFlag) {
  const test::RunResult r = test::Run(
      {HILTWIN_BINARY, "run", "--clock", "virtual", "--duration", "1", "--telemetry", "udp:host"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--telemetry udp:"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace hiltwin
