#pragma once
/// Waiting on a 32-bit word that two processes share (a MAP_SHARED mapping): the futex calls
/// without FUTEX_PRIVATE_FLAG, which C++20's std::atomic::wait (private to one process, no
/// timeout) cannot do. Used by the wire's lockstep (io/wire_bus.h): a side that has to wait for
/// the other first spins briefly (SpinPause), then sleeps here with a timeout, so its wait stays
/// bounded in wall time and it can look after its heartbeat between slices.

#include <atomic>
#include <cstdint>

#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::kernel_glue {

static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t) &&
                  std::atomic<std::uint32_t>::is_always_lock_free,
              "a futex word must be a plain 32-bit word");

/// Sleeps while `word` holds `expected`, at most `timeout_ns` (relative, CLOCK_MONOTONIC).
/// Returns at once when the word already differs; may return early (a wake, a signal, a
/// spurious wake-up): callers re-check their condition. Never throws, never allocates.
void SharedWait(const std::atomic<std::uint32_t>& word, std::uint32_t expected,
                TimeNs timeout_ns) noexcept;

/// Wakes every process sleeping in SharedWait on `word`.
void SharedWakeAll(const std::atomic<std::uint32_t>& word) noexcept;

/// One spin-loop hint (x86 `pause`, arm64 `yield`): lets the sibling hyper-thread run and
/// saves power while a waiter polls a word the other process is about to change.
inline void SpinPause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield" ::: "memory");
#endif
}

}  // namespace hiltwin::kernel_glue
