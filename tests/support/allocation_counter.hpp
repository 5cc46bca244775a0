#pragma once
// Test support: counts the heap allocations of a whole test program by replacing the global
// operator new, and can make one of them fail (fault injection: std::bad_alloc in the middle of
// a computation). Include it in exactly one file of a program (each tests/**/*_test.cpp is a
// program of its own); read the count with bd::testing::allocations().
#include <atomic>
#include <cstdlib>
#include <new>

namespace bd::testing {
inline std::atomic<long> g_allocations{0};
/// Heap allocations so far.
inline long allocations() { return g_allocations.load(); }

// fault injection: allocations of other threads still to succeed before one fails (< 0: none
// fails); the arming thread's own never fail
inline std::atomic<long> g_fail_after{-1};
inline thread_local bool t_spared = false;
inline std::atomic<long> g_failed{0};

/// Makes the (n+1)-th heap allocation after this call in a thread other than the calling one
/// throw std::bad_alloc, once. The calling thread (e.g. a sweep's writer) is spared from now on.
inline void fail_an_allocation_of_another_thread(long n) {
  t_spared = true;
  g_fail_after.store(n);
}
/// How many allocations were made to fail so far.
inline long failed_allocations() { return g_failed.load(); }
}  // namespace bd::testing

// Not inlined: GCC 12 with -fsanitize=address (.ci/sanitize) inlines these into their callers and
// then warns that free() meets a pointer from operator new (-Wmismatched-new-delete), although
// this operator new returns malloc's pointer.
[[gnu::noinline]] void* operator new(std::size_t n) {
  ++bd::testing::g_allocations;
  if (!bd::testing::t_spared) {
    long left = bd::testing::g_fail_after.load();
    while (left >= 0 && !bd::testing::g_fail_after.compare_exchange_weak(left, left - 1)) {
    }
    if (left == 0) {  // this thread took the count from 0 to -1: its allocation fails
      ++bd::testing::g_failed;
      throw std::bad_alloc();
    }
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }
