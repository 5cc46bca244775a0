// Counter-rotating inertias (FourBar::counter_rotations): discs on frame shafts geared to the
// crank (pivot A0) and the rocker (pivot A3) with ratio -1 (core/fourbar/model.hpp).
//
// (a) the Newton–Euler referee with discs obeys the power balance dT/dt = applied power, with
//     T including ½ J_k ω_k², and core's kinetic_energy() holds that term;
// (b) its shaking force and moment are the rates of change of the momenta (derived below) — at
//     random instants analytically and along a driven motion by central differences in time;
// (c) core's forward and inverse dynamics, every formulation, agree with the referee on random
//     linkages with random discs, both branches;
// (d) discs with J = 0 change nothing, bit for bit, and give RC1 = RC3 = 0.
//
// Momentum identities. The system is the three links plus the discs. External to it: the pin
// forces from the ground P0 = -RA0 at A0 and P3 = -RA3 at A3, the shaft bearing forces
// B_k = -RCk at the shafts C_k, the drive torque tau on the crank, and the loads F_k + m_k g at
// the centres of mass c_k and moments M_k. A disc never translates, so the linear momentum is
// p = Σ m_k v_k and
//     dp/dt = -RA0 - RA3 - RC1 - RC3 + Σ (F_k + m_k g)  =>  Fsh = Σ (F_k + m_k g) - dp/dt.
// A disc spins at -ω_k about its fixed shaft: its angular momentum about A0 is -J_k ω_k. With
//     H = Σ [c_k × m_k v_k + I_k ω_k] - J_1 ω_1 - J_3 ω_3          (about the fixed point A0)
//     dH/dt = A3 × (-RA3) + C1 × (-RC1) + C3 × (-RC3) + tau + Σ [c_k × (F_k + m_k g) + M_k]
// and with Msh = A3 × RA3 - tau + C1 × RC1 + C3 × RC3 (core/fourbar/dynamics.hpp):
//     Msh = Σ [c_k × (F_k + m_k g) + M_k] - dH/dt.
// Power: pins and shafts are fixed points and the ideal mesh's forces on link and disc do equal
// and opposite work (same velocity at the mesh point), so dT/dt = Σ (F_k + m_k g)·v_k + M_k ω_k
// + tau ω_1.
//
// Tolerances. Instantaneous identities and the formulation comparison are exact up to round-off
// of small LU solves (~1e-14 of the sample's size), checked at 1e-10 of the size as in
// dynamics_test.cpp (forces against max(1 N, all reaction magnitudes), moments against that times
// the longest lever — links and shaft positions —, accelerations against max(1 rad/s², |α_k|)).
// Derivatives in time by the fourth-order central difference with h = 1e-4 s: truncation
// h⁴/30·|x⁽⁵⁾| and round-off ~eps·|x|/h ~ 2e-12·|x|, against a rate ~ ω|x|. (The second-order
// difference at h = 1e-5 s was measured too coarse for the kinetic energy: its truncation reached
// 1.4e-8 of the scale on a random linkage.) 1e-8 of the scale leaves a wide margin while a
// missing disc term (order J ω α) shows at order one.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/energy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/samples.hpp"
#include "tests/reference/newton_euler.hpp"

namespace bd::core {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRel = 1e-10;  // exact identities, see the file comment
constexpr double kFd = 1e-8;    // central differences in time, see the file comment

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

// A shaft position within 3 m of the origin on each axis and at least 0.2 m from the pivot.
Vec2 random_shaft(std::mt19937_64& rng, const Vec2& pivot) {
  for (;;) {
    const Vec2 at(uniform(rng, -3, 3), uniform(rng, -3, 3));
    if ((at - pivot).norm() >= 0.2) return at;
  }
}

// The model with random discs, J in [0.1, 3] kg m²: `which` 0 both, 1 crank only, 2 rocker only.
FourBar with_random_discs(FourBar m, std::mt19937_64& rng, int which = 0) {
  m.counter_rotations = {};
  if (which != 2) {
    m.counter_rotations.crank.inertia = uniform(rng, 0.1, 3.0);
    m.counter_rotations.crank.at = random_shaft(rng, Vec2(0, 0));
  }
  if (which != 1) {
    m.counter_rotations.rocker.inertia = uniform(rng, 0.1, 3.0);
    m.counter_rotations.rocker.at = random_shaft(rng, Vec2(m.frame_length, 0));
  }
  return make_fourbar(m);
}

FourBar random_model_with_discs(std::mt19937_64& rng, int i) {
  // mostly both discs; every fourth model has only the crank's, every fourth only the rocker's
  const int which = i % 4 == 1 ? 1 : i % 4 == 3 ? 2 : 0;
  return with_random_discs(samples::random_crank_rocker(rng), rng, which);
}

Branch other(Branch b) { return b == Branch::kPlus ? Branch::kMinus : Branch::kPlus; }

struct RandomState {
  double theta1{}, omega1{}, alpha1{};
};
RandomState random_state(std::mt19937_64& rng) {
  return {uniform(rng, 0, kTwoPi), uniform(rng, -3, 3), uniform(rng, -5, 5)};
}

std::string where(const FourBar& m, double theta1, double omega1) {
  return "branch " + std::to_string(static_cast<int>(m.branch)) +
         ", theta1 = " + std::to_string(theta1) + ", omega1 = " + std::to_string(omega1) +
         ", J1 = " + std::to_string(m.counter_rotations.crank.inertia) +
         ", J3 = " + std::to_string(m.counter_rotations.rocker.inertia);
}

// ---- sizes ---------------------------------------------------------------------------------

double longest_lever(const FourBar& m) {
  return std::max({1.0, m.crank.length, m.coupler.length, m.rocker.length, m.frame_length,
                   m.counter_rotations.crank.at.norm(), m.counter_rotations.rocker.at.norm()});
}
double force_scale(const DynamicsSample& s) {
  return std::max({1.0, s.RA0.norm(), s.RA3.norm(), s.RC1.norm(), s.RC3.norm(), s.Fsh.norm()});
}
double moment_scale(const FourBar& m, const DynamicsSample& s) {
  return std::max({force_scale(s) * longest_lever(m), std::abs(s.tau), std::abs(s.Msh)});
}
double acceleration_scale(const DynamicsSample& s) {
  return std::max(
      {1.0, std::abs(s.state.alpha1), std::abs(s.state.alpha2), std::abs(s.state.alpha3)});
}

// ---- momenta and power, from the referee's own point motion --------------------------------

std::array<double, 3> rates(const FourBarState& s) { return {s.omega1, s.omega2, s.omega3}; }
std::array<double, 3> accelerations(const FourBarState& s) {
  return {s.alpha1, s.alpha2, s.alpha3};
}
// total applied force on link k: F_k + m_k g
Vec2 applied_force(const FourBar& model, int k) {
  return link_load(model, k).force + link(model, k).mass * model.loads.gravity;
}

// p = Σ m_k v_k
Vec2 linear_momentum_of(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  Vec2 p = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) p += link(model, k).mass * m.com[k - 1].v;
  return p;
}
// H about A0 = Σ [c_k × m_k v_k + I_k ω_k] - J_1 ω_1 - J_3 ω_3
double angular_momentum_about_A0(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> w = rates(s);
  double H = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const Link& L = link(model, k);
    H += cross(m.com[k - 1].p, L.mass * m.com[k - 1].v) + L.inertia * w[k - 1];
  }
  return H - model.counter_rotations.crank.inertia * s.omega1 -
         model.counter_rotations.rocker.inertia * s.omega3;
}
// dp/dt = Σ m_k a_k
Vec2 linear_momentum_rate(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  Vec2 r = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) r += link(model, k).mass * m.com[k - 1].a;
  return r;
}
// dH/dt = Σ [c_k × m_k a_k + I_k α_k] - J_1 α_1 - J_3 α_3 (v_k × v_k = 0)
double angular_momentum_rate(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> a = accelerations(s);
  double r = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const Link& L = link(model, k);
    r += cross(m.com[k - 1].p, L.mass * m.com[k - 1].a) + L.inertia * a[k - 1];
  }
  return r - model.counter_rotations.crank.inertia * s.alpha1 -
         model.counter_rotations.rocker.inertia * s.alpha3;
}
// Σ (F_k + m_k g) and Σ [c_k × (F_k + m_k g) + M_k] about A0
Vec2 total_applied_force(const FourBar& model) {
  Vec2 F = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) F += applied_force(model, k);
  return F;
}
double applied_moment_about_A0(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  double M = 0.0;
  for (int k = 1; k <= 3; ++k)
    M += cross(m.com[k - 1].p, applied_force(model, k)) + link_load(model, k).moment;
  return M;
}

// dT/dt = Σ m_k v_k·a_k + I_k ω_k α_k + J_1 ω_1 α_1 + J_3 ω_3 α_3 (disc: (-ω)(-α) = ω α), and the
// sum of the terms' magnitudes
struct Rate {
  double value{}, size{};
};
Rate kinetic_energy_rate(const FourBar& model, const FourBarState& s) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> w = rates(s);
  const std::array<double, 3> a = accelerations(s);
  Rate r;
  auto add = [&r](double term) {
    r.value += term;
    r.size += std::abs(term);
  };
  for (int k = 1; k <= 3; ++k) {
    const Link& L = link(model, k);
    add(L.mass * m.com[k - 1].v.dot(m.com[k - 1].a));
    add(L.inertia * w[k - 1] * a[k - 1]);
  }
  add(model.counter_rotations.crank.inertia * s.omega1 * s.alpha1);
  add(model.counter_rotations.rocker.inertia * s.omega3 * s.alpha3);
  return r;
}
// Σ (F_k + m_k g)·v_k + M_k ω_k + tau ω_1
Rate applied_power(const FourBar& model, const FourBarState& s, double tau) {
  const reference::LinkageMotion m = reference::linkage_motion(model, s);
  const std::array<double, 3> w = rates(s);
  Rate r;
  auto add = [&r](double term) {
    r.value += term;
    r.size += std::abs(term);
  };
  add(tau * s.omega1);
  for (int k = 1; k <= 3; ++k) {
    add(applied_force(model, k).dot(m.com[k - 1].v));
    add(link_load(model, k).moment * w[k - 1]);
  }
  return r;
}

FourBar without_loads(FourBar model) {
  model.loads = Loads{};
  return model;
}

// ---- (a) energy ----------------------------------------------------------------------------

TEST(CounterRotation, KineticEnergyHoldsTheDiscs) {
  std::mt19937_64 rng(101);
  for (int i = 0; i < 20; ++i) {
    const FourBar m = random_model_with_discs(rng, i);
    FourBar bare = m;
    bare.counter_rotations = {};
    const RandomState x = random_state(rng);
    const auto pose = solve_position(m, x.theta1);
    ASSERT_TRUE(pose.has_value());
    const FourBarState s = solve_velocity(m, *pose, x.omega1);
    const double discs = 0.5 * m.counter_rotations.crank.inertia * s.omega1 * s.omega1 +
                         0.5 * m.counter_rotations.rocker.inertia * s.omega3 * s.omega3;
    const double T = kinetic_energy(m, s);
    EXPECT_NEAR(T, kinetic_energy(bare, s) + discs, 1e-14 * T) << where(m, x.theta1, x.omega1);
    EXPECT_GT(discs, 0.0);
  }
}

// Ideal pins, shafts and mesh do no net work, so Newton–Euler with discs implies dT/dt = applied
// power. A wrong mesh direction, lever arm or disc sign leaves a force doing work.
TEST(CounterRotation, RefereePowerBalance) {
  std::mt19937_64 rng(202);
  for (int i = 0; i < 100; ++i) {
    const FourBar loaded = random_model_with_discs(rng, i);
    const RandomState x = random_state(rng);
    const std::string at = where(loaded, x.theta1, x.omega1);
    // free, no loads: T is constant
    const FourBar free_model = without_loads(loaded);
    const DynamicsSample f0 = reference::newton_euler_forward(free_model, x.theta1, x.omega1);
    const Rate dT0 = kinetic_energy_rate(free_model, f0.state);
    EXPECT_LT(std::abs(dT0.value), kRel * dT0.size) << at;
    // free under loads and gravity
    const DynamicsSample f1 = reference::newton_euler_forward(loaded, x.theta1, x.omega1);
    const Rate dT1 = kinetic_energy_rate(loaded, f1.state);
    const Rate P1 = applied_power(loaded, f1.state, 0.0);
    EXPECT_LT(std::abs(dT1.value - P1.value), kRel * (dT1.size + P1.size)) << at;
    // driven: the drive's power joins in
    const DynamicsSample d = reference::newton_euler_inverse(loaded, x.theta1, x.omega1, x.alpha1);
    const Rate dT2 = kinetic_energy_rate(loaded, d.state);
    const Rate P2 = applied_power(loaded, d.state, d.tau);
    EXPECT_LT(std::abs(dT2.value - P2.value), kRel * (dT2.size + P2.size)) << at;
    // the discs matter here: without them the forward acceleration differs at order one
    FourBar bare = loaded;
    bare.counter_rotations = {};
    const DynamicsSample b = reference::newton_euler_forward(bare, x.theta1, x.omega1);
    EXPECT_GT(std::abs(b.state.alpha1 - f1.state.alpha1), 1e-6 * acceleration_scale(f1)) << at;
  }
}

// ---- (b) momenta ---------------------------------------------------------------------------

TEST(CounterRotation, RefereeShakingForceAndMomentAreMomentumRates) {
  std::mt19937_64 rng(303);
  for (int i = 0; i < 100; ++i) {
    const FourBar model = random_model_with_discs(rng, i);
    const RandomState x = random_state(rng);
    const std::string at = where(model, x.theta1, x.omega1);
    for (const DynamicsSample& s :
         {reference::newton_euler_forward(model, x.theta1, x.omega1),
          reference::newton_euler_inverse(model, x.theta1, x.omega1, x.alpha1)}) {
      const double F = force_scale(s);
      const double M = moment_scale(model, s);
      // Fsh = Σ (F_k + m_k g) - Σ m_k a_k
      const Vec2 Fsh = total_applied_force(model) - linear_momentum_rate(model, s.state);
      EXPECT_LT((s.Fsh - Fsh).norm(), kRel * F) << at;
      EXPECT_LT((s.Fsh - (s.RA0 + s.RA3 + s.RC1 + s.RC3)).norm(), kRel * F) << at;
      // Msh = Σ [c_k × (F_k + m_k g) + M_k] - dH/dt, discs included in H
      const double Msh =
          applied_moment_about_A0(model, s.state) - angular_momentum_rate(model, s.state);
      EXPECT_NEAR(s.Msh, Msh, kRel * M) << at;
      // the shafts carry only the mesh force: RCk is tangential to the circle about the pivot
      // through the shaft, of size 2 J |α_k| / |C - P|
      const std::array<const CounterRotation*, 2> discs{&model.counter_rotations.crank,
                                                        &model.counter_rotations.rocker};
      const std::array<Vec2, 2> pivots{Vec2(0, 0), Vec2(model.frame_length, 0)};
      const std::array<Vec2, 2> RC{s.RC1, s.RC3};
      const std::array<double, 2> alpha{s.state.alpha1, s.state.alpha3};
      for (int d = 0; d < 2; ++d) {
        const Vec2 r = discs[d]->at - pivots[d];
        if (discs[d]->inertia == 0) {
          EXPECT_EQ(RC[d], Vec2::Zero()) << at;
          continue;
        }
        EXPECT_LT(std::abs(RC[d].dot(r)), kRel * F * r.norm()) << at;
        EXPECT_NEAR(RC[d].norm(), 2 * discs[d]->inertia * std::abs(alpha[d]) / r.norm(), kRel * F)
            << at;
      }
    }
  }
}

// A driven motion theta1(t) = 0.4 + 2.1 t + 0.3 sin(3 t), with the referee's inverse dynamics at
// each instant.
struct Driven {
  double theta1, omega1, alpha1;
};
Driven driven_at(double t) {
  return {0.4 + 2.1 * t + 0.3 * std::sin(3 * t), 2.1 + 0.9 * std::cos(3 * t),
          -2.7 * std::sin(3 * t)};
}
DynamicsSample driven_sample(const FourBar& model, double t) {
  const Driven d = driven_at(t);
  return reference::newton_euler_inverse(model, d.theta1, d.omega1, d.alpha1);
}
// d/dt of quantity(state) along the driven motion: fourth-order central difference, h = 1e-4 s
template <class Result, class Quantity>
Result rate_in_time(const FourBar& model, double t, Quantity quantity) {
  const double h = 1e-4;
  auto at = [&](double dt) -> Result { return quantity(driven_sample(model, t + dt).state); };
  return (8.0 * (at(h) - at(-h)) - (at(2 * h) - at(-2 * h))) / (12.0 * h);
}

TEST(CounterRotation, ShakingForceAndMomentByCentralDifferencesInTime) {
  std::mt19937_64 rng(404);
  for (int i = 0; i < 8; ++i) {
    FourBar model = random_model_with_discs(rng, i);
    if (i % 2 == 1) model.branch = other(model.branch);
    for (int j = 0; j < 25; ++j) {
      const double t = 0.1 * j;
      const DynamicsSample s = driven_sample(model, t);
      const std::string at =
          where(model, s.state.theta1, s.state.omega1) + ", t = " + std::to_string(t);
      const Vec2 dp = rate_in_time<Vec2>(
          model, t, [&](const FourBarState& x) -> Vec2 { return linear_momentum_of(model, x); });
      const double dH = rate_in_time<double>(
          model, t, [&](const FourBarState& x) { return angular_momentum_about_A0(model, x); });
      const double F = force_scale(s);
      const double M = moment_scale(model, s);
      EXPECT_LT((s.Fsh - (total_applied_force(model) - dp)).norm(), kFd * F) << at;
      EXPECT_NEAR(s.Msh, applied_moment_about_A0(model, s.state) - dH, kFd * M) << at;
      // and core's kinetic energy along the same motion: dT/dt = applied power + tau ω1
      const double dT = rate_in_time<double>(
          model, t, [&](const FourBarState& x) { return kinetic_energy(model, x); });
      const Rate P = applied_power(model, s.state, s.tau);
      const Rate dT_exact = kinetic_energy_rate(model, s.state);
      EXPECT_NEAR(dT, P.value, kFd * (P.size + dT_exact.size)) << at;
    }
  }
}

// ---- (c) core against the referee ----------------------------------------------------------

void expect_matches(const FourBar& model, const DynamicsSample& got, const DynamicsSample& ref,
                    const std::string& at) {
  const double F = force_scale(ref);
  const double M = moment_scale(model, ref);
  const double A = acceleration_scale(ref);
  const FourBarState& g = got.state;
  const FourBarState& r = ref.state;
  EXPECT_LT(std::abs(g.alpha1 - r.alpha1), kRel * A)
      << at << ": alpha1 " << g.alpha1 << " vs referee " << r.alpha1;
  EXPECT_LT(std::abs(g.alpha2 - r.alpha2), kRel * A)
      << at << ": alpha2 " << g.alpha2 << " vs referee " << r.alpha2;
  EXPECT_LT(std::abs(g.alpha3 - r.alpha3), kRel * A)
      << at << ": alpha3 " << g.alpha3 << " vs referee " << r.alpha3;
  EXPECT_LT(std::abs(got.tau - ref.tau), kRel * M)
      << at << ": tau " << got.tau << " vs referee " << ref.tau;
  EXPECT_LT((got.RA0 - ref.RA0).norm(), kRel * F)
      << at << ": RA0 " << got.RA0.transpose() << " vs referee " << ref.RA0.transpose();
  EXPECT_LT((got.RA3 - ref.RA3).norm(), kRel * F)
      << at << ": RA3 " << got.RA3.transpose() << " vs referee " << ref.RA3.transpose();
  EXPECT_LT((got.RC1 - ref.RC1).norm(), kRel * F)
      << at << ": RC1 " << got.RC1.transpose() << " vs referee " << ref.RC1.transpose();
  EXPECT_LT((got.RC3 - ref.RC3).norm(), kRel * F)
      << at << ": RC3 " << got.RC3.transpose() << " vs referee " << ref.RC3.transpose();
  EXPECT_LT((got.Fsh - ref.Fsh).norm(), kRel * F)
      << at << ": Fsh " << got.Fsh.transpose() << " vs referee " << ref.Fsh.transpose();
  EXPECT_LT(std::abs(got.Msh - ref.Msh), kRel * M)
      << at << ": Msh " << got.Msh << " vs referee " << ref.Msh;
}

TEST(CounterRotation, EveryFormulationAgreesWithTheReferee) {
  std::mt19937_64 rng(505);
  int failures_reported = 0;
  for (int i = 0; i < 120; ++i) {
    FourBar model = random_model_with_discs(rng, i);
    for (const Branch branch : {model.branch, other(model.branch)}) {
      model.branch = branch;
      for (int j = 0; j < 2; ++j) {
        const RandomState x = random_state(rng);
        const std::string at =
            "linkage " + std::to_string(i) + ", " + where(model, x.theta1, x.omega1);
        const DynamicsSample ref_f = reference::newton_euler_forward(model, x.theta1, x.omega1);
        const DynamicsSample ref_i =
            reference::newton_euler_inverse(model, x.theta1, x.omega1, x.alpha1);
        for (const Formulation f : kFormulations) {
          const std::string what = at + ", " + to_string(f);
          const auto fwd = forward_dynamics(model, x.theta1, x.omega1, f);
          const auto inv = inverse_dynamics(model, x.theta1, x.omega1, x.alpha1, f);
          ASSERT_TRUE(fwd.has_value()) << what << ": " << fwd.error().what();
          ASSERT_TRUE(inv.has_value()) << what << ": " << inv.error().what();
          expect_matches(model, *fwd, ref_f, what + " forward");
          expect_matches(model, *inv, ref_i, what + " inverse");
          // stop flooding the log once a formulation is plainly wrong
          if (::testing::Test::HasFailure() && ++failures_reported > 12) return;
        }
      }
    }
  }
}

// ---- (d) J = 0 changes nothing -------------------------------------------------------------

void expect_identical(const DynamicsSample& a, const DynamicsSample& b, const std::string& at) {
  EXPECT_EQ(a.state.alpha1, b.state.alpha1) << at;
  EXPECT_EQ(a.state.alpha2, b.state.alpha2) << at;
  EXPECT_EQ(a.state.alpha3, b.state.alpha3) << at;
  EXPECT_EQ(a.tau, b.tau) << at;
  EXPECT_EQ(a.RA0, b.RA0) << at;
  EXPECT_EQ(a.RA3, b.RA3) << at;
  EXPECT_EQ(a.RC1, b.RC1) << at;
  EXPECT_EQ(a.RC3, b.RC3) << at;
  EXPECT_EQ(a.Fsh, b.Fsh) << at;
  EXPECT_EQ(a.Msh, b.Msh) << at;
}
// the plain four-bar's outputs: no shaft forces, Fsh = RA0 + RA3, Msh = l4 RA3y - tau
void expect_plain(const FourBar& model, const DynamicsSample& s, const std::string& at) {
  EXPECT_EQ(s.RC1, Vec2::Zero()) << at;
  EXPECT_EQ(s.RC3, Vec2::Zero()) << at;
  EXPECT_EQ(s.Fsh, Vec2(s.RA0 + s.RA3)) << at;
  EXPECT_EQ(s.Msh, model.frame_length * s.RA3.y() - s.tau) << at;
}

TEST(CounterRotation, ZeroInertiaGivesThePlainFourBarExactly) {
  std::mt19937_64 rng(606);
  for (int i = 0; i < 30; ++i) {
    const FourBar plain = samples::random_crank_rocker(rng);
    // discs of zero inertia, their shafts anywhere (even on the pivot: allowed when J = 0)
    FourBar zero = plain;
    zero.counter_rotations.crank.at = random_shaft(rng, Vec2(0, 0));
    zero.counter_rotations.rocker.at =
        i % 2 ? Vec2(plain.frame_length, 0) : random_shaft(rng, Vec2(plain.frame_length, 0));
    zero = make_fourbar(zero);
    ASSERT_FALSE(has_counter_rotations(zero));
    const RandomState x = random_state(rng);
    const std::string at = where(plain, x.theta1, x.omega1);
    // the referee
    const DynamicsSample rf = reference::newton_euler_forward(plain, x.theta1, x.omega1);
    const DynamicsSample ri = reference::newton_euler_inverse(plain, x.theta1, x.omega1, x.alpha1);
    expect_identical(reference::newton_euler_forward(zero, x.theta1, x.omega1), rf, at);
    expect_identical(reference::newton_euler_inverse(zero, x.theta1, x.omega1, x.alpha1), ri, at);
    expect_plain(plain, rf, at + ", referee forward");
    expect_plain(plain, ri, at + ", referee inverse");
    // core, every formulation
    for (const Formulation f : kFormulations) {
      const std::string what = at + ", " + to_string(f);
      const auto pf = forward_dynamics(plain, x.theta1, x.omega1, f);
      const auto zf = forward_dynamics(zero, x.theta1, x.omega1, f);
      const auto pi = inverse_dynamics(plain, x.theta1, x.omega1, x.alpha1, f);
      const auto zi = inverse_dynamics(zero, x.theta1, x.omega1, x.alpha1, f);
      ASSERT_TRUE(pf && zf && pi && zi) << what;
      expect_identical(*zf, *pf, what + " forward");
      expect_identical(*zi, *pi, what + " inverse");
      expect_plain(plain, *pf, what + " forward");
      expect_plain(plain, *pi, what + " inverse");
    }
    // the kinetic energy
    const auto pose = solve_position(plain, x.theta1);
    ASSERT_TRUE(pose.has_value());
    const FourBarState s = solve_velocity(plain, *pose, x.omega1);
    EXPECT_EQ(kinetic_energy(zero, s), kinetic_energy(plain, s)) << at;
  }
}

}  // namespace
}  // namespace bd::core
