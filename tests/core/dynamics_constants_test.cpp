// The model's constants computed once (core/fourbar/detail/dynamics_constants.hpp, internal to
// core) and the routes that use them: the dynamics overloads with DynamicsConstants, the crank
// vectors of a sweep (CrankSweep) and the driven sweep built on both.
//
// Tolerances. The overloads with constants run the same operations as the one-instant calls, so
// they agree bit for bit. The sweep's crank vector differs from l1·(cos, sin) of the sample's
// angle by a rounding or two of l1, and everything downstream by the same relative amount
// amplified by the position solve's condition (~1e2 on the paper example away from its dead
// centres): 1e-13 of each quantity's scale leaves a margin of ~100 while a wrong angle, branch
// or turn count shows at order one.
#include "core/fourbar/detail/dynamics_constants.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/mass_matrix.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "tests/support/scales.hpp"

namespace bd::core {
namespace {

using detail::CrankSweep;
using detail::dynamics_constants;
using detail::DynamicsConstants;
using detail::mass_matrix_constants;
using detail::MassMatrixConstants;
using detail::Xy;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

void expect_identical(const DynamicsSample& a, const DynamicsSample& b, const std::string& at) {
  EXPECT_EQ(a.state.theta2, b.state.theta2) << at;
  EXPECT_EQ(a.state.theta3, b.state.theta3) << at;
  EXPECT_EQ(a.state.omega2, b.state.omega2) << at;
  EXPECT_EQ(a.state.omega3, b.state.omega3) << at;
  EXPECT_EQ(a.state.alpha1, b.state.alpha1) << at;
  EXPECT_EQ(a.state.alpha2, b.state.alpha2) << at;
  EXPECT_EQ(a.state.alpha3, b.state.alpha3) << at;
  EXPECT_EQ(a.RA0, b.RA0) << at;
  EXPECT_EQ(a.RA3, b.RA3) << at;
  EXPECT_EQ(a.RC1, b.RC1) << at;
  EXPECT_EQ(a.RC3, b.RC3) << at;
  EXPECT_EQ(a.Fsh, b.Fsh) << at;
  EXPECT_EQ(a.Msh, b.Msh) << at;
  EXPECT_EQ(a.tau, b.tau) << at;
}

TEST(DynamicsConstants, OverloadsWithConstantsGiveTheOneInstantResultsBitForBit) {
  std::mt19937_64 rng(31);
  std::vector<FourBar> models = {samples::paper_fourbar(), samples::paper_fourbar_unloaded()};
  for (int i = 0; i < 20; ++i) models.push_back(samples::random_crank_rocker(rng));
  FourBar discs = samples::paper_fourbar();
  discs.counter_rotations.crank = {0.3, Vec2(-0.4, 0.1)};
  models.push_back(make_fourbar(discs));
  for (std::size_t m = 0; m < models.size(); ++m) {
    const FourBar& model = models[m];
    const DynamicsConstants constants = dynamics_constants(model);
    for (int k = 0; k < 24; ++k) {
      const double theta1 = -3.0 + 0.26 * k, omega1 = 1.7 - 0.2 * k, alpha1 = 0.4 - 0.1 * k;
      for (Formulation f : kFormulations) {
        const std::string at = "model " + std::to_string(m) +
                               ", theta1 = " + std::to_string(theta1) + ", " + to_string(f);
        const auto a = forward_dynamics(model, theta1, omega1, f);
        const auto b = forward_dynamics(model, constants, theta1, omega1, f);
        const auto c = inverse_dynamics(model, theta1, omega1, alpha1, f);
        const auto d = inverse_dynamics(model, constants, theta1, omega1, alpha1, f);
        ASSERT_EQ(a.has_value(), b.has_value()) << at;
        ASSERT_EQ(c.has_value(), d.has_value()) << at;
        if (a) {
          expect_identical(*a, *b, at + " forward");
        } else {
          EXPECT_EQ(a.error().what(), b.error().what()) << at;
        }
        if (c) expect_identical(*c, *d, at + " inverse");
      }
    }
  }
}

TEST(DynamicsConstants, MassMatrixBlocksAreTheAssembledMatrix) {
  // d1, d2 and w1..w3 are the blocks of eq. 48's M and eq. 53's Mr: M = [d1 1, W2; W2ᵀ, d2 1]
  // with W v = w ⊗ v, and Mr = [W1, 0; 0, W3ᵀ] (core/fourbar/detail/dynamics_constants.hpp)
  std::mt19937_64 rng(32);
  for (int i = 0; i < 10; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const MassMatrixConstants c = mass_matrix_constants(model);
    const SystemMassMatrices s = system_mass_matrices(model);
    const double tol = 1e-15 * s.M.norm();
    EXPECT_NEAR(c.d1, s.M(0, 0), tol);
    EXPECT_NEAR(c.d1, s.M(1, 1), tol);
    EXPECT_NEAR(c.d2, s.M(2, 2), tol);
    EXPECT_NEAR(c.d2, s.M(3, 3), tol);
    EXPECT_NEAR(c.w2.x, s.M(0, 2), tol);  // W2 = [u -v; v u]
    EXPECT_NEAR(c.w2.y, s.M(1, 2), tol);
    EXPECT_NEAR(-c.w2.y, s.M(0, 3), tol);
    EXPECT_NEAR(c.w2.x, s.M(1, 3), tol);
    EXPECT_NEAR(c.w1.x, s.Mr(0, 0), tol);  // A0 against A1: W1
    EXPECT_NEAR(c.w1.y, s.Mr(1, 0), tol);
    EXPECT_NEAR(c.w3.x, s.Mr(2, 2), tol);  // A3 against A2: W3ᵀ = [u v; -v u]
    EXPECT_NEAR(-c.w3.y, s.Mr(3, 2), tol);
    EXPECT_NEAR(c.w3.y, s.Mr(2, 3), tol);
  }
}

TEST(DynamicsConstants, CrankSweepGivesCosAndSinOfEachAngle) {
  // a driven sweep's angles, 360 and 7 samples per revolution over three revolutions, both
  // directions: every component within two roundings of l1 of l1·cos, l1·sin of the same angle
  for (const double omega1 : {kTwoPi, -3.0}) {
    for (const int per_revolution : {360, 7}) {
      const double l1 = 1.3;
      CrankSweep sweep(l1);
      const double period = kTwoPi / std::abs(omega1);
      double worst = 0;
      for (int j = 0; j < 3 * per_revolution; ++j) {
        const double t = period * j / per_revolution, theta1 = 0.4 + omega1 * t;
        const Xy v = sweep.l1(theta1);
        worst = std::max(
            {worst, std::abs(v.x - l1 * std::cos(theta1)), std::abs(v.y - l1 * std::sin(theta1))});
      }
      EXPECT_LE(worst, 2 * std::numeric_limits<double>::epsilon() * l1)
          << "omega1 = " << omega1 << ", " << per_revolution << " samples";
    }
  }
}

TEST(DynamicsConstants, DrivenSweepMatchesInverseDynamicsAtEverySample) {
  // the sweep's route (constants once, the crank vector turned, the angles continued by whole
  // turns, the derived outputs from the position solve's link vectors) against
  // inverse_dynamics() at the same crank angles: the same numbers to round-off,
  // and the angles the one-instant ones plus whole turns
  std::mt19937_64 rng(33);
  std::vector<FourBar> models = {samples::paper_fourbar(), samples::double_crank()};
  for (int i = 0; i < 3; ++i) models.push_back(samples::random_crank_rocker(rng));
  for (std::size_t m = 0; m < models.size(); ++m) {
    for (Formulation f : kFormulations) {
      SimulateOptions options;
      options.formulation = f;
      const DrivenScene scene{.theta1 = 0.3, .omega1 = -5.0, .revolutions = 2, .samples = 180};
      const Trajectory tr = simulate_driven(models[m], scene, options);
      ASSERT_TRUE(tr.ok()) << tr.message;
      for (std::size_t j = 0; j < tr.samples.size(); ++j) {
        const std::string at =
            "model " + std::to_string(m) + ", " + to_string(f) + ", sample " + std::to_string(j);
        const DynamicsSample& got = tr.samples[j];
        const auto want = inverse_dynamics(models[m], got.state.theta1, scene.omega1, 0.0, f);
        ASSERT_TRUE(want.has_value()) << at;
        const double F = testing::force_scale(*want), M = testing::moment_scale(models[m], *want);
        const double A = testing::acceleration_scale(*want), W = testing::rate_scale(*want);
        for (const auto& [g, w] : {std::pair{got.state.theta2, want->state.theta2},
                                   std::pair{got.state.theta3, want->state.theta3}}) {
          const double turns = (g - w) / kTwoPi;
          EXPECT_NEAR(turns, std::round(turns), 1e-13) << at;
        }
        EXPECT_NEAR(got.state.omega2, want->state.omega2, 1e-13 * W) << at;
        EXPECT_NEAR(got.state.omega3, want->state.omega3, 1e-13 * W) << at;
        EXPECT_NEAR(got.state.alpha2, want->state.alpha2, 1e-13 * A) << at;
        EXPECT_NEAR(got.state.alpha3, want->state.alpha3, 1e-13 * A) << at;
        EXPECT_LT((got.RA0 - want->RA0).norm(), 1e-13 * F) << at;
        EXPECT_LT((got.RA3 - want->RA3).norm(), 1e-13 * F) << at;
        EXPECT_NEAR(got.Msh, want->Msh, 1e-13 * M) << at;
        EXPECT_NEAR(got.tau, want->tau, 1e-13 * M) << at;
        // the derived outputs, from the sweep's link vectors here and from sincos of the angles
        // there
        EXPECT_LT((got.FA1 - want->FA1).norm(), 1e-13 * F) << at;
        EXPECT_LT((got.FA2 - want->FA2).norm(), 1e-13 * F) << at;
        EXPECT_LT((got.Fsh_inertial - want->Fsh_inertial).norm(), 1e-13 * F) << at;
        EXPECT_LT((got.Fsh_static - want->Fsh_static).norm(), 1e-13 * F) << at;
        EXPECT_NEAR(got.Msh_inertial, want->Msh_inertial, 1e-13 * M) << at;
        EXPECT_NEAR(got.Msh_static, want->Msh_static, 1e-13 * M) << at;
        if (j > 0) {  // continuous: far less than a turn between samples
          EXPECT_LT(std::abs(got.state.theta2 - tr.samples[j - 1].state.theta2), 1.0) << at;
          EXPECT_LT(std::abs(got.state.theta3 - tr.samples[j - 1].state.theta3), 1.0) << at;
        }
      }
    }
  }
}

}  // namespace
}  // namespace bd::core
