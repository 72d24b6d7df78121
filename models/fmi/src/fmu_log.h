#pragma once
// The FMU's logger callback. An FMU may log from inside fmi2DoStep, on the loop thread, so the
// callback only formats into a preallocated ring of fixed-size slots (no allocation, no lock,
// no I/O); Drain() writes the messages out later, off the loop.
//
// One producer at a time: the thread calling into the FMU (the main thread in Start, the loop
// thread in Step). An FMU that logs from threads of its own, concurrently, is not supported.

#include <atomic>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "hiltwin/fmi/fmi2_abi.h"
#include "hiltwin/lockfree/cache_line.h"

namespace hiltwin::fmi {

class FmuLog {
 public:
  using Sink = std::function<void(std::string_view line)>;
  static constexpr std::size_t kTextBytes = 440;  ///< longer messages are cut, ending "..."
  static constexpr std::size_t kCategoryBytes = 56;

  /// `capacity_messages` slots (at least 1); `sink` gets each drained line (default: stderr).
  FmuLog(std::string instance_name, std::size_t capacity_messages, Sink sink);

  /// The fmi2CallbackLogger to give the FMU, with `this` as its componentEnvironment.
  static void Callback(fmi2ComponentEnvironment environment, fmi2String instance_name,
                       fmi2Status status, fmi2String category, fmi2String message, ...) noexcept;

  /// Not real-time. Writes every queued message, then one line with the number dropped since
  /// the last drain if any. Returns the messages written. Serialised by a mutex that the
  /// producer never takes.
  std::size_t Drain();

  [[nodiscard]] std::uint64_t dropped() const noexcept {
    return dropped_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

 private:
  struct Slot {
    fmi2Status status = fmi2OK;
    char category[kCategoryBytes] = {};
    char text[kTextBytes] = {};
  };

  void Push(fmi2Status status, const char* category, const char* format,
            std::va_list args) noexcept;
  [[nodiscard]] std::string Format(const Slot& slot) const;

  std::string instance_name_;
  std::size_t capacity_;
  std::unique_ptr<Slot[]> slots_;
  Sink sink_;
  std::mutex drain_mutex_;
  std::uint64_t dropped_reported_ = 0;  ///< guarded by drain_mutex_
  // Monotonic counts: slot = count % capacity; full when written - read == capacity.
  alignas(lockfree::kCacheLineBytes) std::atomic<std::uint64_t> written_{0};
  alignas(lockfree::kCacheLineBytes) std::atomic<std::uint64_t> read_{0};
  alignas(lockfree::kCacheLineBytes) std::atomic<std::uint64_t> dropped_{0};
};

/// "fmi2Warning" for fmi2Warning, ...; "fmi2Status(N)" spelled by the caller otherwise.
[[nodiscard]] const char* StatusName(fmi2Status status) noexcept;

}  // namespace hiltwin::fmi
