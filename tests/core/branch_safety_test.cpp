// A simulation never jumps to the other assembly branch: A2 stays on the model's side of the
// directed line A1 -> A3 at every sample, the loop stays closed, and the angles are continuous,
// over many revolutions of a crank-rocker and a double-crank, free and driven.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"

namespace bd::core {
namespace {

// side of A2 relative to the directed line A1 -> A3: +1 left, -1 right
double side(const FourBar& m, const FourBarState& s) {
  const Joints j = joint_positions(m, pose_of(s));
  return std::copysign(1.0, cross(j.A3 - j.A1, j.A2 - j.A1));
}

void expect_on_branch(const FourBar& m, const Trajectory& t) {
  ASSERT_TRUE(t.ok()) << t.message;
  const double scale = m.crank.length + m.coupler.length + m.rocker.length + m.frame_length;
  for (std::size_t i = 0; i < t.samples.size(); ++i) {
    const FourBarState& s = t.samples[i].state;
    ASSERT_EQ(side(m, s), sign(m.branch)) << "sample " << i << ", t = " << t.t[i];
    ASSERT_LE(closure_residual(m, pose_of(s)), 1e-13 * scale) << "sample " << i;
    if (i > 0) {
      const FourBarState& p = t.samples[i - 1].state;
      // consecutive samples are close in crank angle here, so the others move by much less
      // than a half turn: a jump would show as a change near 2 pi
      ASSERT_LT(std::abs(s.theta2 - p.theta2), 1.0) << "sample " << i;
      ASSERT_LT(std::abs(s.theta3 - p.theta3), 1.0) << "sample " << i;
    }
  }
}

TEST(BranchSafety, CrankRockerDrivenForManyRevolutionsStaysOnItsBranch) {
  for (Branch b : {Branch::kPlus, Branch::kMinus}) {
    FourBar m = samples::paper_fourbar_unloaded();
    m.branch = b;
    const Trajectory t = simulate_driven(m, {0.3, 2 * std::numbers::pi, 50, 72});
    expect_on_branch(m, t);
    // the crank made 50 turns, the rocker none: θ3 is back where it started
    const double dtheta1 = t.samples.back().state.theta1 - t.samples.front().state.theta1;
    EXPECT_NEAR(dtheta1, 2 * std::numbers::pi * (50 - 1.0 / 72), 1e-9);
  }
}

TEST(BranchSafety, DoubleCrankInFreeMotionForManyRevolutionsStaysOnItsBranch) {
  for (Branch b : {Branch::kPlus, Branch::kMinus}) {
    FourBar m = samples::double_crank();
    m.branch = b;
    // 60 s at about one revolution per second under no load
    const Trajectory t = simulate_free(m, {0.0, 6.0, 60.0, 6001});
    expect_on_branch(m, t);
    const FourBarState& last = t.samples.back().state;
    EXPECT_GT(last.theta1, 2 * std::numbers::pi * 20);  // many turns of the crank ...
    EXPECT_GT(std::abs(last.theta3 - t.samples.front().state.theta3),
              2 * std::numbers::pi * 20);  // ... and of the rocker, counted continuously
  }
}

TEST(BranchSafety, CrankRockerInFreeMotionUnderLoadsStaysOnItsBranch) {
  for (Branch b : {Branch::kPlus, Branch::kMinus}) {
    FourBar m = samples::paper_fourbar();
    m.branch = b;
    const Trajectory t = simulate_free(m, {1.0, 4.0, 30.0, 3001});
    expect_on_branch(m, t);
  }
}

}  // namespace
}  // namespace bd::core
