#pragma once
// Test support: counts the heap allocations of a whole test program by replacing the global
// operator new. Include it in exactly one file of a program (each tests/**/*_test.cpp is a
// program of its own); read the count with bd::testing::allocations().
#include <atomic>
#include <cstdlib>
#include <new>

namespace bd::testing {
inline std::atomic<long> g_allocations{0};
/// Heap allocations so far.
inline long allocations() { return g_allocations.load(); }
}  // namespace bd::testing

void* operator new(std::size_t n) {
  ++bd::testing::g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
