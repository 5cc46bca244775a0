// The per-sample path allocates nothing (the project's rule: no heap in a per-sample loop; the
// four-bar uses fixed-size Eigen, the general engine its Workspace's buffers). This test program counts heap allocations
// (tests/support/allocation_counter.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
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

// The general engine: a sample (position by Newton or the chord method, then inverse or forward
// dynamics and every force) works in its Workspace's buffers.
TEST(NoAllocation, PlanarInstantAllocatesNothing) {
  const planar::Model model(planar::linkage_of(samples::paper_fourbar(), 1.0));
  planar::Workspace ws(model);
  std::vector<Vec2> guess = ws.instant.x;
  std::vector<double> z{1.0};
  const std::vector<double> rate{2.0}, acceleration{0.5}, effort{0.3};
  // one evaluation first: the instant's vectors take their sizes
  ASSERT_TRUE(planar::solve_position(model, ws, guess, z));
  ASSERT_TRUE(planar::inverse_dynamics(model, ws, 0.0, rate, acceleration));
  double sink = 0;
  const long before = testing::allocations();
  for (int i = 1; i <= 360; ++i) {
    z[0] = 1.0 + 6.283185307179586 * i / 360;
    guess = ws.instant.x;
    const bool ok = planar::solve_position(model, ws, guess, z) &&
                    planar::inverse_dynamics(model, ws, 0.0, rate, acceleration) &&
                    planar::forward_dynamics(model, ws, 0.0, rate, effort);
    EXPECT_TRUE(ok);
    sink += ws.instant.Msh + ws.instant.input_acceleration[0];
  }
  EXPECT_EQ(testing::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAllocation, PlanarDrivenSimulationAllocatesIndependentlyOfTheSampleCount) {
  const planar::Model model(planar::linkage_of(samples::paper_fourbar(), 0.0));
  auto count = [&model](int samples) {
    const long before = testing::allocations();
    const planar::Trajectory t =
        planar::simulate_driven(model, planar::DrivenScene{{0.0}, {6.283185307179586}, 1, 0, samples});
    EXPECT_TRUE(t.ok()) << t.message;
    return testing::allocations() - before;
  };
  EXPECT_EQ(count(36), count(3600));
}

TEST(NoAllocation, PlanarFreeSimulationAllocatesIndependentlyOfTheSampleCount) {
  const planar::Model model(planar::linkage_of(samples::paper_fourbar(), 1.0));
  for (planar::Route route : {planar::Route::kReduced, planar::Route::kDae}) {
    long steps = 0;
    auto count = [&](double duration, int samples) {
      planar::SimulateOptions o;
      o.route = route;
      const long before = testing::allocations();
      const planar::Trajectory t =
          planar::simulate_free(model, planar::FreeScene{{1.0}, {0.0}, duration, samples}, o);
      EXPECT_TRUE(t.ok()) << t.message;
      steps = t.steps;
      return testing::allocations() - before;
    };
    // per sample: more samples over the same run
    EXPECT_EQ(count(5.0, 51), count(5.0, 5001)) << planar::to_string(route);
    // per step and evaluation: a run four times as long, as many samples
    const long short_run = count(2.0, 51);
    const long short_steps = steps;
    EXPECT_EQ(short_run, count(8.0, 51)) << planar::to_string(route);
    EXPECT_GT(steps, short_steps + 100) << planar::to_string(route);  // hundreds more steps
  }
}

}  // namespace
}  // namespace bd::core
