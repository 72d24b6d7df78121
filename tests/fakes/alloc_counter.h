#pragma once
/// Counts heap allocations made by the current thread while a ScopedAllocationCount is alive.
/// Replaces global operator new (every build) and malloc/calloc/realloc (builds without
/// sanitizers: the sanitizers own malloc). Used to prove the real-time path allocates nothing.

#include <cstdint>

namespace hiltwin::test {

/// True when malloc itself is counted (not only operator new).
bool MallocIsCounted() noexcept;

class ScopedAllocationCount {
 public:
  ScopedAllocationCount() noexcept;
  ~ScopedAllocationCount();
  ScopedAllocationCount(const ScopedAllocationCount&) = delete;
  ScopedAllocationCount& operator=(const ScopedAllocationCount&) = delete;
  /// Allocations by this thread since construction.
  [[nodiscard]] std::uint64_t count() const noexcept;

 private:
  std::uint64_t start_;
};

}  // namespace hiltwin::test
