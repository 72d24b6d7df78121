#pragma once
/// A latest-value mailbox between one writer (the real-time loop) and one reader (the telemetry
/// thread): a triple buffer. The writer fills its own slot and swaps it with the shared one in
/// one atomic exchange; the reader, when the shared slot is fresh, swaps it with its own. Both
/// sides are wait-free: the writer never blocks, retries or allocates, however slow the reader,
/// and the reader always gets the newest complete value, never a torn one. Unlike a seqlock,
/// every access to a slot is ordered by the exchange, so ThreadSanitizer understands it.

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

#include "hiltwin/lockfree/cache_line.h"

namespace hiltwin::lockfree {

template <typename T>
class LatestValue {
  static_assert(std::is_trivially_copyable_v<T>, "the mailbox copies values byte for byte");

 public:
  /// The writer's slot: fill it, then Publish(). Writer thread only.
  [[nodiscard]] T& Back() noexcept { return slots_[back_].value; }
  /// Makes the writer's slot the newest value. Writer thread only; wait-free.
  void Publish() noexcept {
    back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel) &
            kIndexMask;
    ++published_;
  }

  /// Takes the newest value if one arrived since the last call (true), and returns the
  /// reader's current value either way through Front(). Reader thread only; wait-free.
  bool Update() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndexMask;
    return true;
  }
  /// The value the last Update() took (a default T before the first). Reader thread only.
  [[nodiscard]] const T& Front() const noexcept { return slots_[front_].value; }

  /// Values published so far. Writer thread only (a plain count, for tests and benchmarks).
  [[nodiscard]] std::uint64_t published() const noexcept { return published_; }

 private:
  static constexpr std::uint8_t kIndexMask = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;
  /// One cache line each at least, so the writer's stores never share a line with the reader.
  struct alignas(kCacheLineBytes) Slot {
    T value{};
  };
  std::array<Slot, 3> slots_{};
  alignas(kCacheLineBytes) std::atomic<std::uint8_t> middle_{1};
  alignas(kCacheLineBytes) std::uint8_t back_ = 0;   // writer's
  std::uint64_t published_ = 0;                                   // writer's
  alignas(kCacheLineBytes) std::uint8_t front_ = 2;  // reader's
};

}  // namespace hiltwin::lockfree
