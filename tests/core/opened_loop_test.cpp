// The opened-loop formulation (paper §3, eqs. 12-28) against the independent Newton–Euler referee
// and against the mass-matrix formulation; the structure of its matrices (eqs. 22-24); its
// dependent accelerations against the closed-loop kinematics; the state form used by the DAE.
//
// Tolerances. All three solutions are exact; only round-off separates them: a 5x5 LU here, a
// 9x9 LU in the referee, the mass-matrix reduction there. The 5x5 system [M D; Dᵀ 0] is a
// saddle-point matrix whose condition grows like 1/sin² of the transmission angle; the random
// crank-rockers keep it away from 0 and pi (samples.hpp), so round-off stays ~1e-14 of the
// sample's size (measured worst 9.4e-15 over the states below). 1e-10 of the size leaves four
// orders of margin while any formula error (a sign, a lever arm, a missing mass) shows at order
// one. Sizes as in dynamics_test.cpp: forces against max(1 N, |RA0|, |RA3|, |Fsh|), moments
// against that times the longest link, accelerations against max(1 rad/s², |alpha_k|).
#include "core/fourbar/opened_loop.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/fourbar/samples.hpp"
#include "tests/reference/newton_euler.hpp"
#include "tests/support/scales.hpp"
#include "tests/support/allocation_counter.hpp"


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

double angle_gap(double a, double b) { return std::abs(std::remainder(a - b, kTwoPi)); }
std::string scientific(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// largest relative deviation of `got` from `ref` over all outputs (see the file comment)
struct Deviation {
  double value{};
  std::string what;
};
Deviation deviation(const FourBar& model, const DynamicsSample& got, const DynamicsSample& ref) {
  const double F = force_scale(ref), M = moment_scale(model, ref), A = acceleration_scale(ref);
  Deviation d;
  auto take = [&d](double v, const char* name) {
    if (!(v <= d.value)) {
      d.value = v;
      d.what = name;
    }
  };
  const FourBarState &g = got.state, &r = ref.state;
  take(angle_gap(g.theta2, r.theta2) / 1e-2, "theta2");  // angles: same closed form, ~1e-16
  take(angle_gap(g.theta3, r.theta3) / 1e-2, "theta3");
  take(std::abs(g.alpha1 - r.alpha1) / A, "alpha1");
  take(std::abs(g.alpha2 - r.alpha2) / A, "alpha2");
  take(std::abs(g.alpha3 - r.alpha3) / A, "alpha3");
  take((got.RA0 - ref.RA0).norm() / F, "RA0");
  take((got.RA3 - ref.RA3).norm() / F, "RA3");
  take((got.Fsh - ref.Fsh).norm() / F, "Fsh");
  take(std::abs(got.Msh - ref.Msh) / M, "Msh");
  take(std::abs(got.tau - ref.tau) / M, "tau");
  return d;
}

std::string where(const FourBar& m, double theta1, double omega1, double alpha1) {
  return "branch " + std::to_string(static_cast<int>(m.branch)) +
         ", theta1 = " + std::to_string(theta1) + ", omega1 = " + std::to_string(omega1) +
         ", alpha1 = " + std::to_string(alpha1);
}

// forward and inverse opened-loop dynamics against the referee and the mass-matrix formulation;
// returns the worst relative deviation seen
double check_state(const FourBar& model, double theta1, double omega1, double alpha1) {
  const std::string at = where(model, theta1, omega1, alpha1);
  double worst = 0;
  const auto fwd = forward_dynamics_opened_loop(model, theta1, omega1);
  EXPECT_TRUE(fwd.has_value()) << at << ": " << fwd.error().what();
  if (!fwd) return 1.0;
  EXPECT_EQ(fwd->tau, 0.0) << at;
  const auto inv = inverse_dynamics_opened_loop(model, theta1, omega1, alpha1);
  EXPECT_TRUE(inv.has_value()) << at << ": " << inv.error().what();
  if (!inv) return 1.0;
  EXPECT_EQ(inv->state.alpha1, alpha1) << at;

  const DynamicsSample refs[4] = {reference::newton_euler_forward(model, theta1, omega1),
                                  *forward_dynamics(model, theta1, omega1),
                                  reference::newton_euler_inverse(model, theta1, omega1, alpha1),
                                  *inverse_dynamics(model, theta1, omega1, alpha1)};
  const char* names[4] = {"forward vs referee", "forward vs mass matrix", "inverse vs referee",
                          "inverse vs mass matrix"};
  for (int i = 0; i < 4; ++i) {
    const Deviation d = deviation(model, i < 2 ? *fwd : *inv, refs[i]);
    EXPECT_LT(d.value, kRel) << at << ": " << names[i] << ", worst " << d.what;
    worst = std::max(worst, d.value);
  }
  return worst;
}

TEST(OpenedLoop, MatchesRefereeAndMassMatrixOnRandomLinkages) {
  std::mt19937_64 rng(314159);
  std::uniform_real_distribution<double> angle(0.0, kTwoPi), rate(-5.0, 5.0), acc(-20.0, 20.0);
  int plus = 0, minus = 0;
  double worst = 0;
  for (int i = 0; i < 150; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    (model.branch == Branch::kPlus ? plus : minus)++;
    const double theta1 = angle(rng), omega1 = rate(rng), alpha1 = acc(rng);
    worst = std::max(worst, check_state(model, theta1, omega1, alpha1));
    FourBar mirrored = model;  // a crank-rocker assembles on both branches
    mirrored.branch = other(model.branch);
    worst = std::max(worst, check_state(mirrored, theta1, omega1, alpha1));
  }
  EXPECT_GT(plus, 0);
  EXPECT_GT(minus, 0);
  RecordProperty("worst_relative_deviation", scientific(worst));
}

TEST(OpenedLoop, MatchesRefereeAndMassMatrixOnPaperFourBarOverARevolution) {
  double worst = 0;
  for (Branch branch : {Branch::kPlus, Branch::kMinus}) {
    FourBar model = samples::paper_fourbar();
    model.branch = branch;
    for (int i = 0; i < 72; ++i) {
      const double theta1 = kTwoPi * i / 72.0;
      worst = std::max(worst, check_state(model, theta1, 2.0, -3.0));
      worst = std::max(worst, check_state(model, theta1, -4.5, 11.0));
      worst = std::max(worst, check_state(model, theta1, 0.0, 0.0));
    }
  }
  // with gravity as well (the paper example has none)
  FourBar heavy = samples::paper_fourbar();
  heavy.loads.gravity = Vec2(0.0, -9.81);
  for (int i = 0; i < 36; ++i) {
    worst = std::max(worst, check_state(heavy, kTwoPi * i / 36.0, 1.3, 0.7));
  }
  RecordProperty("worst_relative_deviation", scientific(worst));
}

TEST(OpenedLoop, DependentAccelerationsFromTheSolveFollowTheKinematics) {
  // θ̈2, θ̈3 come out of the 5x5 solve; the closed loop requires α_k = Θ_k α1 + γ_k
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> angle(0.0, kTwoPi), rate(-5.0, 5.0), acc(-20.0, 20.0);
  for (int i = 0; i < 200; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const double theta1 = angle(rng), omega1 = rate(rng);
    for (const auto& sample : {forward_dynamics_opened_loop(model, theta1, omega1),
                               inverse_dynamics_opened_loop(model, theta1, omega1, acc(rng))}) {
      ASSERT_TRUE(sample.has_value());
      const FourBarState& s = sample->state;
      const FourBarState k =
          solve_acceleration(model, solve_velocity(model, pose_of(s), omega1), s.alpha1);
      const double scale = acceleration_scale(*sample);
      EXPECT_LT(std::abs(s.alpha2 - k.alpha2), kRel * scale) << "linkage " << i;
      EXPECT_LT(std::abs(s.alpha3 - k.alpha3), kRel * scale) << "linkage " << i;
    }
  }
}

// kinetic energy of the opened chain A0 -> A1 -> A2 (free end A3), link by link (König), for
// independent link rates
double open_chain_kinetic_energy(const FourBar& m, const Pose& p, const Eigen::Vector3d& w) {
  const Vec2 l1 = m.crank.length * unit(p.theta1), l2 = m.coupler.length * unit(p.theta2);
  const double th[3] = {p.theta1, p.theta2, p.theta3};
  const Vec2 v_joint[3] = {Vec2::Zero(), w(0) * perp(l1), w(0) * perp(l1) + w(1) * perp(l2)};
  double T = 0;
  for (int k = 0; k < 3; ++k) {
    const Link& L = link(m, k + 1);
    const Vec2 rho = L.e * unit(th[k]) + L.f * perp(unit(th[k]));
    const Vec2 v = v_joint[k] + w(k) * perp(rho);
    T += 0.5 * L.mass * v.squaredNorm() + 0.5 * L.inertia * w(k) * w(k);
  }
  return T;
}

TEST(OpenedLoop, MassMatrixIsTheOpenChainInertiaAndItsFormsAgree) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(-10.0, 10.0), rate(-3.0, 3.0);
  auto sq = [](double v) { return v * v; };
  for (int i = 0; i < 200; ++i) {
    const FourBar m = samples::random_crank_rocker(rng);
    // independent angles: the terms do not need a closed loop
    const Pose p{angle(rng), angle(rng), angle(rng)};
    const OpenedLoopTerms t = opened_loop_terms(m, p);
    const double scale = t.M.norm();

    // symmetric positive definite
    EXPECT_LT((t.M - t.M.transpose()).norm(), 1e-15 * scale);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(t.M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "linkage " << i;

    // ½ θ̇ᵀ M θ̇ is the open chain's kinetic energy for every rate vector
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d w(rate(rng), rate(rng), rate(rng));
      const double T = open_chain_kinetic_energy(m, p, w);
      EXPECT_NEAR(0.5 * w.dot(t.M * w), T, 1e-13 * std::max(1.0, T)) << "linkage " << i;
    }

    // the principal-vector forms of the diagonal (they divide by m1, m2, m3) equal the simple ones
    const OpenedLoopVectors a = opened_loop_vectors(m, p);
    const double m1 = m.crank.mass, m2 = m.coupler.mass, m3 = m.rocker.mass, mt = m1 + m2 + m3;
    const double M11 = m.crank.inertia + m1 * a.a14p.squaredNorm() +
                       2 * (m2 + m3) * a.a14p.dot(a.a12) + sq(m2 + m3) / m1 * a.a12.squaredNorm() +
                       (m2 + m3) * sq(m.crank.length);
    const double M22 = m.coupler.inertia + sq(m1 + m2) / m2 * a.a21.squaredNorm() +
                       2 * (m1 + m2) * m3 / m2 * a.a21.dot(a.a23) +
                       sq(m3) / m2 * a.a23.squaredNorm() + m3 * sq(m.coupler.length);
    const double M33 = m.rocker.inertia + sq(mt) / m3 * a.a32.squaredNorm();
    EXPECT_NEAR(t.M(0, 0), M11, 1e-13 * scale);
    EXPECT_NEAR(t.M(1, 1), M22, 1e-13 * scale);
    EXPECT_NEAR(t.M(2, 2), M33, 1e-13 * scale);

    // C is skew-symmetric (eq. 23)
    EXPECT_LT((t.C + t.C.transpose()).norm(), 1e-15 * scale);
    EXPECT_EQ(t.C.diagonal().norm(), 0.0);
    // and is the convective part of the open chain's inertia: C_jk = ∂M_jk/∂θ_k (Christoffel
    // symbols of a matrix whose entry jk depends on θ_j - θ_k only); central differences,
    // h = 1e-6: truncation ~h², round-off ~eps/h relative
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Pose pp = p, pm = p;
      (k == 0 ? pp.theta1 : k == 1 ? pp.theta2 : pp.theta3) += h;
      (k == 0 ? pm.theta1 : k == 1 ? pm.theta2 : pm.theta3) -= h;
      const Eigen::Matrix3d dM =
          (opened_loop_terms(m, pp).M - opened_loop_terms(m, pm).M) / (2 * h);
      for (int j = 0; j < 3; ++j) {
        if (j != k) {
          EXPECT_NEAR(t.C(j, k), dM(j, k), 1e-8 * scale) << "j " << j << " k " << k;
        }
      }
    }

    // D_j = ∂r̄A3/∂θ_j (eqs. 20, 24)
    EXPECT_NEAR(t.D(0, 0), -m.crank.length * std::sin(p.theta1), 1e-15 * m.crank.length);
    EXPECT_NEAR(t.D(2, 1), m.rocker.length * std::cos(p.theta3), 1e-15 * m.rocker.length);
  }
}

TEST(OpenedLoop, GeneralisedForcesAreMinusTheLoadPotentialGradient) {
  // Q_j of eq. 25 (tau = 0) is the virtual work of the loads per δθ_j on the open chain:
  // Q_j = -∂V/∂θ_j with V = -Σ (F̄k + m_k ḡ)·r̄_k - Σ M_k θ_k, r̄_k along the chain from A0
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  for (int i = 0; i < 100; ++i) {
    const FourBar m = samples::random_crank_rocker(rng);
    auto V = [&m](const Eigen::Vector3d& th) {
      const Vec2 A1 = m.crank.length * unit(th(0)), A2 = A1 + m.coupler.length * unit(th(1));
      const Vec2 first[3] = {Vec2::Zero(), A1, A2};
      double v = 0;
      for (int k = 0; k < 3; ++k) {
        const Link& L = link(m, k + 1);
        const Vec2 r = first[k] + L.e * unit(th(k)) + L.f * perp(unit(th(k)));
        const LinkLoad& load = link_load(m, k + 1);
        v -= (load.force + L.mass * m.loads.gravity).dot(r) + load.moment * th(k);
      }
      return v;
    };
    const Eigen::Vector3d th(angle(rng), angle(rng), angle(rng));
    const OpenedLoopTerms t = opened_loop_terms(m, {th(0), th(1), th(2)});
    const double h = 1e-5;  // central differences: truncation ~h², round-off ~eps/h
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d e = Eigen::Vector3d::Zero();
      e(j) = h;
      const double dV = (V(th + e) - V(th - e)) / (2 * h);
      EXPECT_NEAR(t.Q(j), -dV, 1e-7 * std::max(1.0, t.Q.norm())) << "linkage " << i << " j " << j;
    }
  }
}

TEST(OpenedLoop, StateFormAgreesOnAClosedStateAndStaysRegularAtALimitPosition) {
  const FourBar model = samples::paper_fourbar();
  const auto a = forward_dynamics_opened_loop(model, 0.8, 1.7);
  ASSERT_TRUE(a.has_value());
  FourBarState s = a->state;
  const auto b = forward_dynamics_opened_loop(model, s);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->state.alpha1, a->state.alpha1);
  EXPECT_EQ(b->RA0, a->RA0);
  EXPECT_EQ(b->RA3, a->RA3);

  // triple rocker at its limit position: coupler and rocker aligned. The reduced formulation
  // fails there (kSingular); the opened loop's 5x5 stays regular, with finite accelerations.
  const FourBar rocker = samples::triple_rocker();
  const double l4 = rocker.frame_length, l1 = rocker.crank.length;
  const double l23 = rocker.coupler.length + rocker.rocker.length;
  const double limit = std::acos((l1 * l1 + l4 * l4 - l23 * l23) / (2 * l1 * l4));
  EXPECT_FALSE(forward_dynamics(rocker, limit, 0.0).has_value());
  const Vec2 A1 = l1 * unit(limit), A3(l4, 0.0);
  const double theta23 = std::atan2((A3 - A1).y(), (A3 - A1).x());
  FourBarState at_limit;
  at_limit.theta1 = limit;
  at_limit.theta2 = at_limit.theta3 = theta23;
  at_limit.omega2 = 0.9;  // at the limit the crank is at rest; coupler and rocker turn
  at_limit.omega3 = -0.9 * rocker.coupler.length / rocker.rocker.length;
  const auto c = forward_dynamics_opened_loop(rocker, at_limit);
  ASSERT_TRUE(c.has_value()) << c.error().what();
  EXPECT_TRUE(std::isfinite(c->state.alpha1) && c->RA3.allFinite());
  // the accelerations satisfy eq. 27 to round-off
  const Vec2 l1v = l1 * unit(limit), l2v = rocker.coupler.length * unit(theta23),
             l3v = rocker.rocker.length * unit(theta23);
  const FourBarState& x = c->state;
  const Vec2 residual = x.alpha1 * perp(l1v) - x.omega1 * x.omega1 * l1v + x.alpha2 * perp(l2v) -
                        x.omega2 * x.omega2 * l2v + x.alpha3 * perp(l3v) -
                        x.omega3 * x.omega3 * l3v;
  EXPECT_LT(residual.norm(), 1e-12 * (1 + std::abs(x.alpha1) + std::abs(x.alpha2)));

  // all three links parallel: singular
  FourBarState flat;
  flat.theta1 = flat.theta2 = 0.0;
  flat.theta3 = std::numbers::pi;
  const auto d = forward_dynamics_opened_loop(rocker, flat);
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error().kind, DynamicsError::Kind::kSingular);
}

TEST(OpenedLoop, UnreachableAndDeadCentreAnglesAreErrors) {
  const FourBar rocker = samples::triple_rocker();
  const auto far = forward_dynamics_opened_loop(rocker, 2.5, 0.0);
  ASSERT_FALSE(far.has_value());
  EXPECT_EQ(far.error().kind, DynamicsError::Kind::kAssembly);
  const auto inv = inverse_dynamics_opened_loop(rocker, -2.5, 0.0, 1.0);
  ASSERT_FALSE(inv.has_value());
  EXPECT_EQ(inv.error().kind, DynamicsError::Kind::kAssembly);
}

TEST(OpenedLoop, OneInstantAllocatesNothing) {
  const FourBar m = samples::paper_fourbar();
  double sink = 0;
  const long before = testing::allocations();
  for (int i = 0; i < 360; ++i) {
    const double theta1 = kTwoPi * i / 360;
    const auto f = forward_dynamics_opened_loop(m, theta1, 2.0);
    const auto g = inverse_dynamics_opened_loop(m, theta1, 2.0, 0.5);
    const auto h = forward_dynamics_opened_loop(m, f->state, Vec2(1e-3, -2e-3));
    sink += f->state.alpha1 + g->tau + h->state.alpha2;
  }
  EXPECT_EQ(testing::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace bd::core
