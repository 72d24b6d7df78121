#pragma once
/// A single-writer seqlock over a few 64-bit words, made only of atomic loads and stores (no
/// fences), after H.-J. Boehm, "Can seqlocks get along with programming language memory
/// models?" (MSPC 2012), so ThreadSanitizer understands it and it works across processes in
/// shared memory. Used by the wire backend's ring of encoder periods (wire_bus.cpp).
///
/// Writer of version `tag`: sequence = 2·tag + 1 (relaxed); every word (release);
/// sequence = 2·tag (release). Reader of `tag`: s1 = sequence (acquire); every word (acquire);
/// s2 = sequence (relaxed); the words are accepted iff s1 == s2 == 2·tag.
///
/// Why an accepted read is one write's words (the sequence values of a slot only grow, as its
/// single writer writes ever larger tags):
/// - s1 == 2·tag reads the final release store of write `tag`, so every word store of that write
///   happens before the reader's word loads: each load sees that write's value or a later one.
/// - If a word load sees a later write's value, that value was stored with release after (in
///   program order) the later write's relaxed store of its odd sequence; the acquire load
///   synchronises with it, so that odd store happens before the reader's s2 load, and by
///   read-read coherence s2 reads it or a later value: s2 > s1, the read is refused.
/// So no fence is needed. On x86 release stores and acquire loads are plain moves; the only cost
/// over relaxed accesses is that the compiler keeps their order, which a seqlock needs anyway.
///
/// The reader never retries: a slot being written, overwritten or left half-written forever (a
/// writer that crashed, or another process scribbling over shared memory) is just refused, so it
/// cannot make a reader wait. Zero-filled memory is a valid state (no version published).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace hiltwin::lockfree {

template <std::size_t kWords>
struct SeqlockSlot {
  std::atomic<std::uint64_t> sequence;  ///< 2·tag when version `tag` is complete, odd while written
  std::array<std::atomic<std::uint64_t>, kWords> words;
};

/// Publishes `words` as version `tag` (> every tag written to this slot before). One writer per
/// slot.
template <std::size_t kWords>
void SeqlockWrite(SeqlockSlot<kWords>& slot, std::uint64_t tag,
                  const std::array<std::uint64_t, kWords>& words) noexcept {
  slot.sequence.store(2 * tag + 1, std::memory_order_relaxed);
  for (std::size_t i = 0; i < kWords; ++i) slot.words[i].store(words[i], std::memory_order_release);
  slot.sequence.store(2 * tag, std::memory_order_release);
}

/// Copies version `tag` into `out`; false (and `out` unspecified) when the slot holds another
/// version or is being written.
template <std::size_t kWords>
bool SeqlockRead(const SeqlockSlot<kWords>& slot, std::uint64_t tag,
                 std::array<std::uint64_t, kWords>& out) noexcept {
  const std::uint64_t before = slot.sequence.load(std::memory_order_acquire);
  if (before != 2 * tag) return false;
  for (std::size_t i = 0; i < kWords; ++i) out[i] = slot.words[i].load(std::memory_order_acquire);
  return slot.sequence.load(std::memory_order_relaxed) == before;
}

}  // namespace hiltwin::lockfree
