// Dynamics at one instant: core's mass-matrix formulation against the independent Newton–Euler
// referee (tests/reference/newton_euler.hpp), momentum identities, a parallelogram, purity and the
// assembly error; and the referee itself against power balance and Lagrange's equation.
//
// Tolerances. The referee and the mass-matrix formulation are both exact; only round-off in a
// 9x9 LU solve on one side and the mass-matrix reduction on the other separates them. That
// round-off is ~eps times a modest condition number (measured worst over 2000 random states:
// 1e-14 of the sample's size), so 1e-10 of the size leaves a wide margin while any formula error
// (a wrong sign, lever arm or inertia term) shows at order one. Sizes: forces against
// max(1 N, |RA0|, |RA3|, |Fsh|), moments and torques against that times the longest link,
// accelerations against max(1 rad/s^2, |alpha_k|); never element by element near a zero crossing.
#include "core/fourbar/dynamics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/samples.hpp"
#include "tests/reference/newton_euler.hpp"
#include "tests/support/scales.hpp"

namespace bd::core {
namespace {

using testing::acceleration_scale;
using testing::force_scale;
using testing::longest_link;
using testing::moment_scale;
using testing::other;
using testing::rate_scale;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRel = 1e-10;  // see the file comment

// angles may be reported in different 2pi ranges
double angle_gap(double a, double b) { return std::abs(std::remainder(a - b, kTwoPi)); }

std::string where(const FourBar& m, double theta1, double omega1) {
  return "branch " + std::to_string(static_cast<int>(m.branch)) +
         ", theta1 = " + std::to_string(theta1) + ", omega1 = " + std::to_string(omega1);
}

// every field of `got` against the referee's `ref`
void expect_matches(const FourBar& model, const DynamicsSample& got, const DynamicsSample& ref,
                    const std::string& at) {
  const double F = force_scale(ref);
  const double M = moment_scale(model, ref);
  const double A = acceleration_scale(ref);
  const double W = rate_scale(ref);
  const FourBarState& g = got.state;
  const FourBarState& r = ref.state;
  EXPECT_LT(angle_gap(g.theta1, r.theta1), 1e-12) << at;
  EXPECT_LT(angle_gap(g.theta2, r.theta2), 1e-12) << at;
  EXPECT_LT(angle_gap(g.theta3, r.theta3), 1e-12) << at;
  EXPECT_LT(std::abs(g.omega1 - r.omega1), kRel * W) << at;
  EXPECT_LT(std::abs(g.omega2 - r.omega2), kRel * W) << at;
  EXPECT_LT(std::abs(g.omega3 - r.omega3), kRel * W) << at;
  EXPECT_LT(std::abs(g.alpha1 - r.alpha1), kRel * A)
      << at << ": alpha1 " << g.alpha1 << " vs referee " << r.alpha1;
  EXPECT_LT(std::abs(g.alpha2 - r.alpha2), kRel * A) << at;
  EXPECT_LT(std::abs(g.alpha3 - r.alpha3), kRel * A) << at;
  EXPECT_LT(std::abs(got.tau - ref.tau), kRel * M)
      << at << ": tau " << got.tau << " vs referee " << ref.tau;
  EXPECT_LT((got.RA0 - ref.RA0).norm(), kRel * F)
      << at << ": RA0 " << got.RA0.transpose() << " vs referee " << ref.RA0.transpose();
  EXPECT_LT((got.RA3 - ref.RA3).norm(), kRel * F)
      << at << ": RA3 " << got.RA3.transpose() << " vs referee " << ref.RA3.transpose();
  EXPECT_LT((got.Fsh - ref.Fsh).norm(), kRel * F) << at;
  EXPECT_LT(std::abs(got.Msh - ref.Msh), kRel * M)
      << at << ": Msh " << got.Msh << " vs referee " << ref.Msh;
}

// forward and inverse dynamics of core against the referee at one state
void check_against_referee(const FourBar& model, double theta1, double omega1, double alpha1) {
  const std::string at = where(model, theta1, omega1);
  const auto fwd = forward_dynamics(model, theta1, omega1);
  ASSERT_TRUE(fwd.has_value()) << at << ": " << fwd.error().what();
  expect_matches(model, *fwd, reference::newton_euler_forward(model, theta1, omega1),
                 at + " (forward)");
  EXPECT_EQ(fwd->tau, 0.0) << at;

  const auto inv = inverse_dynamics(model, theta1, omega1, alpha1);
  ASSERT_TRUE(inv.has_value()) << at << ": " << inv.error().what();
  expect_matches(model, *inv, reference::newton_euler_inverse(model, theta1, omega1, alpha1),
                 at + ", alpha1 = " + std::to_string(alpha1) + " (inverse)");
  EXPECT_EQ(inv->state.alpha1, alpha1) << at;
}

// the fixed-seed random states of the comparison tests
struct RandomState {
  double theta1, omega1, alpha1;
};
RandomState random_state(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> angle(0.0, kTwoPi), rate(-5.0, 5.0), acc(-20.0, 20.0);
  const double theta1 = angle(rng);
  const double omega1 = rate(rng);
  return {theta1, omega1, acc(rng)};
}

TEST(Dynamics, MassMatrixMatchesNewtonEulerOnRandomLinkages) {
  std::mt19937_64 rng(20240611);
  int plus = 0, minus = 0;
  for (int i = 0; i < 150; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    (model.branch == Branch::kPlus ? plus : minus)++;
    const RandomState x = random_state(rng);
    check_against_referee(model, x.theta1, x.omega1, x.alpha1);
    // the same linkage on its other branch: a crank-rocker assembles on both
    FourBar mirrored = model;
    mirrored.branch = other(model.branch);
    check_against_referee(mirrored, x.theta1, x.omega1, x.alpha1);
  }
  // the generator itself draws both branches
  EXPECT_GT(plus, 0);
  EXPECT_GT(minus, 0);
}

TEST(Dynamics, MassMatrixMatchesNewtonEulerOnPaperFourBar) {
  for (Branch branch : {Branch::kPlus, Branch::kMinus}) {
    FourBar model = samples::paper_fourbar();
    model.branch = branch;
    for (int i = 0; i < 24; ++i) {
      const double theta1 = kTwoPi * i / 24.0;
      check_against_referee(model, theta1, 2.0, -3.0);
      check_against_referee(model, theta1, -4.5, 11.0);
    }
  }
}

TEST(Dynamics, InverseAtForwardAccelerationNeedsNoTorque) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 120; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const RandomState x = random_state(rng);
    const std::string at = where(model, x.theta1, x.omega1);
    const auto fwd = forward_dynamics(model, x.theta1, x.omega1);
    ASSERT_TRUE(fwd.has_value()) << at << ": " << fwd.error().what();
    const auto inv = inverse_dynamics(model, x.theta1, x.omega1, fwd->state.alpha1);
    ASSERT_TRUE(inv.has_value()) << at << ": " << inv.error().what();
    // tau = 0 against the size of the moments that cancel in it
    EXPECT_LT(std::abs(inv->tau), kRel * moment_scale(model, *fwd)) << at;
    EXPECT_LT((inv->RA0 - fwd->RA0).norm(), kRel * force_scale(*fwd)) << at;
    EXPECT_LT((inv->RA3 - fwd->RA3).norm(), kRel * force_scale(*fwd)) << at;

    // the referee is consistent with itself in the same way
    const DynamicsSample rf = reference::newton_euler_forward(model, x.theta1, x.omega1);
    const DynamicsSample ri =
        reference::newton_euler_inverse(model, x.theta1, x.omega1, rf.state.alpha1);
    EXPECT_LT(std::abs(ri.tau), kRel * moment_scale(model, rf)) << at;
  }
}

// Summing Newton's and Euler's laws over the three links, with the ground's pin forces -RA0
// (at A0) and -RA3 (at A3) and the drive torque as the only external actions besides the loads:
//   Fsh = RA0 + RA3 = Σ (F_k + m_k g) - Σ m_k a_k
//   Msh = A3 x RA3 - tau = Σ [c_k x (F_k + m_k g) + M_k] - Σ [c_k x m_k a_k + I_k alpha_k]
// (moments about A0). The centre-of-mass accelerations here come from core's kinematics, not from
// the dynamics code.
TEST(Dynamics, ShakingForceAndMomentEqualLoadsMinusMomentumRates) {
  std::mt19937_64 rng(99);
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const RandomState x = random_state(rng);
    const std::string at = where(model, x.theta1, x.omega1);
    const auto fwd = forward_dynamics(model, x.theta1, x.omega1);
    const auto inv = inverse_dynamics(model, x.theta1, x.omega1, x.alpha1);
    ASSERT_TRUE(fwd.has_value() && inv.has_value()) << at;
    for (const DynamicsSample* s : {&*fwd, &*inv}) {
      const std::array<double, 3> alpha{s->state.alpha1, s->state.alpha2, s->state.alpha3};
      Vec2 force{0, 0};
      double moment = 0.0;  // tau cancels: it turns the crank and, as -tau, the frame
      double size = 0.0;    // magnitudes of the terms, for the moment tolerance
      for (int k = 1; k <= 3; ++k) {
        const Link& L = link(model, k);
        const LinkLoad& load = link_load(model, k);
        const Vec2 c = centre_of_mass(model, k, pose_of(s->state));
        const Vec2 a = centre_of_mass_acceleration(model, k, s->state);
        const Vec2 applied = load.force + L.mass * model.loads.gravity;
        force += applied - L.mass * a;
        moment += cross(c, applied) + load.moment - cross(c, L.mass * a) - L.inertia * alpha[k - 1];
        size += std::abs(cross(c, applied)) + std::abs(load.moment) +
                std::abs(cross(c, L.mass * a)) + std::abs(L.inertia * alpha[k - 1]);
      }
      const double F = std::max(force_scale(*s), force.norm());
      EXPECT_LT((s->Fsh - force).norm(), kRel * F)
          << at << ": Fsh " << s->Fsh.transpose() << " vs " << force.transpose();
      EXPECT_LT(std::abs(s->Msh - moment), kRel * std::max(moment_scale(model, *s), size))
          << at << ": Msh " << s->Msh << " vs " << moment;
    }
  }
}

TEST(Dynamics, ParallelogramKeepsCouplerAngle) {
  // away from the flat (change-point) positions theta1 = 0, pi; the parallelogram (rather than
  // the antiparallelogram) is branch +1 for theta1 in (0, pi) and branch -1 in (pi, 2 pi)
  for (double theta1 : {0.3, 0.9, 1.5, 2.2, 2.8, 3.5, 4.1, 4.8, 5.4, 6.0}) {
    FourBar model = samples::parallelogram();
    model.branch = theta1 < std::numbers::pi ? Branch::kPlus : Branch::kMinus;
    const std::string at = where(model, theta1, 3.0);
    const auto fwd = forward_dynamics(model, theta1, 3.0);
    const auto inv = inverse_dynamics(model, theta1, 3.0, -7.0);
    ASSERT_TRUE(fwd.has_value() && inv.has_value()) << at;
    for (const DynamicsSample* s : {&*fwd, &*inv}) {
      EXPECT_LT(std::abs(s->state.omega2), 1e-12 * rate_scale(*s)) << at;
      EXPECT_LT(std::abs(s->state.alpha2), 1e-12 * acceleration_scale(*s)) << at;
      // crank and rocker stay parallel
      EXPECT_LT(std::abs(s->state.omega3 - s->state.omega1), 1e-12 * rate_scale(*s)) << at;
    }
    check_against_referee(model, theta1, 3.0, -7.0);
  }
}

bool same_model(const FourBar& a, const FourBar& b) {
  const auto same_link = [](const Link& x, const Link& y) {
    return x.length == y.length && x.mass == y.mass && x.e == y.e && x.f == y.f &&
           x.inertia == y.inertia;
  };
  const auto same_load = [](const LinkLoad& x, const LinkLoad& y) {
    return x.force == y.force && x.moment == y.moment;
  };
  return same_link(a.crank, b.crank) && same_link(a.coupler, b.coupler) &&
         same_link(a.rocker, b.rocker) && a.frame_length == b.frame_length &&
         a.branch == b.branch && a.loads.gravity == b.loads.gravity &&
         same_load(a.loads.crank, b.loads.crank) && same_load(a.loads.coupler, b.loads.coupler) &&
         same_load(a.loads.rocker, b.loads.rocker);
}

bool same_sample(const DynamicsSample& a, const DynamicsSample& b) {
  const FourBarState &x = a.state, &y = b.state;
  return x.theta1 == y.theta1 && x.theta2 == y.theta2 && x.theta3 == y.theta3 &&
         x.omega1 == y.omega1 && x.omega2 == y.omega2 && x.omega3 == y.omega3 &&
         x.alpha1 == y.alpha1 && x.alpha2 == y.alpha2 && x.alpha3 == y.alpha3 && a.RA0 == b.RA0 &&
         a.RA3 == b.RA3 && a.Fsh == b.Fsh && a.Msh == b.Msh && a.tau == b.tau;
}

TEST(Dynamics, CallsArePure) {
  const FourBar model = samples::paper_fourbar();
  const FourBar copy = model;
  const auto first = forward_dynamics(model, 1.0, 2.5);
  const auto second = forward_dynamics(model, 1.0, 2.5);
  ASSERT_TRUE(first.has_value() && second.has_value());
  EXPECT_TRUE(same_sample(*first, *second));
  const auto inv1 = inverse_dynamics(model, 1.0, 2.5, -4.0);
  const auto inv2 = inverse_dynamics(model, 1.0, 2.5, -4.0);
  ASSERT_TRUE(inv1.has_value() && inv2.has_value());
  EXPECT_TRUE(same_sample(*inv1, *inv2));
  EXPECT_TRUE(same_model(model, copy));
}

TEST(Dynamics, UnreachableCrankAngleIsAnError) {
  // non-Grashof (1 + 2.5 > 1.2 + 2): at theta1 = pi, |A1A3| = 4.5 > l2 + l3 = 2.2
  FourBar candidate;
  candidate.crank = {2.5, 1.0, 1.0, 0.1, 0.5};
  candidate.coupler = {1.0, 1.0, 0.5, 0.0, 0.1};
  candidate.rocker = {1.2, 1.0, 0.6, 0.0, 0.1};
  candidate.frame_length = 2.0;
  const FourBar model = make_fourbar(candidate);
  ASSERT_EQ(classify_grashof(model), GrashofClass::kNonGrashof);
  const double theta1 = std::numbers::pi;
  const auto fwd = forward_dynamics(model, theta1, 1.0);
  ASSERT_FALSE(fwd.has_value());
  EXPECT_EQ(fwd.error().kind, DynamicsError::Kind::kAssembly);
  EXPECT_EQ(fwd.error().theta1, theta1);
  EXPECT_NE(fwd.error().what().find("theta1"), std::string::npos) << fwd.error().what();
  const auto inv = inverse_dynamics(model, theta1, 1.0, 2.0);
  ASSERT_FALSE(inv.has_value());
  EXPECT_EQ(inv.error().kind, DynamicsError::Kind::kAssembly);
  EXPECT_NE(inv.error().what().find("theta1"), std::string::npos) << inv.error().what();
  // where it does close, it works
  EXPECT_TRUE(forward_dynamics(model, 0.0, 1.0).has_value());
}

// ---- the referee checked on its own, independently of core's dynamics ----------------------

// dT/dt = Σ m_k v_k·a_k + I_k omega_k alpha_k, from the referee's own centre-of-mass motion
double kinetic_energy_rate(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> omega{s.omega1, s.omega2, s.omega3};
  const std::array<double, 3> alpha{s.alpha1, s.alpha2, s.alpha3};
  double rate = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const Link& L = link(model, k);
    rate += L.mass * m.com[k - 1].v.dot(m.com[k - 1].a) + L.inertia * omega[k - 1] * alpha[k - 1];
  }
  return rate;
}
// power of the loads, the weights and the drive: Σ (F_k + m_k g)·v_k + M_k omega_k + tau omega1
double applied_power(const FourBar& model, const FourBarState& s, double tau) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> omega{s.omega1, s.omega2, s.omega3};
  double power = tau * s.omega1;
  for (int k = 1; k <= 3; ++k) {
    const LinkLoad& load = link_load(model, k);
    power += (load.force + link(model, k).mass * model.loads.gravity).dot(m.com[k - 1].v) +
             load.moment * omega[k - 1];
  }
  return power;
}
// sum of the magnitudes of the terms above, for a relative tolerance
double power_size(const FourBar& model, const FourBarState& s, double tau) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> omega{s.omega1, s.omega2, s.omega3};
  const std::array<double, 3> alpha{s.alpha1, s.alpha2, s.alpha3};
  double size = std::abs(tau * s.omega1);
  for (int k = 1; k <= 3; ++k) {
    const Link& L = link(model, k);
    const LinkLoad& load = link_load(model, k);
    size += std::abs(L.mass * m.com[k - 1].v.dot(m.com[k - 1].a)) +
            std::abs(L.inertia * omega[k - 1] * alpha[k - 1]) +
            std::abs((load.force + L.mass * model.loads.gravity).dot(m.com[k - 1].v)) +
            std::abs(load.moment * omega[k - 1]);
  }
  return size;
}

FourBar without_loads(FourBar model) {
  model.loads = Loads{};
  return model;
}

// Ideal pins do no work in a motion the joints allow, so Newton–Euler implies
// dT/dt = applied power. This checks the referee's pin-force directions, lever arms and signs
// (a wrong one leaves a pin force doing work); the acceleration kinematics are checked below.
TEST(NewtonEulerReferee, PowerBalance) {
  std::mt19937_64 rng(4242);
  for (int i = 0; i < 100; ++i) {
    const FourBar loaded = samples::random_crank_rocker(rng);
    const RandomState x = random_state(rng);
    const std::string at = where(loaded, x.theta1, x.omega1);
    // free motion without loads: kinetic energy is constant
    const FourBar free_model = without_loads(loaded);
    const DynamicsSample f0 = reference::newton_euler_forward(free_model, x.theta1, x.omega1);
    EXPECT_LT(std::abs(kinetic_energy_rate(free_model, f0.state)),
              kRel * power_size(free_model, f0.state, 0.0))
        << at;
    // free motion under loads and gravity
    const DynamicsSample f1 = reference::newton_euler_forward(loaded, x.theta1, x.omega1);
    EXPECT_LT(std::abs(kinetic_energy_rate(loaded, f1.state) - applied_power(loaded, f1.state, 0)),
              kRel * power_size(loaded, f1.state, 0.0))
        << at;
    // driven: the drive's power joins in
    const DynamicsSample d = reference::newton_euler_inverse(loaded, x.theta1, x.omega1, x.alpha1);
    EXPECT_LT(
        std::abs(kinetic_energy_rate(loaded, d.state) - applied_power(loaded, d.state, d.tau)),
        kRel * power_size(loaded, d.state, d.tau))
        << at;
  }
}

// The referee's state is consistent: the chain A0 -> A1 -> A2 -> A3 ends at rest at (l4, 0), and
// its centre-of-mass accelerations equal d/dt of its velocities, by central differences in theta1:
// v_k = J_k(theta1) omega1, so a_k = J_k alpha1 + dJ_k/dtheta1 omega1^2.
// h = 1e-5 rad: truncation ~h^2 = 1e-10, round-off ~eps/h = 2e-11, relative to the size.
TEST(NewtonEulerReferee, KinematicsConsistent) {
  std::mt19937_64 rng(31);
  const double h = 1e-5;
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const RandomState x = random_state(rng);
    const std::string at = where(model, x.theta1, x.omega1);
    const DynamicsSample s = reference::newton_euler_inverse(model, x.theta1, x.omega1, x.alpha1);
    const reference::LinkageMotion m = reference::linkage_motion(model, s.state);
    const double L = longest_link(model);
    const double vs = L * rate_scale(s);
    const double as = L * std::max(acceleration_scale(s), rate_scale(s) * rate_scale(s));
    EXPECT_LT((m.A3.p - Vec2(model.frame_length, 0.0)).norm(), 1e-12 * L) << at;
    EXPECT_LT(m.A3.v.norm(), 1e-12 * vs) << at;
    EXPECT_LT(m.A3.a.norm(), 1e-12 * as) << at;

    // J_k at theta1 +- h from unit-rate states
    const auto unit_rate = [&](double theta1) {
      FourBarState u = reference::newton_euler_forward(model, theta1, 1.0).state;
      u.alpha1 = u.alpha2 = u.alpha3 = 0.0;
      return reference::linkage_motion(model, u);
    };
    const reference::LinkageMotion up = unit_rate(x.theta1 + h);
    const reference::LinkageMotion down = unit_rate(x.theta1 - h);
    const reference::LinkageMotion here = unit_rate(x.theta1);
    for (int k = 0; k < 3; ++k) {
      // velocities: J_k = dc_k/dtheta1
      const Vec2 J_fd = (up.com[k].p - down.com[k].p) / (2 * h);
      EXPECT_LT((here.com[k].v - J_fd).norm(), 1e-7 * L) << at << ", link " << k + 1;
      // accelerations
      const Vec2 dJ = (up.com[k].v - down.com[k].v) / (2 * h);
      const Vec2 a_fd = here.com[k].v * x.alpha1 + dJ * x.omega1 * x.omega1;
      EXPECT_LT((m.com[k].a - a_fd).norm(), 1e-7 * as) << at << ", link " << k + 1;
    }
  }
}

// Lagrange's equation for the one-degree-of-freedom mechanism, built from velocities only:
//   T = ½ mu(theta1) omega1^2,  mu = Σ m_k |J_k|^2 + I_k Theta_k^2,
//   mu alpha1 + ½ mu' omega1^2 = Q = Σ (F_k + m_k g)·J_k + M_k Theta_k   (+ tau),
// with mu' by central differences (h = 1e-5: truncation ~h^2 = 1e-10, round-off ~eps/h = 2e-11,
// relative). A route to alpha1 and tau that shares no acceleration formula with the referee.
TEST(NewtonEulerReferee, MatchesLagrangeEquation) {
  std::mt19937_64 rng(555);
  const double h = 1e-5;
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const RandomState x = random_state(rng);
    const std::string at = where(model, x.theta1, x.omega1);
    // reduced inertia mu [kg m^2] and generalised force Q [N m]: kinetic energy and applied
    // power at unit crank rate
    const auto mu_and_Q = [&](double theta1) {
      FourBarState u = reference::newton_euler_forward(model, theta1, 1.0).state;
      u.alpha1 = u.alpha2 = u.alpha3 = 0.0;
      const reference::LinkageMotion m = reference::linkage_motion(model, u);
      const std::array<double, 3> dtheta_dtheta1{u.omega1, u.omega2, u.omega3};
      double mu = 0.0;
      for (int k = 1; k <= 3; ++k) {
        const Link& L = link(model, k);
        mu += L.mass * m.com[k - 1].v.squaredNorm() +
              L.inertia * dtheta_dtheta1[k - 1] * dtheta_dtheta1[k - 1];
      }
      return std::array<double, 2>{mu, applied_power(model, u, 0.0)};
    };
    const auto [mu, Q] = mu_and_Q(x.theta1);
    const double dmu = (mu_and_Q(x.theta1 + h)[0] - mu_and_Q(x.theta1 - h)[0]) / (2 * h);
    const double bias = 0.5 * dmu * x.omega1 * x.omega1;
    const double size = std::abs(Q) + std::abs(bias) + mu * std::abs(x.alpha1);

    const DynamicsSample fwd = reference::newton_euler_forward(model, x.theta1, x.omega1);
    EXPECT_LT(std::abs(mu * fwd.state.alpha1 + bias - Q), 1e-7 * size)
        << at << ": alpha1 " << fwd.state.alpha1 << " vs Lagrange " << (Q - bias) / mu;
    const DynamicsSample inv = reference::newton_euler_inverse(model, x.theta1, x.omega1, x.alpha1);
    EXPECT_LT(std::abs(inv.tau - (mu * x.alpha1 + bias - Q)), 1e-7 * size)
        << at << ": tau " << inv.tau << " vs Lagrange " << mu * x.alpha1 + bias - Q;
  }
}

}  // namespace
}  // namespace bd::core
