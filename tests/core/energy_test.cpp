#include "core/fourbar/energy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"

namespace bd::core {
namespace {

// Centre-of-mass offset s̄ = e + i f of a link turned to angle theta [m].
Vec2 offset(const Link& l, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * l.e - s * l.f, s * l.e + c * l.f};
}

// A closed state with its velocity stage, at crank angle theta1 [rad] and rate omega1 [rad/s].
FourBarState state_at(const FourBar& model, double theta1, double omega1) {
  const auto pose = solve_position(model, theta1);
  EXPECT_TRUE(pose.has_value()) << "theta1 = " << theta1;
  return solve_velocity(model, *pose, omega1);
}

TEST(Energy, KineticEnergyMatchesDefinition) {
  const FourBar model = samples::paper_fourbar();
  const FourBarState s = state_at(model, 0.7, 1.3);

  // the definition, written out from the link geometry with the rigid-body velocity field
  // v_P = v_Q + ω × (P - Q): crank about A0, coupler from A1, rocker from A2
  const Vec2 l1 = model.crank.length * unit(s.theta1);
  const Vec2 l2 = model.coupler.length * unit(s.theta2);
  const Vec2 v_A1 = s.omega1 * perp(l1);
  const Vec2 v_A2 = v_A1 + s.omega2 * perp(l2);
  const Vec2 v1 = s.omega1 * perp(offset(model.crank, s.theta1));
  const Vec2 v2 = v_A1 + s.omega2 * perp(offset(model.coupler, s.theta2));
  const Vec2 v3 = v_A2 + s.omega3 * perp(offset(model.rocker, s.theta3));
  const double T =
      0.5 * model.crank.mass * v1.squaredNorm() + 0.5 * model.coupler.mass * v2.squaredNorm() +
      0.5 * model.rocker.mass * v3.squaredNorm() + 0.5 * model.crank.inertia * s.omega1 * s.omega1 +
      0.5 * model.coupler.inertia * s.omega2 * s.omega2 +
      0.5 * model.rocker.inertia * s.omega3 * s.omega3;

  // the rocker's far end is A3, at rest: a check that the state is the closed one
  const Vec2 l3 = model.rocker.length * unit(s.theta3);
  EXPECT_LT((v_A2 + s.omega3 * perp(l3)).norm(), 1e-12 * v_A1.norm());
  // same sums in another order: round-off only
  EXPECT_NEAR(kinetic_energy(model, s), T, 1e-14 * T);
  EXPECT_GT(T, 0.0);
}

TEST(Energy, KineticEnergyIsQuadraticInRate) {
  const FourBar model = samples::paper_fourbar();
  const double T1 = kinetic_energy(model, state_at(model, 2.1, 1.0));
  const double T3 = kinetic_energy(model, state_at(model, 2.1, -3.0));
  EXPECT_NEAR(T3, 9.0 * T1, 1e-13 * T3);
}

TEST(Energy, MomentumMatchesCentralDifferencesOfCentreOfMass) {
  // p = M dc/dt = M (dc/dθ1) ω1. Central difference in θ1 with h = 1e-5 rad: truncation
  // ~ h²/6 |c'''| ~ 2e-11 |c|, round-off ~ eps |c| / h ~ 2e-11 |c|, so 1e-9 of the momentum's
  // scale M |c'| ω1 leaves a wide margin.
  std::mt19937_64 rng(7);
  for (const FourBar& model :
       {samples::paper_fourbar(), samples::random_crank_rocker(rng), samples::parallelogram()}) {
    const double M = total_mass(model);
    for (const double theta1 : {0.3, 1.1, 2.0, 2.9}) {
      const double omega1 = 1.7, h = 1e-5;
      const FourBarState s = state_at(model, theta1, omega1);
      const auto before = solve_position(model, theta1 - h);
      const auto after = solve_position(model, theta1 + h);
      ASSERT_TRUE(before && after);
      const Vec2 dc_dtheta1 =
          (system_centre_of_mass(model, *after) - system_centre_of_mass(model, *before)) / (2 * h);
      const Vec2 expected = M * dc_dtheta1 * omega1;
      const Vec2 p = linear_momentum(model, s);
      const double scale = M * omega1 * (model.crank.length + model.coupler.length);
      EXPECT_LT((p - expected).norm(), 1e-9 * scale) << "theta1 = " << theta1;
    }
  }
}

TEST(Energy, SystemCentreOfMassIsMassWeightedMean) {
  const FourBar model = samples::paper_fourbar();
  const Pose pose = *solve_position(model, 0.4);
  Vec2 sum = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) sum += link(model, k).mass * centre_of_mass(model, k, pose);
  const Vec2 c = system_centre_of_mass(model, pose);
  EXPECT_LT((total_mass(model) * c - sum).norm(), 1e-14 * sum.norm());
}

TEST(Energy, LoadPotentialGradientIsMinusTheGeneralisedForce) {
  // -dV/dθ1 is the virtual work of the loads per unit crank rotation: Σ F̄_k·(dr̄_k/dθ1) +
  // Σ M_k Θk; with the velocity stage at ω1 = 1 the rates are exactly these derivatives.
  // Central difference h = 1e-5 rad: truncation ~ h² ~ 1e-10, round-off ~ eps |V| / h ~ 1e-10.
  std::mt19937_64 rng(11);
  const FourBar model = samples::random_crank_rocker(rng);  // with gravity and loads
  for (const double theta1 : {0.2, 1.5, 3.0, 4.4}) {
    const double h = 1e-5;
    const FourBarState s = state_at(model, theta1, 1.0);
    double Q = 0.0, scale = 0.0;
    for (int k = 1; k <= 3; ++k) {
      const LinkLoad& load = link_load(model, k);
      const Vec2 force = load.force + link(model, k).mass * model.loads.gravity;
      const double rate = k == 1 ? s.omega1 : k == 2 ? s.omega2 : s.omega3;
      Q += force.dot(centre_of_mass_velocity(model, k, s)) + load.moment * rate;
      scale +=
          force.norm() * centre_of_mass_velocity(model, k, s).norm() + std::abs(load.moment * rate);
    }
    // continuous angles either side: the pose after is unwrapped to the one before
    const Pose before = *solve_position(model, theta1 - h);
    Pose after = *solve_position(model, theta1 + h);
    after.theta2 +=
        2 * std::numbers::pi * std::round((before.theta2 - after.theta2) / (2 * std::numbers::pi));
    after.theta3 +=
        2 * std::numbers::pi * std::round((before.theta3 - after.theta3) / (2 * std::numbers::pi));
    const double dV = (load_potential(model, after) - load_potential(model, before)) / (2 * h);
    EXPECT_NEAR(-dV, Q, 1e-8 * scale) << "theta1 = " << theta1;
  }
}

}  // namespace
}  // namespace bd::core
