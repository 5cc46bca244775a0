// The per-sample path allocates nothing (the project's rule: fixed-size Eigen, no heap in a
// per-sample loop). This test program counts heap allocations
// (tests/support/allocation_counter.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "tests/support/allocation_counter.hpp"

namespace bd::core {
namespace {

TEST(NoAllocation, DynamicsOfOneInstantAllocatesNothing) {
  const FourBar m = samples::paper_fourbar();
  double sink = 0;
  const long before = testing::allocations();
  for (int i = 0; i < 360; ++i) {
    const double theta1 = 6.283185307179586 * i / 360;
    const auto f = forward_dynamics(m, theta1, 2.0);
    const auto g = inverse_dynamics(m, theta1, 2.0, 0.5);
    sink += f->state.alpha1 + g->tau;
  }
  EXPECT_EQ(testing::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAllocation, DrivenSimulationAllocatesIndependentlyOfTheSampleCount) {
  // the trajectory's vectors are reserved once: the count of allocations must not grow with
  // the number of samples
  const FourBar m = samples::paper_fourbar_unloaded();
  auto count = [&m](int samples) {
    const long before = testing::allocations();
    const Trajectory t = simulate_driven(m, {0.0, 6.283185307179586, 1, samples});
    EXPECT_TRUE(t.ok());
    return testing::allocations() - before;
  };
  const long few = count(36);
  EXPECT_GT(few, 0);  // the counter sees the trajectory's own vectors
  EXPECT_EQ(few, count(3600));
}

TEST(NoAllocation, FreeSimulationAllocatesIndependentlyOfTheSampleCount) {
  const FourBar m = samples::paper_fourbar();
  auto count = [&m](int samples) {
    const long before = testing::allocations();
    const Trajectory t = simulate_free(m, {1.0, 0.0, 5.0, samples});
    EXPECT_TRUE(t.ok());
    return testing::allocations() - before;
  };
  EXPECT_EQ(count(51), count(5001));
}

}  // namespace
}  // namespace bd::core
