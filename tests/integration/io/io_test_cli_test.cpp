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
                            "count_errors", "counts_over_limit", "frames_peer_absent",
                            "reader_illegal_transitions", "reader_too_fast_edges", "reader_resyncs"}) {
      EXPECT_TRUE(j.contains(key)) << key;
    }
    EXPECT_EQ(j["counts_over_limit"], 0);
    // Data frames only: 300 of the 400 transfers; the INIT and the 100 TEST loop-backs apart.
    EXPECT_EQ(j["frames_sent"], 300);
    EXPECT_EQ(j["frames_received"], 300);
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
  r = IoTest({"--io", "mock", "--wait-peer", "5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--wait-peer only applies to --io wire:NAME"), std::string::npos) << r.err;
  r = IoTest({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--board-image"), std::string::npos);
  EXPECT_NE(r.out.find("--wait-peer"), std::string::npos);
  EXPECT_NE(r.out.find("every 4th is a TEST loop-back"), std::string::npos) << r.out;
}

TEST(IoTestCli, MissingSpidevIsAnIoError) {
  const auto r = IoTest({"--io", "spidev:/dev/spidev97.3"});
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_NE(r.err.find("/dev/spidev97.3"), std::string::npos) << r.err;
}

std::string WireName(const char* tag) {
  const std::string name = std::string("itest-cli-") + tag + "-" + std::to_string(::getpid());
  io::WireBus::Unlink(name);
  return name;
}

/// A background process for the other end of a wire; its output goes to a file removed on Stop.
class Peer {
 public:
  explicit Peer(const std::vector<std::string>& argv)
      : out_("/tmp/hiltwin-io-cli-peer-" + std::to_string(::getpid())),
        process_(test::Spawn(argv, out_)) {}
  ~Peer() {
    process_.Kill(SIGTERM);
    ::unlink(out_.c_str());
    ::unlink((out_ + ".err").c_str());
  }
  Peer(const Peer&) = delete;
  Peer& operator=(const Peer&) = delete;

 private:
  std::string out_;
  kernel_glue::Process process_;
};

/// The other side of a wire bring-up: `hiltwin io-test` in the background, long enough to outlast
/// the run under test (stopped when the Peer goes).
std::vector<std::string> IoTestPeer(const std::string& name, const char* image) {
  return {HILTWIN_BINARY, "io-test", "--io", "wire:" + name, "--image", image, "--frames",
          "1000000", "--rate", "1000", "--wait-peer", "30"};
}

/// io-test as `image` over a fresh wire, against io-test as `peer_image` in another process.
test::RunResult IoTestAgainstIoTestPeer(const char* tag, const char* image, const char* peer_image) {
  const std::string name = WireName(tag);
  const Peer peer(IoTestPeer(name, peer_image));
  return IoTest({"--io", "wire:" + name, "--image", image, "--frames", "400", "--rate", "2000",
                 "--wait-peer", "20", "--json"});
}

TEST(IoTestCli, EcsSideOverTheWireChecksTheTwinIoTestsPattern) {
  const test::RunResult r = IoTestAgainstIoTestPeer("ecs", "icoboard", "icoboard_inverse");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_received"], 300);  // data frames
  EXPECT_EQ(j["peer_absent"], false);
  EXPECT_EQ(j["frames_peer_absent"], 0);
  EXPECT_EQ(j["count_errors"], 0);
  EXPECT_EQ(j["reader_illegal_transitions"], 0);
  EXPECT_EQ(j["reader_resyncs"], 0);
}

TEST(IoTestCli, TwinSideOverTheWireChecksTheEcsIoTestsPattern) {
  const test::RunResult r = IoTestAgainstIoTestPeer("twin", "icoboard_inverse", "icoboard");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_received"], 300);  // data frames
  EXPECT_EQ(j["frames_peer_absent"], 0);
  EXPECT_EQ(j["count_errors"], 0);
}

TEST(IoTestCli, APeerThatDoesNotSendThePatternIsCaught) {
  // hiltwin_io_wire_peer's twin echoes the PWM as encoder positions: values cross, but they are not
  // io-test's pattern, so the data check across the wire must fail the run.
  const std::string name = WireName("echo");
  test::RunResult r;
  {
    const Peer echo({HILTWIN_WIRE_PEER, "twin", name, "1000"});
    r = IoTest({"--io", "wire:" + name, "--image", "icoboard", "--frames", "400", "--rate", "2000",
                "--wait-peer", "20", "--json"});
  }
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames_peer_absent"], 0);
  EXPECT_GT(j["count_errors"], 0);
  EXPECT_EQ(j["ok"], false);
  EXPECT_NE(r.err.find("the other side must run io-test too"), std::string::npos) << r.err;
}

TEST(IoTestCli, AWireWithNoPeerForTheWholeRunExitsFive) {
  const std::string name = WireName("alone");
  auto r = IoTest({"--io", "wire:" + name, "--frames", "40", "--rate", "1000", "--json"});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["peer_absent"], true);
  EXPECT_EQ(j["frames_peer_absent"], 40);
  EXPECT_EQ(j["ok"], false);
  EXPECT_NE(r.err.find("no ECS process was attached to wire:" + name + " during the whole run"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("hiltwin io-test --io wire:" + name + " --image icoboard "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--wait-peer"), std::string::npos) << r.err;

  // Waiting for a peer that never comes ends the same way, before INIT.
  r = IoTest({"--io", "wire:" + name, "--image", "icoboard", "--wait-peer", "0.3"});
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_NE(r.err.find("no twin process attached to wire:" + name + " within 0.3 s"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--image icoboard_inverse"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace hiltwin
