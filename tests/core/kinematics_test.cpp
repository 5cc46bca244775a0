// Closed-form kinematics (paper eqs. 2-10) against finite differences, loop closure, both
// branches, Grashof classes, transmission angle and the assembly-failure error.
#include "core/fourbar/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/fourbar/samples.hpp"

namespace bd::core {
namespace {

constexpr double kPi = std::numbers::pi;

// angle difference folded into (-pi, pi]
double angle_diff(double a, double b) { return std::remainder(a - b, 2 * kPi); }

Pose pose_at(const FourBar& m, double theta1) {
  const auto p = solve_position(m, theta1);
  EXPECT_TRUE(p.has_value()) << "theta1 = " << theta1;
  return *p;
}

TEST(Kinematics, LoopClosesToRoundOffOnBothBranches) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    FourBar m = samples::random_crank_rocker(rng);
    const double scale = m.crank.length + m.coupler.length + m.rocker.length + m.frame_length;
    for (Branch b : {Branch::kPlus, Branch::kMinus}) {
      for (int i = 0; i < 36; ++i) {
        const double theta1 = 2 * kPi * i / 36;
        const auto p = solve_position(m, theta1, b);
        ASSERT_TRUE(p.has_value());
        // a sum of four vectors of length <= scale: round-off a few eps * scale
        EXPECT_LE(closure_residual(m, *p), 1e-14 * scale) << "theta1 = " << theta1;
      }
    }
  }
}

TEST(Kinematics, BranchesAreMirrorImagesAboutA1A3) {
  const FourBar m = samples::paper_fourbar();
  for (int i = 0; i < 24; ++i) {
    const double theta1 = 2 * kPi * i / 24;
    const Pose plus = *solve_position(m, theta1, Branch::kPlus);
    const Pose minus = *solve_position(m, theta1, Branch::kMinus);
    const Joints jp = joint_positions(m, plus), jm = joint_positions(m, minus);
    const Vec2 d = jp.A3 - jp.A1;
    // A2 left of A1->A3 on branch +1 (h23 > 0), right on -1, at the same distances
    EXPECT_GT(cross(d, jp.A2 - jp.A1), 0);
    EXPECT_LT(cross(d, jm.A2 - jm.A1), 0);
    EXPECT_NEAR((jp.A2 - jp.A1).norm(), m.coupler.length, 1e-14);
    EXPECT_NEAR((jm.A2 - jm.A1).norm(), m.coupler.length, 1e-14);
    EXPECT_NEAR((jm.A3 - jm.A2).norm(), m.rocker.length, 1e-14);
    EXPECT_NEAR(d.dot(jp.A2 - jp.A1), d.dot(jm.A2 - jm.A1), 1e-13);
  }
}

TEST(Kinematics, RatesMatchCentralDifferencesOfPositions) {
  std::mt19937_64 rng(12);
  // h = 1e-5: truncation ~ h^2 |θ'''| ~ 1e-10, round-off ~ eps/h ~ 2e-11
  const double h = 1e-5;
  for (int trial = 0; trial < 50; ++trial) {
    const FourBar m = samples::random_crank_rocker(rng);
    for (int i = 0; i < 12; ++i) {
      const double theta1 = 2 * kPi * (i + 0.37) / 12, omega1 = 1.7;
      const FourBarState s = solve_velocity(m, pose_at(m, theta1), omega1);
      const Pose a = pose_at(m, theta1 + h), b = pose_at(m, theta1 - h);
      const double w2 = angle_diff(a.theta2, b.theta2) / (2 * h) * omega1;
      const double w3 = angle_diff(a.theta3, b.theta3) / (2 * h) * omega1;
      const double scale = std::max({1.0, std::abs(s.omega2), std::abs(s.omega3)});
      EXPECT_NEAR(s.omega2, w2, 1e-7 * scale) << "trial " << trial << " theta1 " << theta1;
      EXPECT_NEAR(s.omega3, w3, 1e-7 * scale) << "trial " << trial << " theta1 " << theta1;
    }
  }
}

TEST(Kinematics, AccelerationsMatchCentralDifferencesOfRates) {
  std::mt19937_64 rng(13);
  // along theta1(t) = theta1 + omega1 t + alpha1 t^2 / 2, omega1(t) = omega1 + alpha1 t;
  // h = 1e-5 s: truncation ~ h^2, round-off ~ eps/h
  const double h = 1e-5;
  for (int trial = 0; trial < 50; ++trial) {
    const FourBar m = samples::random_crank_rocker(rng);
    for (int i = 0; i < 12; ++i) {
      const double theta1 = 2 * kPi * (i + 0.61) / 12, omega1 = -2.3, alpha1 = 4.1;
      const FourBarState s =
          solve_acceleration(m, solve_velocity(m, pose_at(m, theta1), omega1), alpha1);
      auto rates = [&](double t) {
        return solve_velocity(m, pose_at(m, theta1 + omega1 * t + alpha1 * t * t / 2),
                              omega1 + alpha1 * t);
      };
      const FourBarState a = rates(h), b = rates(-h);
      const double a2 = (a.omega2 - b.omega2) / (2 * h), a3 = (a.omega3 - b.omega3) / (2 * h);
      const double scale = std::max({1.0, std::abs(s.alpha2), std::abs(s.alpha3)});
      EXPECT_NEAR(s.alpha2, a2, 1e-6 * scale) << "trial " << trial << " theta1 " << theta1;
      EXPECT_NEAR(s.alpha3, a3, 1e-6 * scale) << "trial " << trial << " theta1 " << theta1;
      EXPECT_DOUBLE_EQ(s.alpha1, alpha1);
    }
  }
}

TEST(Kinematics, CentreOfMassVelocityAndAccelerationMatchDifferences) {
  const FourBar m = samples::paper_fourbar();
  const double theta1 = 0.8, omega1 = 1.3, alpha1 = -0.7, h = 1e-5;
  auto state = [&](double t) {
    return solve_acceleration(
        m, solve_velocity(m, pose_at(m, theta1 + omega1 * t + alpha1 * t * t / 2), omega1 + alpha1 * t),
        alpha1);
  };
  const FourBarState s0 = state(0), sp = state(h), sm = state(-h);
  for (int k = 1; k <= 3; ++k) {
    const Vec2 v_fd = (centre_of_mass(m, k, pose_of(sp)) - centre_of_mass(m, k, pose_of(sm))) / (2 * h);
    const Vec2 a_fd = (centre_of_mass_velocity(m, k, sp) - centre_of_mass_velocity(m, k, sm)) / (2 * h);
    EXPECT_LT((centre_of_mass_velocity(m, k, s0) - v_fd).norm(), 1e-8) << "link " << k;
    EXPECT_LT((centre_of_mass_acceleration(m, k, s0) - a_fd).norm(), 1e-7) << "link " << k;
  }
}

TEST(Kinematics, ParallelogramKeepsCouplerAngle) {
  const FourBar m = samples::parallelogram();
  for (int i = 1; i < 12; ++i) {
    const double theta1 = kPi * i / 12;  // branch +1 is the parallelogram on (0, pi)
    const Pose p = pose_at(m, theta1);
    EXPECT_NEAR(p.theta2, 0.0, 1e-14);
    EXPECT_NEAR(angle_diff(p.theta3, theta1 + kPi), 0.0, 1e-14);
    const FourBarState s = solve_acceleration(m, solve_velocity(m, p, 2.0), 3.0);
    EXPECT_NEAR(s.omega2, 0.0, 1e-14);
    EXPECT_NEAR(s.alpha2, 0.0, 1e-13);
    EXPECT_NEAR(s.omega3, 2.0, 1e-14);
  }
}

TEST(Kinematics, AssemblyFailureIsReportedWithTheGap) {
  // double rocker: l23 = |A1A3| reaches l1 + l4 = 4.5 > l2 + l3 = 3 at theta1 = pi
  FourBar m = samples::paper_fourbar();
  m.crank.length = 1.5;
  m.coupler.length = 1.0;
  m.rocker.length = 2.0;
  m.frame_length = 3.0;
  const auto p = solve_position(m, kPi);
  ASSERT_FALSE(p.has_value());
  EXPECT_NEAR(p.error().gap, 1.5, 1e-12);
  EXPECT_NE(p.error().what().find("theta1 = 3.14159 rad"), std::string::npos) << p.error().what();
  EXPECT_NE(p.error().what().find("exceeds l2 + l3 by 1.5 m"), std::string::npos);
  // too short: |A1A3| = 1.5 < |l2 - l3| = 2 at theta1 = 0 when l4 = 3, l1 = 1.5, l2 = 1, l3 = 3
  m.rocker.length = 3.0;
  const auto q = solve_position(m, 0.0);
  ASSERT_FALSE(q.has_value());
  EXPECT_NEAR(q.error().gap, -0.5, 1e-12);
  EXPECT_NE(q.error().what().find("falls short of |l2 - l3| by 0.5 m"), std::string::npos);
}

TEST(Kinematics, FlatTriangleAtTheLimitStillCloses) {
  // l1 + l4 = l2 + l3 exactly at theta1 = pi: flat, h23 = 0
  FourBar m = samples::paper_fourbar();
  m.crank.length = 1.0;
  m.frame_length = 2.0;
  m.coupler.length = 1.5;
  m.rocker.length = 1.5;
  const auto p = solve_position(m, kPi);
  ASSERT_TRUE(p.has_value());
  EXPECT_LE(closure_residual(m, *p), 1e-14);
  EXPECT_NEAR(std::sin(p->theta3 - p->theta2), 0.0, 1e-7);
}

TEST(Kinematics, TransmissionAngle) {
  // square: at theta1 = pi/2 the coupler is horizontal and the rocker vertical: mu = pi/2
  FourBar m = samples::paper_fourbar();
  m.crank.length = m.coupler.length = m.rocker.length = m.frame_length = 1.0;
  const Pose p = pose_at(m, kPi / 2);
  EXPECT_NEAR(transmission_angle(p), kPi / 2, 1e-14);
  // paper linkage: mu from the law of cosines on triangle A1 A2 A3
  const FourBar q = samples::paper_fourbar();
  for (double theta1 : {0.0, 1.0, 2.5, 4.0}) {
    const Pose r = pose_at(q, theta1);
    const double l23 = (joint_positions(q, r).A3 - joint_positions(q, r).A1).norm();
    const double l2 = q.coupler.length, l3 = q.rocker.length;
    EXPECT_NEAR(std::cos(transmission_angle(r)), (l2 * l2 + l3 * l3 - l23 * l23) / (2 * l2 * l3),
                1e-14);
  }
}

TEST(Kinematics, GrashofClasses) {
  auto make = [](double l1, double l2, double l3, double l4) {
    FourBar m = samples::paper_fourbar();
    m.crank.length = l1;
    m.coupler.length = l2;
    m.rocker.length = l3;
    m.frame_length = l4;
    return m;
  };
  EXPECT_EQ(classify_grashof(samples::paper_fourbar()), GrashofClass::kCrankRocker);
  EXPECT_TRUE(crank_turns_fully(samples::paper_fourbar()));
  EXPECT_EQ(classify_grashof(make(2, 3, 2.5, 1)), GrashofClass::kDoubleCrank);
  EXPECT_TRUE(crank_turns_fully(make(2, 3, 2.5, 1)));
  EXPECT_EQ(classify_grashof(make(2, 1, 2.5, 3)), GrashofClass::kDoubleRocker);
  EXPECT_FALSE(crank_turns_fully(make(2, 1, 2.5, 3)));
  EXPECT_EQ(classify_grashof(make(2, 2.5, 1, 3)), GrashofClass::kRockerCrank);
  EXPECT_FALSE(crank_turns_fully(make(2, 2.5, 1, 3)));
  EXPECT_EQ(classify_grashof(samples::parallelogram()), GrashofClass::kChangePoint);
  EXPECT_TRUE(crank_turns_fully(samples::parallelogram()));
  EXPECT_EQ(classify_grashof(make(3, 3, 2.5, 6)), GrashofClass::kNonGrashof);
  EXPECT_FALSE(crank_turns_fully(make(3, 3, 2.5, 6)));
  EXPECT_STREQ(to_string(GrashofClass::kDoubleRocker), "double-rocker");
}

}  // namespace
}  // namespace bd::core
