#pragma once
/// Commands from other threads to one consumer (a running session's loop takes signal
/// forwarding, telemetry sinks and tests' commands), kept in the order they were sent. A
/// bounded queue after Dmitry Vyukov's: every slot carries a sequence number, producers claim a
/// slot with one compare-exchange, the consumer (the loop, after its cycle) takes slots in order. Nothing allocates after construction;
/// the consumer never waits (a slot a producer has claimed but not yet filled reads as empty,
/// and is taken next cycle), and a full queue refuses the command rather than blocking.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "hiltwin/lockfree/cache_line.h"

namespace hiltwin::lockfree {

template <typename T, std::size_t kCapacity>
class CommandQueue {
  static_assert(kCapacity >= 2 && (kCapacity & (kCapacity - 1)) == 0, "a power of two");

 public:
  CommandQueue() noexcept {
    for (std::size_t i = 0; i < kCapacity; ++i)
      cells_[i].sequence.store(i, std::memory_order_relaxed);
  }

  /// Any thread. False when the queue is full (the command is refused, not lost silently: the
  /// caller says so).
  [[nodiscard]] bool TryPush(const T& value) noexcept {
    std::size_t position = enqueue_.load(std::memory_order_relaxed);
    for (;;) {
      Cell& cell = cells_[position & kMask];
      const std::size_t sequence = cell.sequence.load(std::memory_order_acquire);
      const auto lag = static_cast<std::ptrdiff_t>(sequence - position);
      if (lag == 0) {
        if (enqueue_.compare_exchange_weak(position, position + 1, std::memory_order_relaxed)) {
          cell.value = value;
          cell.sequence.store(position + 1, std::memory_order_release);
          return true;
        }
      } else if (lag < 0) {
        return false;  // full: the consumer has not freed this slot yet
      } else {
        position = enqueue_.load(std::memory_order_relaxed);
      }
    }
  }

  /// The one consumer. False when nothing (complete) is queued.
  [[nodiscard]] bool TryPop(T& out) noexcept {
    const std::size_t position = dequeue_.load(std::memory_order_relaxed);
    Cell& cell = cells_[position & kMask];
    if (cell.sequence.load(std::memory_order_acquire) != position + 1) return false;
    out = cell.value;
    cell.sequence.store(position + kCapacity, std::memory_order_release);
    dequeue_.store(position + 1, std::memory_order_relaxed);
    return true;
  }

  /// The consumer's cheap check before TryPop: two relaxed loads, no locked instruction.
  [[nodiscard]] bool MaybeNonEmpty() const noexcept {
    return enqueue_.load(std::memory_order_relaxed) != dequeue_.load(std::memory_order_relaxed);
  }

 private:
  static constexpr std::size_t kMask = kCapacity - 1;
  struct Cell {
    std::atomic<std::size_t> sequence{0};
    T value{};
  };
  std::array<Cell, kCapacity> cells_;
  alignas(kCacheLineBytes) std::atomic<std::size_t> enqueue_{0};
  alignas(kCacheLineBytes) std::atomic<std::size_t> dequeue_{0};
};

}  // namespace hiltwin::lockfree
