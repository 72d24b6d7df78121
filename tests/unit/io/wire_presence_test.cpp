// When a side is on the wire (issue 34): present only once its set-up is done, that is from
// its first poll (or, in a run that does not wait for its peer, its first exchange after INIT),
// never from the INIT exchange of its option handling; and attached only while its process
// lives, which the kernel says at the process's death, before any parent reaps it. Both sides
// in this process, or a forked peer for the process cases.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>

#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "wire_poll.h"

namespace hiltwin::io {
namespace {

using Wall = std::chrono::steady_clock;

std::string FreshPresenceName(const char* tag) {
  const std::string name = std::string("utest-here-") + tag + "-" + std::to_string(::getpid());
  WireBus::Unlink(name);
  return name;
}

/// A forked ECS on `name` that comes up beside the twin and then only polls until killed.
pid_t StartPollingEcs(const std::string& name) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    WireBus ecs(name, Image::kIcoboard);
    if (!PollUntilUp(ecs)) ::_exit(1);
    for (;;) {
      static_cast<void>(ecs.Poll());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  return pid;
}

/// Whether `pid` is a zombie now: dead, not yet reaped.
bool IsZombie(pid_t pid) {
  siginfo_t info{};
  return ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
         info.si_pid == pid;
}

/// Sends SIGKILL to `pid` and returns once it is a zombie (not reaped); false after 5 s.
bool KillLeavingAZombie(pid_t pid) {
  ::kill(pid, SIGKILL);
  const Wall::time_point deadline = Wall::now() + std::chrono::seconds(5);
  while (!IsZombie(pid) && Wall::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return IsZombie(pid);
}

// Issue 34, 1: the INIT exchange runs while the command handles its options, before the
// session's real-time set-up (hundreds of ms under load). A beat there made a waiting peer
// start at once and then, the set-up outlasting the heartbeat timeout, call this side dead.
TEST(WirePresence, AnInitExchangeDoesNotMakeASidePresentItsFirstPollDoes) {
  const std::string name = FreshPresenceName("init");
  WireBus twin_bus(name, Image::kIcoboardInverse);
  IcoBoardInverse twin(twin_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);
  ASSERT_EQ(twin_bus.Poll().result, BusResult::kPeerAbsent);  // the twin waits for its peer
  WireBus ecs_bus(name, Image::kIcoboard);
  IcoBoard ecs(ecs_bus);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);  // option handling: not present yet
  const BusStatus after_init = twin_bus.Poll();
  EXPECT_EQ(after_init.result, BusResult::kPeerAbsent) << after_init.reason;
  EXPECT_STREQ(after_init.reason,
               "wire: an ECS process has attached but not started (no heartbeat yet)");
  // Its set-up outlasts the heartbeat timeout: still absent, never lost.
  std::this_thread::sleep_for(std::chrono::nanoseconds(kWireMinHeartbeatTimeoutNs) +
                              std::chrono::milliseconds(50));
  EXPECT_EQ(twin_bus.Poll().result, BusResult::kPeerAbsent);
  EXPECT_EQ(ecs_bus.Poll().result, BusResult::kOk);  // set-up done, it waits: present
  EXPECT_EQ(twin_bus.Poll().result, BusResult::kOk);
}

// A run with --wait-peer 0 does not poll: its loop's first exchange, after INIT, is its first
// sign of life.
TEST(WirePresence, WithoutAWaitTheFirstExchangeAfterInitMakesASidePresent) {
  const std::string name = FreshPresenceName("nowait");
  WireBus twin_bus(name, Image::kIcoboardInverse);
  WireBus ecs_bus(name, Image::kIcoboard);
  IcoBoard ecs(ecs_bus);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);
  EXPECT_EQ(twin_bus.Poll().result, BusResult::kPeerAbsent);
  EcsInputs in{};
  EXPECT_TRUE(ecs.Exchange({0, 0, 0, 0}, in).ok());
  EXPECT_EQ(twin_bus.Poll().result, BusResult::kOk);
}

// Issue 34, "zombie": a killed peer whose parent has not reaped it yet still answers
// kill(pid, 0), but it is gone: its side is free for a new process...
TEST(WirePresence, AKilledPeerNotYetReapedNoLongerHoldsItsSide) {
  const std::string name = FreshPresenceName("zombie-side");
  WireBus twin(name, Image::kIcoboardInverse);
  const pid_t child = StartPollingEcs(name);
  ASSERT_GT(child, 0);
  ASSERT_TRUE(PollUntilUp(twin));
  ASSERT_TRUE(KillLeavingAZombie(child));
  try {
    WireBus next_ecs(name, Image::kIcoboard);
  } catch (const std::runtime_error& e) {
    ADD_FAILURE() << e.what();
  }
  EXPECT_TRUE(IsZombie(child)) << "reaped during the test: it proves nothing";
  ::waitpid(child, nullptr, 0);
}

// ...and the side left alone is the last one out, which removes the segment.
TEST(WirePresence, AKilledPeerNotYetReapedLeavesTheSegmentToTheLastSideOut) {
  const std::string name = FreshPresenceName("zombie-unlink");
  pid_t child = -1;
  {
    WireBus twin(name, Image::kIcoboardInverse);
    child = StartPollingEcs(name);
    ASSERT_GT(child, 0);
    ASSERT_TRUE(PollUntilUp(twin));
    ASSERT_TRUE(KillLeavingAZombie(child));
  }
  EXPECT_FALSE(std::filesystem::exists(WireBus::SegmentPath(name)))
      << "the segment was left behind beside a dead, unreaped ECS";
  EXPECT_TRUE(IsZombie(child)) << "reaped during the test: it proves nothing";
  ::waitpid(child, nullptr, 0);
  WireBus::Unlink(name);
}

// A live process on a side keeps it: a second one is refused, naming the first.
TEST(WirePresence, ASecondLiveProcessOnTheSameSideIsRefused) {
  const std::string name = FreshPresenceName("second");
  WireBus twin(name, Image::kIcoboardInverse);
  const pid_t child = StartPollingEcs(name);
  ASSERT_GT(child, 0);
  ASSERT_TRUE(PollUntilUp(twin));
  std::string refusal;
  try {
    WireBus second_ecs(name, Image::kIcoboard);
  } catch (const std::runtime_error& e) {
    refusal = e.what();
  }
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  EXPECT_EQ(refusal, "wire:" + name + " already has an ECS attached (pid " +
                         std::to_string(child) + "); stop it first or use another wire name");
}

// The lock belongs to an open file, not to a process: a second bus on a side in the same
// process (two sessions of one program) is refused as well.
TEST(WirePresence, ASecondBusOnTheSameSideInOneProcessIsRefused) {
  const std::string name = FreshPresenceName("twice");
  WireBus first(name, Image::kIcoboardInverse);
  std::string refusal;
  try {
    WireBus second(name, Image::kIcoboardInverse);
  } catch (const std::runtime_error& e) {
    refusal = e.what();
  }
  EXPECT_EQ(refusal, "wire:" + name + " already has a twin attached (pid " +
                         std::to_string(::getpid()) + "); stop it first or use another wire name");
  EXPECT_EQ(first.Poll().result, BusResult::kPeerAbsent);  // the first is still attached, alone
}

}  // namespace
}  // namespace hiltwin::io
