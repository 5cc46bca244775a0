// The paper's §5.1 example in free motion (theta1 = 1 rad from rest, 5 s, 501 samples), checked
// sample by sample against an independent computation: the Newton-Euler referee integrated by
// the classical fixed-step Runge-Kutta method (no CVODE, no mass-matrix code).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "tests/reference/newton_euler.hpp"

namespace bd::core {
namespace {

struct Y {
  double theta1, omega1;
};

// RK4 of theta1'' = alpha1(theta1, omega1) from the referee, `substeps` steps per sample
std::vector<Y> referee_rk4(const FourBar& m, Y y, double dt, int samples, int substeps) {
  auto f = [&m](const Y& s) {
    return Y{s.omega1, reference::newton_euler_forward(m, s.theta1, s.omega1).state.alpha1};
  };
  std::vector<Y> out{y};
  const double h = dt / substeps;
  for (int i = 1; i < samples; ++i) {
    for (int k = 0; k < substeps; ++k) {
      const Y k1 = f(y);
      const Y k2 = f({y.theta1 + h / 2 * k1.theta1, y.omega1 + h / 2 * k1.omega1});
      const Y k3 = f({y.theta1 + h / 2 * k2.theta1, y.omega1 + h / 2 * k2.omega1});
      const Y k4 = f({y.theta1 + h * k3.theta1, y.omega1 + h * k3.omega1});
      y.theta1 += h / 6 * (k1.theta1 + 2 * k2.theta1 + 2 * k3.theta1 + k4.theta1);
      y.omega1 += h / 6 * (k1.omega1 + 2 * k2.omega1 + 2 * k3.omega1 + k4.omega1);
    }
    out.push_back(y);
  }
  return out;
}

TEST(PaperExample, FreeMotionMatchesRefereeIntegratedByRungeKutta) {
  const FourBar m = samples::paper_fourbar();
  const FreeScene scene{1.0, 0.0, 5.0, 501};
  const Trajectory traj = simulate_free(m, scene, SimulateOptions{});
  ASSERT_TRUE(traj.ok()) << traj.message;
  ASSERT_EQ(traj.samples.size(), 501u);

  // the reference itself: RK4 with h = 0.01/16 s and h/2 must agree far below 1e-8 (RK4's global
  // error ~ h^4 shrinks 16-fold per halving, so their difference bounds the coarser run's error)
  const double dt = scene.duration / (scene.samples - 1);
  const std::vector<Y> ref = referee_rk4(m, {1.0, 0.0}, dt, scene.samples, 16);
  const std::vector<Y> fine = referee_rk4(m, {1.0, 0.0}, dt, scene.samples, 32);
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ASSERT_NEAR(ref[i].theta1, fine[i].theta1, 1e-11) << "sample " << i;
    ASSERT_NEAR(ref[i].omega1, fine[i].omega1, 1e-11) << "sample " << i;
  }

  // scales: the largest magnitude of each quantity over the run
  double w_scale = 0, a_scale = 0, r_scale = 0;
  for (const DynamicsSample& s : traj.samples) {
    w_scale = std::max({w_scale, std::abs(s.state.omega1), std::abs(s.state.omega2),
                        std::abs(s.state.omega3)});
    a_scale = std::max({a_scale, std::abs(s.state.alpha1), std::abs(s.state.alpha2),
                        std::abs(s.state.alpha3)});
    r_scale = std::max({r_scale, s.RA0.norm(), s.RA3.norm()});
  }
  // the integrator runs at relative tolerance 1e-10; its global error over 5 s stays well below
  // the 1e-8 the product promises for this example
  const double tol = 1e-8;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const DynamicsSample& s = traj.samples[i];
    const DynamicsSample r = reference::newton_euler_forward(m, fine[i].theta1, fine[i].omega1);
    EXPECT_NEAR(traj.t[i], dt * static_cast<double>(i), 1e-14);
    EXPECT_NEAR(s.state.theta1, r.state.theta1, tol) << "sample " << i;
    EXPECT_NEAR(std::remainder(s.state.theta2 - r.state.theta2, 2 * std::numbers::pi), 0, tol);
    EXPECT_NEAR(std::remainder(s.state.theta3 - r.state.theta3, 2 * std::numbers::pi), 0, tol);
    EXPECT_NEAR(s.state.omega1, r.state.omega1, tol * w_scale) << "sample " << i;
    EXPECT_NEAR(s.state.omega2, r.state.omega2, tol * w_scale) << "sample " << i;
    EXPECT_NEAR(s.state.omega3, r.state.omega3, tol * w_scale) << "sample " << i;
    EXPECT_NEAR(s.state.alpha1, r.state.alpha1, tol * a_scale) << "sample " << i;
    EXPECT_NEAR(s.state.alpha2, r.state.alpha2, tol * a_scale) << "sample " << i;
    EXPECT_NEAR(s.state.alpha3, r.state.alpha3, tol * a_scale) << "sample " << i;
    EXPECT_LT((s.RA0 - r.RA0).norm(), tol * r_scale) << "sample " << i;
    EXPECT_LT((s.RA3 - r.RA3).norm(), tol * r_scale) << "sample " << i;
    EXPECT_NEAR(s.tau, 0.0, 0.0);
  }
}

}  // namespace
}  // namespace bd::core
