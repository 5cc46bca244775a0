// Issue "formulations": the three formulations and the Newton-Euler referee agree at the 501
// instants of the paper example's free motion, forward and inverse, to 1e-10 relative to each
// quantity's scale over the run. (Random linkages: each formulation's own test compares it with
// the referee and the mass matrix on 300 random states.)
#include <gtest/gtest.h>

#include <algorithm>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "tests/reference/newton_euler.hpp"

namespace bd::core {
namespace {

struct Scales {
  double alpha{}, force{}, moment{};
};

Scales scales_of(const Trajectory& t) {
  Scales s;
  for (const DynamicsSample& d : t.samples) {
    s.alpha = std::max({s.alpha, std::abs(d.state.alpha1), std::abs(d.state.alpha2),
                        std::abs(d.state.alpha3)});
    s.force = std::max({s.force, d.RA0.norm(), d.RA3.norm()});
    s.moment = std::max({s.moment, std::abs(d.Msh)});
  }
  return s;
}

// every output of two samples, each relative to its scale over the run
void expect_agree(const DynamicsSample& a, const DynamicsSample& b, const Scales& s,
                  const std::string& what) {
  // all routes are exact; they differ by the round-off of a few small solves, ~1e-14
  const double tol = 1e-10;
  EXPECT_NEAR(a.state.alpha1, b.state.alpha1, tol * s.alpha) << what;
  EXPECT_NEAR(a.state.alpha2, b.state.alpha2, tol * s.alpha) << what;
  EXPECT_NEAR(a.state.alpha3, b.state.alpha3, tol * s.alpha) << what;
  EXPECT_LT((a.RA0 - b.RA0).norm(), tol * s.force) << what;
  EXPECT_LT((a.RA3 - b.RA3).norm(), tol * s.force) << what;
  EXPECT_LT((a.Fsh - b.Fsh).norm(), tol * s.force) << what;
  EXPECT_NEAR(a.Msh, b.Msh, tol * s.moment) << what;
  EXPECT_NEAR(a.tau, b.tau, tol * s.moment) << what;
}

TEST(CrossVerification, AllFormulationsAndTheRefereeAgreeOverThePaperExample) {
  const FourBar m = samples::paper_fourbar();
  const Trajectory t = simulate_free(m, {1.0, 0.0, 5.0, 501});
  ASSERT_TRUE(t.ok()) << t.message;
  ASSERT_EQ(t.samples.size(), 501u);
  const Scales s = scales_of(t);
  for (std::size_t i = 0; i < t.samples.size(); ++i) {
    const FourBarState& x = t.samples[i].state;
    const DynamicsSample ref_f = reference::newton_euler_forward(m, x.theta1, x.omega1);
    const DynamicsSample ref_i = reference::newton_euler_inverse(m, x.theta1, x.omega1, x.alpha1);
    for (Formulation f : kFormulations) {
      const std::string what = std::string(to_string(f)) + ", sample " + std::to_string(i);
      const auto fwd = forward_dynamics(m, x.theta1, x.omega1, f);
      const auto inv = inverse_dynamics(m, x.theta1, x.omega1, x.alpha1, f);
      ASSERT_TRUE(fwd.has_value()) << what << ": " << fwd.error().what();
      ASSERT_TRUE(inv.has_value()) << what << ": " << inv.error().what();
      expect_agree(*fwd, ref_f, s, what + " forward");
      expect_agree(*inv, ref_i, s, what + " inverse");
      // in free motion the drive torque that reproduces the motion is zero
      EXPECT_NEAR(inv->tau, 0.0, 1e-10 * s.moment) << what;
    }
  }
}

TEST(CrossVerification, FreeSimulationsByEachFormulationAgree) {
  // mass-matrix and complex-masses integrate the same reduced equation: their right-hand sides
  // differ by round-off, so the runs agree to far below the integrator's tolerance scale.
  // opened-loop integrates its 6-state DAE (projected): a different ODE at the same tolerance,
  // measured to stay within ~2e-8 rad of the reduced runs over 5 s.
  const FourBar m = samples::paper_fourbar();
  const Trajectory a = simulate_free(m, {1.0, 0.0, 5.0, 501});
  SimulateOptions o;
  o.formulation = Formulation::kComplexMasses;
  const Trajectory b = simulate_free(m, {1.0, 0.0, 5.0, 501}, o);
  o.formulation = Formulation::kOpenedLoop;
  const Trajectory c = simulate_free(m, {1.0, 0.0, 5.0, 501}, o);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok()) << a.message << b.message << c.message;
  ASSERT_EQ(c.samples.size(), 501u);
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    EXPECT_NEAR(a.samples[i].state.theta1, b.samples[i].state.theta1, 1e-11) << i;
    EXPECT_NEAR(a.samples[i].state.theta1, c.samples[i].state.theta1, 1e-7) << i;
    EXPECT_NEAR(a.samples[i].state.theta3, c.samples[i].state.theta3, 1e-7) << i;
  }
}

}  // namespace
}  // namespace bd::core
