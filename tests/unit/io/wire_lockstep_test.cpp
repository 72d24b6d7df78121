// The wire's lockstep clock (wire_bus.h "Time", docs/lockstep.md), both sides in one process
// (they are different sides, so both may attach), each on its own thread as in two processes:
// the turns follow the virtual times alone (at equal times the ECS first), busy time lets the
// peer run what falls inside it, a stopped peer releases the waiter, a peer that is killed or
// stopped breaks the lockstep within the heartbeat timeout, and a peer on the other clock is
// refused.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <sys/mman.h>
#include <fcntl.h>
#include <thread>
#include <utility>
#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "wire_poll.h"
#include "hiltwin/io/wire_segment.h"
#include "hiltwin/kernel_glue/shared_memory.h"

namespace hiltwin::io {
namespace {

using kernel_glue::TimeNs;
using Wall = std::chrono::steady_clock;

std::string FreshName(const char* tag) {
  const std::string name = std::string("utest-ls-") + tag + "-" + std::to_string(::getpid());
  WireBus::Unlink(name);
  return name;
}

/// Both sides up: each has beaten once (as the session's wait for the peer does).
void BringUp(WireBus& a, WireBus& b) {
  static_cast<void>(a.Poll());
  ASSERT_EQ(b.Poll().result, BusResult::kOk);
  ASSERT_EQ(a.Poll().result, BusResult::kOk);
}

/// One event a side ran: its virtual time and whether the ECS ran it.
struct Event {
  TimeNs t_ns;
  bool ecs;
  bool operator==(const Event&) const = default;
};

/// Runs `times` on `bus`'s lockstep clock, recording each turn, then leaves.
void RunSide(WireBus& bus, const std::vector<TimeNs>& times, bool ecs, std::mutex& mutex,
             std::vector<Event>& log, std::atomic<int>& inside, std::atomic<int>& overlaps) {
  kernel_glue::Clock& clock = *bus.lockstep_clock();
  for (const TimeNs t : times) {
    clock.SleepUntilNs(t);
    if (inside.fetch_add(1) != 0) overlaps.fetch_add(1);  // the other side holds a turn too
    {
      const std::lock_guard lock(mutex);
      log.push_back({clock.NowNs(), ecs});
    }
    inside.fetch_sub(1);
  }
  bus.AnnounceStop(StopCause::kFinished);
}

std::vector<TimeNs> Releases(TimeNs period_ns, int count) {
  std::vector<TimeNs> times;
  for (int k = 1; k <= count; ++k) times.push_back(k * period_ns);
  return times;
}

TEST(WireLockstep, TurnsFollowTheVirtualTimesWithTheEcsFirstAtEqualTimes) {
  const std::string name = FreshName("order");
  WireBus twin(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireBus ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
  BringUp(twin, ecs);
  ASSERT_NE(twin.lockstep_clock(), nullptr);
  EXPECT_TRUE(twin.lockstep_clock()->IsVirtual());
  std::mutex mutex;
  std::vector<Event> log;
  std::atomic<int> inside{0};
  std::atomic<int> overlaps{0};
  // The defaults' shape: the twin at 4 kHz, the ECS at 1 kHz, releases from one period on.
  const std::vector<TimeNs> twin_times = Releases(250'000, 4000);
  const std::vector<TimeNs> ecs_times = Releases(1'000'000, 1000);
  std::thread twin_thread(
      [&] { RunSide(twin, twin_times, false, mutex, log, inside, overlaps); });
  std::thread ecs_thread([&] { RunSide(ecs, ecs_times, true, mutex, log, inside, overlaps); });
  twin_thread.join();
  ecs_thread.join();

  std::vector<Event> expected;  // every event once, by time, the ECS first at equal times
  for (TimeNs t = 250'000; t <= 1'000'000'000; t += 250'000) {
    if (t % 1'000'000 == 0) expected.push_back({t, true});
    expected.push_back({t, false});
  }
  ASSERT_EQ(log.size(), expected.size());
  EXPECT_TRUE(log == expected) << "the turns did not follow the virtual times";
  EXPECT_EQ(overlaps.load(), 0) << "both sides held a turn at once";
  // The twin waits for the ECS once per ECS period (its release at the ECS's time), the ECS
  // for the twin's three releases before its own.
  EXPECT_EQ(twin.lockstep_counts().waits, 4000U);
  EXPECT_EQ(ecs.lockstep_counts().waits, 1000U);
  EXPECT_GE(twin.lockstep_counts().handovers + ecs.lockstep_counts().handovers, 1000U);
}

// The lockstep wait is the loop's sleep: it runs on the real-time path, so it allocates nothing,
// whether a hand-over is spun or slept on the futex (one side sleeps 30 ms per turn for a few
// turns, so the other goes to the futex).
TEST(WireLockstep, WaitsAndHandOversAllocateNothing) {
  const std::string name = FreshName("alloc");
  WireBus twin(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireBus ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
  BringUp(twin, ecs);
  std::uint64_t twin_allocations = ~std::uint64_t{0};
  std::uint64_t ecs_allocations = ~std::uint64_t{0};
  std::thread twin_thread([&] {
    const test::ScopedAllocationCount count;
    kernel_glue::Clock& clock = *twin.lockstep_clock();
    for (TimeNs t = 250'000; t <= 100'000'000; t += 250'000) clock.SleepUntilNs(t);
    twin_allocations = count.count();
    twin.AnnounceStop(StopCause::kFinished);
  });
  std::thread ecs_thread([&] {
    const test::ScopedAllocationCount count;
    kernel_glue::Clock& clock = *ecs.lockstep_clock();
    for (TimeNs t = 1'000'000; t <= 100'000'000; t += 1'000'000) {
      clock.SleepUntilNs(t);
      if (t <= 3'000'000) std::this_thread::sleep_for(std::chrono::milliseconds(30));
    }
    ecs_allocations = count.count();
    ecs.AnnounceStop(StopCause::kFinished);
  });
  twin_thread.join();
  ecs_thread.join();
  EXPECT_EQ(twin_allocations, 0U) << "malloc counted: " << test::MallocIsCounted();
  EXPECT_EQ(ecs_allocations, 0U);
  EXPECT_GT(twin.lockstep_counts().sleeps, 0U) << "the futex path was not taken";
}

TEST(WireLockstep, BusyTimeLetsThePeerRunWhatFallsInsideItFirst) {
  const std::string name = FreshName("spend");
  WireBus twin(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireBus ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
  BringUp(twin, ecs);
  std::mutex mutex;
  std::vector<Event> log;
  const auto note = [&](TimeNs t, bool is_ecs) {
    const std::lock_guard lock(mutex);
    log.push_back({t, is_ecs});
  };
  std::thread twin_thread([&] {
    kernel_glue::Clock& clock = *twin.lockstep_clock();
    clock.SleepUntilNs(100);
    note(clock.NowNs(), false);
    clock.SpendNs(1'000);  // an overrun of 1 µs: the ECS's event at 600 ns comes first
    note(clock.NowNs(), false);
    twin.AnnounceStop(StopCause::kFinished);
  });
  std::thread ecs_thread([&] {
    kernel_glue::Clock& clock = *ecs.lockstep_clock();
    clock.SleepUntilNs(600);
    note(clock.NowNs(), true);
    ecs.AnnounceStop(StopCause::kFinished);
  });
  twin_thread.join();
  ecs_thread.join();
  const std::vector<Event> expected = {{100, false}, {600, true}, {1'100, false}};
  EXPECT_TRUE(log == expected);
}

TEST(WireLockstep, AStoppedPeerReleasesTheWaiterWhoseExchangeThenSaysWhy) {
  const std::string name = FreshName("stop");
  WireBus twin_bus(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireBus ecs_bus(name, Image::kIcoboard, {}, WireClock::kLockstep);
  IcoBoardInverse twin(twin_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);
  BringUp(twin_bus, ecs_bus);
  ecs_bus.AnnounceStop(StopCause::kFinished);  // the ECS ran its plan and ended at time 0
  const Wall::time_point start = Wall::now();
  twin_bus.lockstep_clock()->SleepUntilNs(5 * kernel_glue::kNsPerS);
  EXPECT_LT(Wall::now() - start, std::chrono::milliseconds(100)) << "waited for a stopped peer";
  EXPECT_EQ(twin_bus.lockstep_clock()->NowNs(), 5 * kernel_glue::kNsPerS);
  TwinInputs in{};
  const ExchangeStatus status = twin.Exchange({0, 0, 0, 0}, in);
  EXPECT_TRUE(status.ok()) << status.reason;
  ASSERT_NE(status.peer_stopped, nullptr);
  EXPECT_STREQ(status.peer_stopped, "wire: the ECS finished its run");
}

/// A child process that attaches as the ECS in lockstep, comes up, takes its turn at 1 ms and
/// then holds it, only polling (alive, beating, but never releasing the time) until signalled.
pid_t StartPollingEcs(const std::string& name) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    WireBus ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
    if (!PollUntilUp(ecs)) ::_exit(1);
    ecs.lockstep_clock()->SleepUntilNs(1'000'000);
    for (;;) {
      static_cast<void>(ecs.Poll());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  return pid;
}

/// StartPollingEcs, up beside `twin_bus`, whose board `twin` is initialised; -1 on failure.
pid_t StartHoldingEcsBeside(const std::string& name, WireBus& twin_bus, IcoBoardInverse& twin) {
  const pid_t child = StartPollingEcs(name);
  if (child <= 0) return -1;
  if (!PollUntilUp(twin_bus) || !twin.Init(250'000).ok) {
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    return -1;
  }
  return child;
}

/// The twin runs its release at 250 µs, then waits at 1 ms for the turn the child ECS holds;
/// `signal` reaches the child 200 ms into the wait. Returns how long the wait outlasted it.
Wall::duration WaitWhileTheEcsGets(int signal, WireBus& twin, pid_t child) {
  twin.lockstep_clock()->SleepUntilNs(250'000);  // the ECS waits at 1 ms: the twin's turn
  Wall::time_point signalled;
  std::thread signaller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    signalled = Wall::now();
    ::kill(child, signal);  // not reaped: the caller does, after the wait
  });
  twin.lockstep_clock()->SleepUntilNs(1'000'000);  // the ECS's turn first, which it keeps
  const Wall::time_point released = Wall::now();
  signaller.join();
  return released - signalled;
}

// Issue 34, "zombie": the killed ECS is not reaped until the wait is over (a parent that waits
// for it later), and a zombie still answers kill(pid, 0); the kernel drops its presence at its
// death all the same, so the wait ends within a slice or two, not at the heartbeat timeout.
TEST(WireLockstep, AKilledPeerBreaksTheLockstepAtOnceEvenBeforeItIsReaped) {
  const std::string name = FreshName("kill");
  WireBus twin_bus(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  IcoBoardInverse twin(twin_bus);
  const pid_t child = StartHoldingEcsBeside(name, twin_bus, twin);
  ASSERT_GT(child, 0) << "the forked ECS did not come up, or the twin's INIT failed";
  const Wall::duration late = WaitWhileTheEcsGets(SIGKILL, twin_bus, child);
  siginfo_t info{};
  const bool zombie = ::waitid(P_PID, static_cast<id_t>(child), &info,
                               WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == child;
  ::waitpid(child, nullptr, 0);
  EXPECT_TRUE(zombie) << "the ECS was reaped during the wait: the case is not shown";
  EXPECT_GE(late, Wall::duration::zero()) << "the wait ended before the kill";
  // Well under the heartbeat timeout (500 ms), which a stale heartbeat would have needed.
  EXPECT_LT(late, std::chrono::nanoseconds(kWireLockstepHeartbeatTimeoutNs / 2));
  TwinInputs in{};
  const ExchangeStatus status = twin.Exchange({0, 0, 0, 0}, in);
  EXPECT_EQ(status.code, ExchangeStatus::Code::kFault);
  EXPECT_TRUE(status.board_answered) << "this side's own board must still take safe outputs";
  EXPECT_NE(std::string(status.reason).find("the ECS process is gone (killed or crashed)"),
            std::string::npos)
      << status.reason;
}

// A side counts as up from its INIT's beat; its session's set-up follows before its loop waits
// for the first time, and under load (a sanitizer, a busy machine) that may outlast the
// heartbeat timeout. Still in its set-up (lockstep time 0) and alive, it is not hung.
TEST(WireLockstep, APeerWhoseSetUpOutlastsTheHeartbeatTimeoutIsWaitedFor) {
  const std::string name = FreshName("setup");
  WireBus twin_bus(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  const pid_t child = ::fork();
  if (child == 0) {
    WireBus ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
    if (!PollUntilUp(ecs)) ::_exit(1);
    std::this_thread::sleep_for(std::chrono::nanoseconds(2 * kWireLockstepHeartbeatTimeoutNs));
    ecs.lockstep_clock()->SleepUntilNs(1'000'000);  // its loop's first wait, after a slow set-up
    ecs.AnnounceStop(StopCause::kFinished);
    ::_exit(0);
  }
  ASSERT_GT(child, 0);
  ASSERT_TRUE(PollUntilUp(twin_bus));
  IcoBoardInverse twin(twin_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);
  twin_bus.lockstep_clock()->SleepUntilNs(250'000);  // held by the ECS's set-up, then its turn
  TwinInputs in{};
  const ExchangeStatus status = twin.Exchange({0, 0, 0, 0}, in);
  EXPECT_TRUE(status.ok()) << status.reason;
  ::waitpid(child, nullptr, 0);
}

TEST(WireLockstep, AStoppedPeerThatStopsTakingTurnsBreaksTheLockstepWithinASecond) {
  const std::string name = FreshName("sigstop");
  WireBus twin_bus(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  IcoBoardInverse twin(twin_bus);
  const pid_t child = StartHoldingEcsBeside(name, twin_bus, twin);
  ASSERT_GT(child, 0) << "the forked ECS did not come up, or the twin's INIT failed";
  const Wall::duration late = WaitWhileTheEcsGets(SIGSTOP, twin_bus, child);
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  // Its heartbeat has to age past the timeout first: at least that, and within a second.
  EXPECT_GE(late, std::chrono::nanoseconds(kWireLockstepHeartbeatTimeoutNs) -
                      std::chrono::milliseconds(20));
  EXPECT_LT(late, std::chrono::seconds(1));
  TwinInputs in{};
  const ExchangeStatus status = twin.Exchange({0, 0, 0, 0}, in);
  EXPECT_EQ(status.code, ExchangeStatus::Code::kFault);
  EXPECT_NE(std::string(status.reason).find("the ECS stopped taking its turns"),
            std::string::npos)
      << status.reason;
}

TEST(WireLockstep, APeerOnTheOtherClockIsRefusedAtAttachNamingTheFlag) {
  const std::string name = FreshName("mix");
  {
    WireBus realtime_twin(name, Image::kIcoboardInverse);
    try {
      WireBus lockstep_ecs(name, Image::kIcoboard, {}, WireClock::kLockstep);
      ADD_FAILURE() << "a lockstep ECS attached beside a real-time twin";
    } catch (const std::invalid_argument& e) {
      EXPECT_STREQ(e.what(), "the twin on this wire runs --clock realtime and this ECS --clock "
                             "virtual (lockstep); start both sides with the same --clock");
    }
    EXPECT_EQ(realtime_twin.Poll().result, BusResult::kPeerAbsent);  // it never attached
  }
  WireBus lockstep_twin(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  EXPECT_THROW(WireBus(name, Image::kIcoboard), std::invalid_argument);
}

/// The segment as a third party maps it.
WireSegment* MapForVandal(const std::string& name) {
  const int fd = ::shm_open(("/hiltwin-wire-" + name).c_str(), O_RDWR, 0);
  if (fd < 0) return nullptr;
  void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  return map == MAP_FAILED ? nullptr : static_cast<WireSegment*>(map);
}

TEST(WireLockstep, APeerOnTheOtherClockThatAttachedAtTheSameMomentIsRefusedWhileWaiting) {
  const std::string name = FreshName("race");
  WireBus twin(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireSegment* seg = MapForVandal(name);
  ASSERT_NE(seg, nullptr);
  // What a real-time ECS that passed its own check a moment before the twin attached leaves:
  // its presence lock, held on its own open file, and its entry.
  const int ecs_fd = ::shm_open(("/hiltwin-wire-" + name).c_str(), O_RDWR, 0);
  ASSERT_GE(ecs_fd, 0);
  ASSERT_EQ(kernel_glue::TakePresence(ecs_fd, wire::kEcsPresenceByte), 0);
  seg->ecs.pid.store(static_cast<std::int32_t>(::getpid()));
  seg->ecs.clock.store(wire::kClockRealtime);
  seg->ecs.attached.store(1);
  seg->ecs.sessions.fetch_add(1);
  const BusStatus status = twin.Poll();
  EXPECT_EQ(status.result, BusResult::kPeerMismatch);
  EXPECT_STREQ(status.reason, "wire: the ECS on this wire runs --clock realtime and this twin "
                              "--clock virtual (lockstep); start both sides with the same --clock");
  seg->ecs.attached.store(0);
  ::close(ecs_fd);
  ::munmap(seg, sizeof(WireSegment));
}

TEST(WireLockstep, AnImpossibleLockstepTimeIsACorruptedWireNotAWaitForever) {
  const std::string name = FreshName("vandal");
  WireBus twin_bus(name, Image::kIcoboardInverse, {}, WireClock::kLockstep);
  WireBus ecs_bus(name, Image::kIcoboard, {}, WireClock::kLockstep);
  IcoBoardInverse twin(twin_bus);
  IcoBoard ecs(ecs_bus);
  ASSERT_TRUE(twin.Init(250'000).ok);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);
  BringUp(twin_bus, ecs_bus);
  WireSegment* seg = MapForVandal(name);
  ASSERT_NE(seg, nullptr);
  seg->ecs.lockstep_ns.store(-7);
  twin_bus.lockstep_clock()->SleepUntilNs(250'000);  // returns: nothing more is read
  TwinInputs in{};
  ExchangeStatus status = twin.Exchange({0, 0, 0, 0}, in);
  EXPECT_EQ(status.code, ExchangeStatus::Code::kFault);
  EXPECT_NE(std::string(status.reason).find("the ECS's lockstep time is -7 ns"), std::string::npos)
      << status.reason;
  // The ECS sees its own lockstep time overwritten (a side told "wait" or "run" forever).
  EcsInputs ecs_in{};
  status = ecs.Exchange({0, 0, 0, 0}, ecs_in);
  EXPECT_EQ(status.code, ExchangeStatus::Code::kFault);
  EXPECT_NE(std::string(status.reason).find("this side's own entry was overwritten"),
            std::string::npos)
      << status.reason;
  EXPECT_NE(std::string(status.reason).find("lockstep time -7, expected 0)"),
            std::string::npos)
      << status.reason;
  ::munmap(seg, sizeof(WireSegment));
}

}  // namespace
}  // namespace hiltwin::io
