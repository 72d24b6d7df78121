#pragma once
/// Lock-free single-producer/single-consumer ring after L. Lamport ("Specifying concurrent
/// program modules", 1983): each index is written by one side only, published with release and
/// read with acquire. The index logic (SpscRing, independent of element type and capacity, as
/// ETL's queue_spsc_atomic base) and a typed queue on top of it.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "hiltwin/lockfree/cache_line.h"

namespace hiltwin::lockfree {

/// Bytes that keep the producer's and the consumer's indices off each other's cache line.

/// Claim/publish/release index logic over `capacity` slots stored by the owner. Indices are
/// free-running 64-bit counters (they never wrap in practice), the slot is `index & mask`.
/// Exactly one producer thread and one consumer thread; every call is wait-free.
class SpscRing {
 public:
  /// Throws std::invalid_argument unless capacity is a power of two (start-up only).
  explicit SpscRing(std::size_t capacity) : capacity_(capacity), mask_(capacity - 1) {
    if (capacity == 0 || (capacity & (capacity - 1)) != 0) {
      throw std::invalid_argument("SpscRing: capacity " + std::to_string(capacity) +
                                  " is not a power of two; choose e.g. 1024 or 65536");
    }
  }

  /// Number of slots.
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

  /// Producer: the slot to fill next, or false when the ring is full (nothing changes).
  [[nodiscard]] bool TryClaim(std::size_t& slot) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - producer_cached_tail_ >= capacity_) {
      // Only re-read the consumer's index when the cached one says full: keeps the
      // consumer's cache line out of the producer's fast path.
      producer_cached_tail_ = tail_.load(std::memory_order_acquire);
      if (head - producer_cached_tail_ >= capacity_) return false;
    }
    slot = static_cast<std::size_t>(head & mask_);
    return true;
  }

  /// Producer: make the slot returned by the last successful TryClaim visible.
  void Publish() noexcept {
    head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  /// Consumer: number of published slots not yet released.
  [[nodiscard]] std::size_t Available() noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_relaxed));
  }

  /// Consumer: slot of the `offset`-th readable element (offset < Available()).
  [[nodiscard]] std::size_t ReadSlot(std::size_t offset) const noexcept {
    return static_cast<std::size_t>((tail_.load(std::memory_order_relaxed) + offset) & mask_);
  }

  /// Consumer: hand `count` read slots back to the producer.
  void Release(std::size_t count) noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + count, std::memory_order_release);
  }

  /// Any thread: occupancy at some recent instant (for statistics only).
  [[nodiscard]] std::size_t SizeApprox() const noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    return head >= tail ? static_cast<std::size_t>(head - tail) : 0;
  }

 private:
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> head_{0};  ///< next index to write
  std::uint64_t producer_cached_tail_ = 0;                       ///< producer's view of tail_
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> tail_{0};  ///< next index to read
  alignas(kCacheLineBytes) std::size_t capacity_;
  std::size_t mask_;
};

/// Fixed-capacity SPSC queue of trivially copyable values; storage allocated once at
/// construction. TryPush never blocks and counts what it could not take.
template <typename T>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>, "SpscQueue copies elements by value");

 public:
  /// Throws std::invalid_argument unless capacity is a power of two (start-up only).
  explicit SpscQueue(std::size_t capacity)
      : ring_(capacity), storage_(std::make_unique<T[]>(capacity)) {}

  /// Producer: false (and one more drop counted) when full.
  [[nodiscard]] bool TryPush(const T& value) noexcept {
    std::size_t slot = 0;
    if (!ring_.TryClaim(slot)) {
      drops_.store(drops_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return false;
    }
    storage_[slot] = value;
    ring_.Publish();
    return true;
  }

  /// Consumer: false when empty.
  [[nodiscard]] bool TryPop(T& out) noexcept {
    if (ring_.Available() == 0) return false;
    out = storage_[ring_.ReadSlot(0)];
    ring_.Release(1);
    return true;
  }

  /// Pushes refused because the queue was full (any thread may read).
  [[nodiscard]] std::uint64_t drops() const noexcept {
    return drops_.load(std::memory_order_relaxed);
  }
  /// Number of slots.
  [[nodiscard]] std::size_t capacity() const noexcept { return ring_.capacity(); }
  /// Occupancy at some recent instant.
  [[nodiscard]] std::size_t SizeApprox() const noexcept { return ring_.SizeApprox(); }

 private:
  SpscRing ring_;
  std::unique_ptr<T[]> storage_;
  std::atomic<std::uint64_t> drops_{0};
};

}  // namespace hiltwin::lockfree
