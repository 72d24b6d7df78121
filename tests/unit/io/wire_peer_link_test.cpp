// The wire's peer link, both sides in one process (they are different sides, so both may attach):
// a side that waits keeps its heartbeat fresh with Poll, and a side that stops tells the other
// why, so the other sees kPeerStopped (a clean end) instead of a lost heartbeat (a fault).
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"

namespace hiltwin::io {
namespace {

std::string FreshPeerName(const char* tag) {
  const std::string name = std::string("utest-peer-") + tag + "-" + std::to_string(::getpid());
  WireBus::Unlink(name);
  return name;
}

TEST(WirePeerLink, PollSaysWhetherThePeerIsThereAndKeepsThisSideAlive) {
  const std::string name = FreshPeerName("poll");
  WireBus twin(name, Image::kIcoboardInverse);
  EXPECT_EQ(twin.Poll().result, BusResult::kPeerAbsent);
  WireBus ecs(name, Image::kIcoboard);
  EXPECT_EQ(ecs.Poll().result, BusResult::kOk);  // the twin polled already: it is up
  EXPECT_EQ(twin.Poll().result, BusResult::kOk);
}

// Attaching is not being up: a side counts from its first beat. Before it, it may still be in
// its real-time set-up (which may outlast the heartbeat timeout), so its peer must neither start
// against it nor, later, call it lost.
TEST(WirePeerLink, AnAttachedSideThatHasNotBeatenYetIsAbsentNotUp) {
  const std::string name = FreshPeerName("setup");
  WireBus twin(name, Image::kIcoboardInverse);
  ASSERT_EQ(twin.Poll().result, BusResult::kPeerAbsent);
  WireBus ecs(name, Image::kIcoboard);  // attached, still setting up: no Poll, no transfer
  const BusStatus before = twin.Poll();
  EXPECT_EQ(before.result, BusResult::kPeerAbsent);
  EXPECT_STREQ(before.reason, "wire: an ECS process has attached but not started (no heartbeat "
                              "yet)");
  // Set-up longer than the heartbeat timeout: still absent, never lost.
  std::this_thread::sleep_for(std::chrono::nanoseconds(kWireMinHeartbeatTimeoutNs) +
                              std::chrono::milliseconds(50));
  EXPECT_EQ(twin.Poll().result, BusResult::kPeerAbsent);
  EXPECT_EQ(ecs.Poll().result, BusResult::kOk);  // its first beat: the twin beat already
  EXPECT_EQ(twin.Poll().result, BusResult::kOk);
}

TEST(WirePeerLink, AnAnnouncedStopReachesThePeerWithItsCause) {
  const std::string name = FreshPeerName("stop");
  WireBus twin_bus(name, Image::kIcoboardInverse);
  WireBus ecs_bus(name, Image::kIcoboard);
  IcoBoard ecs(ecs_bus);
  IcoBoardInverse twin(twin_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);
  EcsInputs in{};
  const std::array<std::int32_t, kChannels> pwm{};
  ExchangeStatus status = ecs.Exchange(pwm, in);
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.peer_stopped, nullptr);

  twin_bus.AnnounceStop(StopCause::kQosAbort);
  status = ecs.Exchange(pwm, in);
  EXPECT_TRUE(status.ok()) << status.reason;  // the ECS's own board still answered
  ASSERT_NE(status.peer_stopped, nullptr);
  EXPECT_STREQ(status.peer_stopped, "wire: the twin aborted its run on its QoS policy");
  EXPECT_EQ(ecs_bus.Poll().result, BusResult::kPeerStopped);

  ecs_bus.AnnounceStop(StopCause::kPeerStopped);
  EXPECT_STREQ(twin_bus.PeerStatus().reason,
               "wire: the ECS stopped because its peer had stopped");
}

TEST(WirePeerLink, AStoppedPeerThatDetachedStaysStoppedNotLost) {
  const std::string name = FreshPeerName("detach");
  WireBus twin(name, Image::kIcoboardInverse);
  {
    WireBus ecs(name, Image::kIcoboard);
    ecs.AnnounceStop(StopCause::kFinished);
  }
  const BusStatus status = twin.PeerStatus();
  EXPECT_EQ(status.result, BusResult::kPeerStopped);
  EXPECT_STREQ(status.reason, "wire: the ECS finished its run");
  // A new ECS on the same wire starts afresh: its stop cause is cleared when it attaches.
  WireBus next(name, Image::kIcoboard);
  static_cast<void>(next.Poll());  // its first beat: up from here
  EXPECT_EQ(twin.Poll().result, BusResult::kOk);
}

TEST(WirePeerLink, OnlyTheWireBackendHasAPeer) {
  EXPECT_EQ(OpenBackend("mock", {})->peer_link(), nullptr);
  const std::string name = FreshPeerName("backend");
  EXPECT_NE(OpenBackend("wire:" + name, {})->peer_link(), nullptr);
}

TEST(WireBus, AnExchangeIsTheRequestAndItsFetchOnThisSidesBoard) {
  // The driver's request transfer and its NOOP fetch run against this side's board as one
  // exchange: the ALL publishes one encoder period, the fetch none, and the fetch carries the
  // ALL's answer (with the PWM the ECS put on the wire).
  const std::string name = FreshPeerName("pair");
  WireBus twin_bus(name, Image::kIcoboardInverse);
  WireBus ecs_bus(name, Image::kIcoboard);
  IcoBoard ecs(ecs_bus);
  IcoBoardInverse twin(twin_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);  // publishes period 1 (position 0)
  ASSERT_TRUE(ecs.Init(1'000'000).ok);
  EcsInputs ecs_in{};
  ASSERT_TRUE(ecs.Exchange({1000, 0, 0, 0}, ecs_in).ok());
  TwinInputs twin_in{};
  const ExchangeStatus status = twin.Exchange({100, 0, 0, 0}, twin_in);
  ASSERT_TRUE(status.ok()) << status.reason;
  EXPECT_EQ(twin_in.pwm[0], 1000);
  EXPECT_EQ(twin_bus.board().data_frames(), 1U);
  EncoderPeriod period;
  ASSERT_TRUE(twin_bus.ReadEncoderPeriod(2, period));
  EXPECT_EQ(period.channels[0].pulses, 100U);
  EXPECT_FALSE(twin_bus.ReadEncoderPeriod(3, period));  // the fetch published nothing
  EXPECT_EQ(twin.timing().transfers, 2U);               // INIT and the ALL: one per exchange
}

TEST(StopCause, NamesMatchTheRunReportsStopReasons) {
  EXPECT_STREQ(ToString(StopCause::kFinished), "finished");
  EXPECT_STREQ(ToString(StopCause::kStopRequested), "stop_requested");
  EXPECT_STREQ(ToString(StopCause::kQosAbort), "qos_abort");
  EXPECT_STREQ(ToString(StopCause::kPeerStopped), "peer_stopped");
}

}  // namespace
}  // namespace hiltwin::io
