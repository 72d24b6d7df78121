#include "hiltwin/kernel_glue/shared_wait.h"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <climits>

namespace hiltwin::kernel_glue {
namespace {

long Futex(const std::atomic<std::uint32_t>& word, int op, std::uint32_t value,
           const struct timespec* timeout) noexcept {
  // The kernel reads the word at its address; std::atomic<uint32_t> is that word (asserted).
  auto* address = const_cast<std::uint32_t*>(reinterpret_cast<const std::uint32_t*>(&word));
  return ::syscall(SYS_futex, address, op, value, timeout, nullptr, 0);
}

}  // namespace

void SharedWait(const std::atomic<std::uint32_t>& word, std::uint32_t expected,
                TimeNs timeout_ns) noexcept {
  if (timeout_ns <= 0) return;
  struct timespec timeout {};
  timeout.tv_sec = static_cast<time_t>(timeout_ns / kNsPerS);
  timeout.tv_nsec = static_cast<long>(timeout_ns % kNsPerS);
  // FUTEX_WAIT, not FUTEX_WAIT_PRIVATE: the word lives in a mapping both processes share.
  // EAGAIN (the word changed), EINTR and ETIMEDOUT all mean "look again": nothing to report.
  static_cast<void>(Futex(word, FUTEX_WAIT, expected, &timeout));
}

void SharedWakeAll(const std::atomic<std::uint32_t>& word) noexcept {
  static_cast<void>(Futex(word, FUTEX_WAKE, INT_MAX, nullptr));
}

}  // namespace hiltwin::kernel_glue
