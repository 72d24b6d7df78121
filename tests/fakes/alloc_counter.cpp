#include "fakes/alloc_counter.h"

#include <cstdlib>
#include <new>

namespace {

// Thread-local so a background thread (logger writer, gtest) never pollutes the loop's count.
// This file is linked into the test executable, so the TLS is static: touching it cannot
// itself allocate.
thread_local std::uint64_t t_allocations = 0;
thread_local int t_armed = 0;

inline void Note() noexcept {
  if (t_armed > 0) ++t_allocations;
}

}  // namespace

namespace hiltwin::test {

ScopedAllocationCount::ScopedAllocationCount() noexcept : start_(t_allocations) { ++t_armed; }
ScopedAllocationCount::~ScopedAllocationCount() { --t_armed; }
std::uint64_t ScopedAllocationCount::count() const noexcept { return t_allocations - start_; }

#if defined(HILTWIN_UNDER_SANITIZER)
bool MallocIsCounted() noexcept { return false; }
#else
bool MallocIsCounted() noexcept { return true; }
#endif

}  // namespace hiltwin::test

#if !defined(HILTWIN_UNDER_SANITIZER)
// glibc exports its allocator under these names; forwarding to them lets us count malloc.
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t n, std::size_t size);
extern "C" void* __libc_realloc(void* p, std::size_t size);
extern "C" void __libc_free(void* p);

extern "C" void* malloc(std::size_t size) {
  Note();
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t n, std::size_t size) {
  Note();
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t size) {
  Note();
  return __libc_realloc(p, size);
}
extern "C" void free(void* p) { __libc_free(p); }
#endif

// operator new is counted in every build (replacing it is allowed under the sanitizers too).
void* operator new(std::size_t size) {
  Note();
  if (size == 0) size = 1;
  void* p = std::malloc(size);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  Note();
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return ::operator new(size, tag);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
