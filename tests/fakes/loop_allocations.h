#pragma once
// A RunSession hook that counts the loop thread's heap allocations from its first cycle to
// after the safe outputs: the proof that the real-time path allocates nothing. Header-only, for
// tests that link hiltwin::runtime.

#include <cstdint>
#include <optional>

#include "fakes/alloc_counter.h"
#include "hiltwin/runtime/run_session.h"

namespace hiltwin::test {

class LoopAllocations final : public runtime::LoopThreadHooks {
 public:
  void BeforeLoop() noexcept override { counter_.emplace(); }
  void AfterLoop() noexcept override {
    count = counter_->count();
    counter_.reset();
  }
  /// Allocations counted; all ones until the loop has run.
  std::uint64_t count = ~std::uint64_t{0};

 private:
  std::optional<ScopedAllocationCount> counter_;
};

}  // namespace hiltwin::test
