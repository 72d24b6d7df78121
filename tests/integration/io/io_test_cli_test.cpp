// `hiltwin io-test` as a user runs it: the built binary (HILTWIN_BINARY), exit codes and output.
#include <signal.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "hiltwin/io/wire_bus.h"
#include "fakes/process.h"

namespace hiltwin {
namespace {

test::RunResult IoTest(std::vector<std::string> args) {
  args.insert(args.begin(), {HILTWIN_BINARY, "io-test"});
  return test::Run(args);
}

TEST(IoTestCli, WrongBoardImageExitsFiveWithTheThesisStyleMessage) {
  const auto r = IoTest({"--io", "mock", "--board-image", "icoboard"});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("Failed to initialise FPGA: found icoboard, the twin needs icoboard_inverse"),
            std::string::npos)
      << r.err;
  const auto ecs = IoTest({"--io", "mock", "--image", "icoboard", "--board-image", "icoboard_inverse"});
  EXPECT_EQ(ecs.exit_code, 5);
  EXPECT_NE(ecs.err.find("found icoboard_inverse, the ECS needs icoboard"), std::string::npos) << ecs.err;
}

TEST(IoTestCli, JsonSummaryOfACleanMockRun) {
  for (const char* image : {"icoboard_inverse", "icoboard"}) {
    const auto r = IoTest({"--io", "mock", "--image", image, "--frames", "400", "--rate", "20000", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const auto j = nlohmann::json::parse(r.out);
    for (const char* key : {"frames_sent", "frames_received", "frames_corrupted", "frames_missed",
                            "count_errors"}) {
      EXPECT_TRUE(j.contains(key)) << key;
    }
    EXPECT_EQ(j["frames_sent"], 401);  // INIT + 400
    EXPECT_EQ(j["frames_received"], 401);
    EXPECT_EQ(j["frames_corrupted"], 0);
    EXPECT_EQ(j["frames_missed"], 0);
    EXPECT_EQ(j["count_errors"], 0);
    EXPECT_EQ(j["ok"], true);
  }
}

TEST(IoTestCli, UsageErrorsExitTwoAndSayWhatIsAccepted) {
  auto r = IoTest({"--io", "serial:/dev/ttyS0"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("accepted forms: mock, wire:NAME"), std::string::npos) << r.err;
  r = IoTest({"--io", "wire:x", "--board-image", "icoboard"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("mock"), std::string::npos) << r.err;
  r = IoTest({"--image", "inverse"});
  EXPECT_EQ(r.exit_code, 2);
  r = IoTest({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--board-image"), std::string::npos);
}

TEST(IoTestCli, MissingSpidevIsAnIoError) {
  const auto r = IoTest({"--io", "spidev:/dev/spidev97.3"});
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_NE(r.err.find("/dev/spidev97.3"), std::string::npos) << r.err;
}

TEST(IoTestCli, EcsSideOverTheWireWithATwinPeer) {
  const std::string name = "itest-cli-" + std::to_string(::getpid());
  io::WireBus::Unlink(name);
  const pid_t peer = test::Spawn({HILTWIN_WIRE_PEER, "twin", name, "1000"});
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto r = IoTest({"--io", "wire:" + name, "--image", "icoboard", "--frames", "400", "--rate",
                         "2000", "--json"});
  test::KillAndWait(peer, SIGTERM);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_received"], 401);
  EXPECT_EQ(j["peer_absent"], false);
}

}  // namespace
}  // namespace hiltwin
