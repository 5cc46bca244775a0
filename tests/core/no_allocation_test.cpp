// The per-sample path allocates nothing (STYLE.md: fixed-size Eigen, no heap in a per-sample
// loop). This test program replaces the global operator new to count heap allocations.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "core/dynamics.hpp"
#include "core/samples.hpp"
#include "core/simulate.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace bd::core {
namespace {

TEST(NoAllocation, DynamicsOfOneInstantAllocatesNothing) {
  const FourBar m = samples::paper_fourbar();
  double sink = 0;
  const long before = g_allocations.load();
  for (int i = 0; i < 360; ++i) {
    const double theta1 = 6.283185307179586 * i / 360;
    const auto f = forward_dynamics(m, theta1, 2.0);
    const auto g = inverse_dynamics(m, theta1, 2.0, 0.5);
    sink += f->state.alpha1 + g->tau;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAllocation, DrivenSimulationAllocatesIndependentlyOfTheSampleCount) {
  // the trajectory's vectors are reserved once: the count of allocations must not grow with
  // the number of samples
  const FourBar m = samples::paper_fourbar_unloaded();
  auto count = [&m](int samples) {
    const long before = g_allocations.load();
    const Trajectory t = simulate_driven(m, {0.0, 6.283185307179586, 1, samples});
    EXPECT_TRUE(t.ok());
    return g_allocations.load() - before;
  };
  const long few = count(36);
  EXPECT_GT(few, 0);  // the counter sees the trajectory's own vectors
  EXPECT_EQ(few, count(3600));
}

TEST(NoAllocation, FreeSimulationAllocatesIndependentlyOfTheSampleCount) {
  const FourBar m = samples::paper_fourbar();
  auto count = [&m](int samples) {
    const long before = g_allocations.load();
    const Trajectory t = simulate_free(m, {1.0, 0.0, 5.0, samples});
    EXPECT_TRUE(t.ok());
    return g_allocations.load() - before;
  };
  EXPECT_EQ(count(51), count(5001));
}

}  // namespace
}  // namespace bd::core
