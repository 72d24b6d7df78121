// The wire's trust model (issue 16): the segment is owner-only, and whatever another process
// writes into it is checked before either side acts on it. Both sides run in this process; a
// second mapping of the segment plays the vandal, writing one field at a time. A corruption is
// an I/O fault naming the field, after which the side reads nothing more from the wire, while
// its own board still answers (so the run's safe outputs land).
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fakes/alloc_counter.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/io/wire_segment.h"

namespace hiltwin::io {
namespace {

using lockfree::SeqlockRead;
using lockfree::SeqlockWrite;

std::string FreshTrustName(const char* tag) {
  const std::string name = std::string("utest-trust-") + tag + "-" + std::to_string(::getpid());
  WireBus::Unlink(name);
  return name;
}

/// The message of the std::runtime_error `make` throws ("" when it throws none).
std::string RefusalOf(const std::function<void()>& make) {
  try {
    make();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(WireSegmentAccess, AFreshSegmentIsOwnerOnlyWhateverTheUmask) {
  for (const mode_t mask : {mode_t{0}, mode_t{0022}, mode_t{0277}}) {
    const std::string name = FreshTrustName("fresh");
    const mode_t old_mask = ::umask(mask);
    WireBus bus(name, Image::kIcoboard);
    ::umask(old_mask);
    struct stat info {};
    ASSERT_EQ(::stat(WireBus::SegmentPath(name).c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777U, 0600U) << "umask " << mask;
    EXPECT_EQ(info.st_uid, ::geteuid());
  }
}

TEST(WireSegmentAccess, ASegmentOthersCanWriteIsRefused) {
  const std::string name = FreshTrustName("open");
  const int fd = ::shm_open(WireBus::SegmentName(name).c_str(), O_RDWR | O_CREAT | O_EXCL, 0666);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::fchmod(fd, 0666), 0);
  ::close(fd);
  const std::string refusal = RefusalOf([&] { WireBus bus(name, Image::kIcoboardInverse); });
  WireBus::Unlink(name);
  EXPECT_NE(refusal.find(WireBus::SegmentPath(name) + " has mode 0666, not 0600"),
            std::string::npos)
      << refusal;
  EXPECT_NE(refusal.find("rm " + WireBus::SegmentPath(name)), std::string::npos) << refusal;
}

TEST(WireSegmentAccess, ASegmentOfAnotherUserIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a segment to another user";
  const std::string name = FreshTrustName("owner");
  const int fd = ::shm_open(WireBus::SegmentName(name).c_str(), O_RDWR | O_CREAT | O_EXCL, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::fchown(fd, 65534, 65534), 0);
  ::close(fd);
  const std::string refusal = RefusalOf([&] { WireBus bus(name, Image::kIcoboard); });
  WireBus::Unlink(name);
  EXPECT_NE(refusal.find("belongs to uid 65534, not to this process's uid 0"), std::string::npos)
      << refusal;
}

// Whether a side's process lives is its presence lock's to say, not its pid's (issue 34): a
// forged pid of a live process in a side's entry does not keep a new process off that side.
// A live process that holds the side does (WirePresence.ASecondLiveProcessOnTheSameSideIs...).
TEST(WireSegmentAccess, AForgedLivePidInThisSidesEntryDoesNotHoldTheSide) {
  const std::string name = FreshTrustName("forged");
  WireBus twin(name, Image::kIcoboardInverse);
  {
    WireBus ecs(name, Image::kIcoboard);
  }
  const int fd = ::shm_open(WireBus::SegmentName(name).c_str(), O_RDWR, 0);
  ASSERT_GE(fd, 0);
  void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  ASSERT_NE(map, MAP_FAILED);
  auto* segment = static_cast<WireSegment*>(map);
  segment->ecs.pid.store(1);  // init: alive, and not an ECS
  segment->ecs.attached.store(1);
  EXPECT_EQ(RefusalOf([&] {
              WireBus ecs(name, Image::kIcoboard);
              EXPECT_EQ(segment->ecs.pid.load(), ::getpid());
            }),
            "");
  ::munmap(map, sizeof(WireSegment));
}

/// Both sides attached and exchanging; `vandal` is a third mapping of the segment.
class WireVandal : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    for (char& ch : test) {
      if (ch == '/') ch = '-';  // parameterised tests: "Name/3"
    }
    name_ = FreshTrustName(test.substr(test.size() > 24 ? test.size() - 24 : 0).c_str());
    twin_bus_.emplace(name_, Image::kIcoboardInverse);
    ecs_bus_.emplace(name_, Image::kIcoboard);
    twin_.emplace(*twin_bus_);
    ecs_.emplace(*ecs_bus_);
    ASSERT_TRUE(twin_->Init(1'000'000).ok);
    ASSERT_TRUE(ecs_->Init(1'000'000).ok);
    const int fd = ::shm_open(WireBus::SegmentName(name_).c_str(), O_RDWR, 0);
    ASSERT_GE(fd, 0);
    void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    ::close(fd);
    ASSERT_NE(map, MAP_FAILED);
    vandal_ = static_cast<WireSegment*>(map);
    // A few clean exchanges: the ECS puts 1000 on PWM 0, the twin moves encoder 0 to 100.
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).ok());
      ASSERT_TRUE(twin_->Exchange({100, 0, 0, 0}, twin_in_).ok());
    }
    ASSERT_EQ(twin_in_.pwm[0], 1000);
  }
  void TearDown() override {
    if (vandal_ != nullptr) ::munmap(vandal_, sizeof(WireSegment));
  }

  /// One ECS exchange, expected to be the corruption fault naming `what`.
  void ExpectEcsFault(const std::string& what) {
    const ExchangeStatus status = ecs_->Exchange({1000, 0, 0, 0}, ecs_in_);
    EXPECT_EQ(status.code, ExchangeStatus::Code::kFault) << status.reason;
    EXPECT_TRUE(status.board_answered) << "the ECS's own board must still take safe outputs";
    ExpectNames(status.reason, what);
  }
  void ExpectTwinFault(const std::string& what) {
    const ExchangeStatus status = twin_->Exchange({100, 0, 0, 0}, twin_in_);
    EXPECT_EQ(status.code, ExchangeStatus::Code::kFault) << status.reason;
    EXPECT_TRUE(status.board_answered);
    ExpectNames(status.reason, what);
  }
  void ExpectNames(const std::string& reason, const std::string& what) const {
    EXPECT_NE(reason.find(what), std::string::npos) << reason;
    EXPECT_NE(reason.find("the segment is corrupted (another process writes into " +
                          WireBus::SegmentPath(name_) + ")"),
              std::string::npos)
        << reason;
  }
  /// Overwrites the newest published period (not yet read by the ECS) with `edit` applied.
  std::uint64_t ForgeNewestPeriod(const std::function<void(std::array<std::uint64_t, 5>&)>& edit) {
    EXPECT_TRUE(twin_->Exchange({100, 0, 0, 0}, twin_in_).ok());
    const std::uint64_t index = vandal_->encoder_newest.load();
    std::array<std::uint64_t, 5> words{};
    EXPECT_TRUE(SeqlockRead(vandal_->encoder_periods[index % kEncoderLineHistory], index, words));
    edit(words);
    SeqlockWrite(vandal_->encoder_periods[index % kEncoderLineHistory], index, words);
    return index;
  }

  std::string name_;
  std::optional<WireBus> twin_bus_;
  std::optional<WireBus> ecs_bus_;
  std::optional<IcoBoardInverse> twin_;
  std::optional<IcoBoard> ecs_;
  WireSegment* vandal_ = nullptr;
  EcsInputs ecs_in_;
  TwinInputs twin_in_;
};

TEST_F(WireVandal, APwmWordOverFullScaleStopsTheTwinWhichThenReadsNothing) {
  vandal_->pwm_words.store(0x0FFF);  // channel 0: magnitude 4095
  ExpectTwinFault("wire: PWM word 0 is 0x0fff (magnitude 4095, largest 2048, sign positive)");
  EXPECT_EQ(twin_bus_->board().pwm_output()[0], 0);
  // Latched: valid words again do not bring the wire back; the twin's PWM input stays idle.
  ASSERT_TRUE(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).ok());
  ExpectTwinFault("PWM word 0");
  EXPECT_EQ(twin_bus_->board().pwm_output()[0], 0);
}

TEST_F(WireVandal, AnImpossibleEncoderPeriodStopsTheEcs) {
  const std::uint64_t index =
      ForgeNewestPeriod([](auto& words) { words[1] &= 0xFFFF'FFFF'0000'0000ULL; });
  ExpectEcsFault("wire: encoder period " + std::to_string(index) + " has divider 0 (a board "
                 "uses 4..65535)");
}

/// One impossible encoder period: how the vandal edits its words, and what the fault names.
struct PeriodCase {
  std::function<void(std::array<std::uint64_t, 5>&)> edit;
  std::string what;
};

class WireVandalPeriod : public WireVandal, public ::testing::WithParamInterface<PeriodCase> {};

TEST_P(WireVandalPeriod, EachImpossibleFieldIsNamed) {
  ForgeNewestPeriod(GetParam().edit);
  ExpectEcsFault(GetParam().what);
}

INSTANTIATE_TEST_SUITE_P(
    Fields, WireVandalPeriod,
    ::testing::Values(
        PeriodCase{[](auto& w) { w[1] = (std::uint64_t{70000} << 32U) | 100U; },
                   "70000 sub-ticks (a board uses 1..65535)"},
        PeriodCase{[](auto& w) { w[3] = 9000; },
                   "9000 pulses on channel 0 (at most 8192 in one period)"},
        PeriodCase{[](auto& w) { w[4] = 0x05; }, "direction 5 on channel 0 (-1, 0 or 1)"},
        PeriodCase{[](auto& w) { w[2] = 0x3000; }, "start position 12288 on channel 0"},
        PeriodCase{[](auto& w) { w[0] = 0x7FFF'FFFF'FFFF'0000ULL; },
                   "start 9223372036854710272 ns (this clock reads"},
        PeriodCase{[](auto& w) { w[4] |= 0xFF'0000'0000ULL; },
                   "reserved direction bits 0xff set"}));

TEST_F(WireVandal, ARingIndexFarAheadOrBackStopsTheEcs) {
  const std::uint64_t newest = vandal_->encoder_newest.load();
  vandal_->encoder_newest.store(newest + 1'000'000'000'000ULL);
  ExpectEcsFault(" to " + std::to_string(newest + 1'000'000'000'000ULL) + " within ");
  ExpectNames(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).reason, "the ring's newest index jumped");
}

TEST_F(WireVandal, ARingIndexGoingBackStopsBothSides) {
  ASSERT_TRUE(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).ok());
  const std::uint64_t newest = vandal_->encoder_newest.load();
  vandal_->encoder_newest.store(1);
  ExpectEcsFault("the ring's newest index went back from " + std::to_string(newest) + " to 1");
  ExpectTwinFault("the ring's newest index is 1, but this twin published up to " +
                  std::to_string(newest));
}

TEST_F(WireVandal, ASeqlockTornForeverIsALossNotAFaultOrAHang) {
  std::this_thread::sleep_for(std::chrono::milliseconds(3));  // the twin's periods are over
  ASSERT_TRUE(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).ok());
  ASSERT_EQ(ecs_in_.counts[0], 100);
  ASSERT_TRUE(twin_->Exchange({200, 0, 0, 0}, twin_in_).ok());
  const std::uint64_t index = vandal_->encoder_newest.load();
  vandal_->encoder_periods[index % kEncoderLineHistory].sequence.store(2 * index + 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(3));
  for (int i = 0; i < 3; ++i) {
    const ExchangeStatus status = ecs_->Exchange({1000, 0, 0, 0}, ecs_in_);
    EXPECT_TRUE(status.ok()) << status.reason;
  }
  EXPECT_EQ(ecs_in_.counts[0], 100);  // the torn period (towards 200) was never acted on
}

TEST_F(WireVandal, AChangedHeaderStopsBothSides) {
  vandal_->magic.store(0x1234);
  ExpectEcsFault("the segment's header (state 2, magic 0x1234, version 6");
  ExpectTwinFault("the segment's header");
}

TEST_F(WireVandal, APeerPidChangedWithoutANewSessionIsAForgery) {
  vandal_->twin.pid.store(1);
  // A new twin stores its pid just before it counts its session: not at once...
  EXPECT_TRUE(ecs_->Exchange({1000, 0, 0, 0}, ecs_in_).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // ...but when no new session follows, it was forged.
  ExpectEcsFault("the twin's pid changed from " + std::to_string(::getpid()) +
                 " to 1 without a new session");
}

TEST_F(WireVandal, ThisSidesOwnEntryOverwrittenIsNoticed) {
  vandal_->ecs.pid.store(-5);
  ExpectEcsFault("this side's own entry was overwritten (pid -5, expected " +
                 std::to_string(::getpid()));
  vandal_->twin.stop_cause.store(3);  // a fake "aborted on its QoS policy" from the twin
  ExpectTwinFault("this side's own entry was overwritten (pid " + std::to_string(::getpid()) +
                  ", expected " + std::to_string(::getpid()) + "; stop cause 3, expected 0;");
}

TEST_F(WireVandal, ImpossiblePeerEntriesAndPinBitsStopTheReader) {
  vandal_->twin_pins.store(0xF0);
  ExpectEcsFault("the twin's pin bits are 0xf0");
  vandal_->ecs.last_beat_ns.store(std::numeric_limits<std::int64_t>::max());  // "alive" forever
  ExpectTwinFault("the ECS's entry holds impossible values");
}

// Fuzz findings (fuzz/corpus/wire_layout/regression_peer_*_overflow.bin): PeerStatus, which a
// side may ask without a transfer, computed 20 x step and now - heartbeat on garbage and
// overflowed (undefined behaviour; the sanitizer build stops on it). Garbage is a lost peer.
TEST_F(WireVandal, AnAbsurdPeerStepOrHeartbeatIsALostPeerWithoutOverflow) {
  vandal_->twin.step_ns.store(std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(ecs_bus_->PeerStatus().result, BusResult::kOk);  // a fresh beat: alive
  vandal_->twin.last_beat_ns.store(std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(ecs_bus_->PeerStatus().result, BusResult::kPeerLost);
  vandal_->twin.step_ns.store(std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(ecs_bus_->PeerStatus().result, BusResult::kPeerLost);
}

TEST_F(WireVandal, ExchangesAllocateNothingCleanOrCorrupted) {
  // The checks and the latched message (formatted into the bus's own buffer) run on the loop's
  // path: clean exchanges, the one that finds the garbage and the ones after it.
  std::uint64_t allocations = 0;
  bool faulted = false;
  {
    test::ScopedAllocationCount count;
    for (int i = 0; i < 100; ++i) {
      (void)ecs_->Exchange({1000, 0, 0, 0}, ecs_in_);
      (void)twin_->Exchange({100, 0, 0, 0}, twin_in_);
    }
    for (int i = 0; i < 10; ++i) {  // each side overwrites its own field: garbage every time
      vandal_->twin_pins.store(0xF0);
      const bool ecs_faulted = !ecs_->Exchange({0, 0, 0, 0}, ecs_in_).ok();
      vandal_->pwm_words.store(0x0FFF);
      faulted = ecs_faulted && !twin_->Exchange({0, 0, 0, 0}, twin_in_).ok();
    }
    allocations = count.count();
  }
  EXPECT_TRUE(faulted);
  EXPECT_EQ(allocations, 0U);
}

TEST_F(WireVandal, RandomBytesOverEverythingStopBothSidesWithoutACrash) {
  std::mt19937_64 random(16);
  auto* bytes = reinterpret_cast<unsigned char*>(vandal_);
  for (std::size_t i = 0; i < sizeof(WireSegment); ++i) {
    bytes[i] = static_cast<unsigned char>(random() & 0xFFU);
  }
  ExpectEcsFault("wire: ");
  ExpectTwinFault("wire: ");
}

}  // namespace
}  // namespace hiltwin::io
