#include "hiltwin/lockfree/spsc_ring.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>
#include <vector>

#include "fakes/alloc_counter.h"

namespace hiltwin::lockfree {
namespace {

#if defined(HILTWIN_UNDER_SANITIZER)
constexpr std::uint64_t kStressItems = 100'000;
#else
constexpr std::uint64_t kStressItems = 1'000'000;
#endif

TEST(SpscRing, RejectsCapacityThatIsNotAPowerOfTwo) {
  EXPECT_THROW(SpscRing(0), std::invalid_argument);
  EXPECT_THROW(SpscRing(3), std::invalid_argument);
  EXPECT_THROW(SpscRing(1000), std::invalid_argument);
  EXPECT_EQ(SpscRing(1).capacity(), 1U);
  EXPECT_EQ(SpscRing(1024).capacity(), 1024U);
}

TEST(SpscRing, ClaimsSlotsInOrderAndRefusesWhenFull) {
  SpscRing ring(4);
  std::size_t slot = 99;
  for (std::size_t i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.TryClaim(slot));
    EXPECT_EQ(slot, i);
    ring.Publish();
  }
  EXPECT_FALSE(ring.TryClaim(slot));
  EXPECT_EQ(ring.Available(), 4U);
  EXPECT_EQ(ring.ReadSlot(0), 0U);
  EXPECT_EQ(ring.ReadSlot(3), 3U);
  ring.Release(2);
  EXPECT_EQ(ring.Available(), 2U);
  EXPECT_EQ(ring.ReadSlot(0), 2U);
  // Space freed by the consumer becomes claimable, wrapping to slot 0.
  ASSERT_TRUE(ring.TryClaim(slot));
  EXPECT_EQ(slot, 0U);
  ring.Publish();
  ASSERT_TRUE(ring.TryClaim(slot));
  EXPECT_EQ(slot, 1U);
  ring.Publish();
  EXPECT_FALSE(ring.TryClaim(slot));
  EXPECT_EQ(ring.SizeApprox(), 4U);
}

TEST(SpscQueue, FifoOrderAcrossManyWraps) {
  SpscQueue<std::uint32_t> queue(8);
  std::uint32_t next_in = 0;
  std::uint32_t next_out = 0;
  for (int round = 0; round < 100; ++round) {
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(queue.TryPush(next_in++));
    std::uint32_t value = 0;
    for (int i = 0; i < 5; ++i) {
      ASSERT_TRUE(queue.TryPop(value));
      ASSERT_EQ(value, next_out++);
    }
    EXPECT_FALSE(queue.TryPop(value));
  }
  EXPECT_EQ(queue.drops(), 0U);
}

TEST(SpscQueue, CountsEveryRefusedPush) {
  SpscQueue<int> queue(2);
  EXPECT_TRUE(queue.TryPush(1));
  EXPECT_TRUE(queue.TryPush(2));
  EXPECT_FALSE(queue.TryPush(3));
  EXPECT_FALSE(queue.TryPush(4));
  EXPECT_EQ(queue.drops(), 2U);
  int value = 0;
  ASSERT_TRUE(queue.TryPop(value));
  EXPECT_EQ(value, 1);
  EXPECT_TRUE(queue.TryPush(5));
  EXPECT_EQ(queue.drops(), 2U);
}

TEST(SpscQueue, PushAndPopAllocateNothing) {
  SpscQueue<double> queue(64);
  double value = 0.0;
  test::ScopedAllocationCount allocations;
  for (int i = 0; i < 1000; ++i) {
    (void)queue.TryPush(i);
    (void)queue.TryPop(value);
  }
  EXPECT_EQ(allocations.count(), 0U);
}

// Two threads, a small ring (many wraps): every value arrives exactly once and in order.
TEST(SpscQueue, ConcurrentProducerConsumerLosesAndReordersNothing) {
  SpscQueue<std::uint64_t> queue(64);
  std::uint64_t refused = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kStressItems;) {
      if (queue.TryPush(i)) {
        ++i;
      } else {
        ++refused;
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  std::uint64_t out_of_order = 0;
  while (expected < kStressItems) {
    std::uint64_t value = 0;
    if (queue.TryPop(value)) {
      if (value != expected) ++out_of_order;
      expected = value + 1;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0U);
  EXPECT_EQ(expected, kStressItems);
  EXPECT_EQ(queue.drops(), refused);
  std::uint64_t extra = 0;
  EXPECT_FALSE(queue.TryPop(extra));
}

}  // namespace
}  // namespace hiltwin::lockfree
