// The wire's seqlock raced for real (issue 16): a writer thread and a reader thread on one slot,
// then the twin and ECS sides of a WireBus on two threads. Run in the ThreadSanitizer build
// too: an accepted read must be one write's words, and the writer's earlier plain writes must
// happen before it (TSan reports a race on the side table below otherwise).
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/lockfree/seqlock.h"

namespace hiltwin::io {
namespace {

using lockfree::SeqlockRead;
using lockfree::SeqlockSlot;
using lockfree::SeqlockWrite;

using Words = std::array<std::uint64_t, 5>;

/// Every word derived from the tag, differently: a read mixing two writes cannot pass.
Words WordsOf(std::uint64_t tag) {
  return {tag, ~tag, tag * 0x9E37'79B9'7F4A'7C15ULL, tag ^ 0x5555'5555'5555'5555ULL, tag + 7};
}

/// Keeps a producer and a consumer thread overlapping on a busy machine: every kPace items the
/// producer waits until the consumer has looked twice more, so a consumer that was not
/// scheduled yet cannot find the producer done before it ever ran (the second look began while
/// the producer waited: it reads a quiet slot). In between the two race freely. Relaxed: this
/// adds no synchronisation TSan would count, the seqlock's own stays the only one.
class Overlap {
 public:
  static constexpr std::uint64_t kPace = 1000;
  void ConsumerLooked() noexcept { looks_.fetch_add(1, std::memory_order_relaxed); }
  void ProducerPaces(std::uint64_t item) noexcept {
    if (item % kPace != 1) return;
    const std::uint64_t seen = looks_.load(std::memory_order_relaxed);
    while (looks_.load(std::memory_order_relaxed) < seen + 2) std::this_thread::yield();
  }

 private:
  std::atomic<std::uint64_t> looks_{0};
};

#ifdef HILTWIN_UNDER_SANITIZER
constexpr std::uint64_t kTags = 100'000;  // TSan runs ~10x slower
#else
constexpr std::uint64_t kTags = 1'000'000;
#endif

TEST(Seqlock, ConcurrentReadsAreOneWritesWordsOrRefused) {
  // Two slots: the reader reads tag t while the writer writes t + 1 next to it and then
  // overwrites t's slot with t + 2, as often as it can.
  std::array<SeqlockSlot<5>, 2> slots{};
  std::atomic<std::uint64_t> newest{0};
  std::atomic<bool> done{false};
  // Written plainly before each tag is published: an accepted read of tag t must see side[t]
  // (the read synchronises with the write), which TSan checks.
  std::vector<std::uint64_t> side(kTags + 1, 0);
  Overlap overlap;
  std::thread writer([&] {
    for (std::uint64_t tag = 1; tag <= kTags; ++tag) {
      overlap.ProducerPaces(tag);
      side[tag] = tag * 3;
      SeqlockWrite(slots[tag % 2], tag, WordsOf(tag));
      newest.store(tag, std::memory_order_relaxed);
    }
    done.store(true, std::memory_order_release);
  });
  std::uint64_t accepted = 0;
  std::uint64_t refused = 0;
  std::uint64_t inconsistent = 0;
  std::uint64_t side_wrong = 0;
  Words out{};
  while (!done.load(std::memory_order_acquire)) {
    // Relaxed: the only synchronisation with the writer is the seqlock's own.
    const std::uint64_t newest_tag = newest.load(std::memory_order_relaxed);
    // The newest tag (usually intact) and the one before it, whose slot the writer is about to
    // overwrite with the next tag (often torn under the reader).
    for (std::uint64_t back = 0; back < 2 && back < newest_tag; ++back) {
      const std::uint64_t tag = newest_tag - back;
      if (!SeqlockRead(slots[tag % 2], tag, out)) {
        ++refused;
        continue;
      }
      ++accepted;
      if (out != WordsOf(tag)) ++inconsistent;
      if (side[tag] != tag * 3) ++side_wrong;
    }
    overlap.ConsumerLooked();
  }
  writer.join();
  std::printf("seqlock race: %llu reads accepted, %llu refused (overwritten before or while read)\n",
              static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(refused));
  EXPECT_EQ(inconsistent, 0U);
  EXPECT_EQ(side_wrong, 0U);
  EXPECT_GT(accepted, 0U);
  ASSERT_TRUE(SeqlockRead(slots[kTags % 2], kTags, out));  // the last write, once the writer is done
  EXPECT_EQ(out, WordsOf(kTags));
}

TEST(Seqlock, ATornOrOtherVersionIsRefusedAtOnce) {
  SeqlockSlot<5> slot{};
  Words out{};
  EXPECT_FALSE(SeqlockRead(slot, 1, out));  // zero-filled: nothing published
  SeqlockWrite(slot, 3, WordsOf(3));
  EXPECT_TRUE(SeqlockRead(slot, 3, out));
  EXPECT_FALSE(SeqlockRead(slot, 2, out));  // an older version is gone
  EXPECT_FALSE(SeqlockRead(slot, 4, out));  // a newer one is not there yet
  slot.sequence.store(2 * 5 + 1);           // a writer that never finished (or a vandal)
  EXPECT_FALSE(SeqlockRead(slot, 5, out));  // refused, without waiting
  EXPECT_FALSE(SeqlockRead(slot, 3, out));
}

/// The twin's target for channel c at its exchange n: moving every channel at its own rate.
std::int32_t Target(std::uint64_t n, std::size_t c) {
  return WrapToRelative(static_cast<std::int64_t>(n * (c + 1)));
}

#ifdef HILTWIN_UNDER_SANITIZER
constexpr std::uint64_t kTwinExchanges = 5'000;
#else
constexpr std::uint64_t kTwinExchanges = 50'000;
#endif

TEST(WireRace, TheTwinPublishesWhileTheEcsReadsOnAnotherThread) {
  const std::string name = "utest-race-" + std::to_string(::getpid());
  WireBus::Unlink(name);
  WireBus twin_bus(name, Image::kIcoboardInverse);
  WireBus ecs_bus(name, Image::kIcoboard);
  IcoBoardInverse twin(twin_bus);
  IcoBoard ecs(ecs_bus);
  constexpr std::int64_t kTwinStepNs = 100'000;  // 2500 sub-ticks: every change here fits
  ASSERT_TRUE(twin.Init(kTwinStepNs).ok);
  ASSERT_TRUE(ecs.Init(1'000'000).ok);

  std::atomic<bool> done{false};
  std::uint64_t twin_faults = 0;
  Overlap overlap;
  std::thread twin_thread([&] {
    TwinInputs in;
    for (std::uint64_t n = 1; n <= kTwinExchanges; ++n) {
      overlap.ProducerPaces(n);
      std::array<std::int32_t, kChannels> out{};
      for (std::size_t c = 0; c < kChannels; ++c) out[c] = Target(n, c);
      if (!twin.Exchange(out, in).ok()) ++twin_faults;
    }
    done.store(true, std::memory_order_release);
  });
  std::uint64_t ecs_faults = 0;
  std::uint64_t periods_read = 0;
  std::uint64_t out_of_order = 0;
  EcsInputs in;
  EncoderPeriod period;
  EncoderPeriod previous;
  while (!done.load(std::memory_order_acquire)) {
    const ExchangeStatus status = ecs.Exchange({0, 0, 0, 0}, in);
    if (!status.ok()) {
      ++ecs_faults;
      std::printf("ECS: %s\n", status.reason);
    }
    const std::uint64_t index = ecs_bus.board().encoder_lines().period().index;
    // The period the readers are in and its predecessor, when still in the ring.
    if (index > 1 && ecs_bus.ReadEncoderPeriod(index, period) &&
        ecs_bus.ReadEncoderPeriod(index - 1, previous)) {
      ++periods_read;
      if (period.index != index || previous.start_ns() > period.start_ns()) ++out_of_order;
    }
    overlap.ConsumerLooked();
  }
  twin_thread.join();
  // The twin is done: once its last period has run out, the ECS counts where it left them.
  std::this_thread::sleep_for(std::chrono::nanoseconds(2 * kTwinStepNs));
  ASSERT_TRUE(ecs.Exchange({0, 0, 0, 0}, in).ok());
  std::printf("wire race: %llu twin exchanges, %llu period pairs read by the ECS, resyncs %llu\n",
              static_cast<unsigned long long>(kTwinExchanges),
              static_cast<unsigned long long>(periods_read),
              static_cast<unsigned long long>(ecs_bus.board().encoder_lines().counters().resyncs));
  EXPECT_EQ(twin_faults, 0U);
  EXPECT_EQ(ecs_faults, 0U);
  EXPECT_EQ(out_of_order, 0U);
  EXPECT_GT(periods_read, 0U);
  for (std::size_t c = 0; c < kChannels; ++c) {
    EXPECT_EQ(in.counts[c], Target(kTwinExchanges, c)) << "channel " << c;
  }
}

}  // namespace
}  // namespace hiltwin::io
