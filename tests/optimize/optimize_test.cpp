// optimize() (optimize/optimize.hpp) with every algorithm against closed-form optima, the
// constraints at the reported optimum, the verification by an independent formulation, the
// infeasible and the refused cases, and the names and options.
//
// The reference. In a driven scene without loads or gravity, a point counterweight of mass m_c
// at p (link axes, from the pivot) on the crank or the rocker changes the shaking force only by
// m_c times the acceleration of p, which is linear in the mass moment z = m_c p: the pivot is
// fixed and the motion is prescribed. So per sample Fsh_i(z) = F0_i + A_i z with
// z = (crank m_c p; rocker m_c q) in R^4, and
//   Fsh_rms(z)^2 = (1/N) Σ |F0_i + A_i z|^2 = z'Hz + 2 g'z + c,
// a convex quadratic (linear least squares). The test assembles H, g, c itself from four
// simulations of unit counterweights (core::simulate_driven, mass-matrix formulation) and solves
// it: without bounds the minimiser is the force-balanced design (Fsh = 0, cross-checked against
// balance::force_balance); with the crank's counterweight capped (mass_max · distance_max below
// the moment full balance needs) the minimiser lies on the disc |z_crank| = cap and is found by
// the KKT condition (H + λ P) z = -g, |P z| = cap, λ > 0 by bisection on λ.
//
// Tolerances.
// - Mass moments, gradient methods: 1e-6 of |z_ref| (the brief's figure; the solvers stop at
//   relative_tolerance = 1e-10 on x and f, and the capped optimum is a smooth minimum with
//   Fsh_rms > 0). The reference itself is good to ~1e-13 (differences of simulated forces of
//   O(100 N), a 4x4 solve).
// - Derivative-free methods: COBYLA 1e-6 (unbounded) and 1e-5 (capped), ISRES 2e-2 of |z_ref|
//   with the budgets below. COBYLA builds linear models, ISRES is a stochastic evolution
//   strategy: ISRES does not converge to 1e-6 in a few thousand evaluations, but it must find
//   the right basin and get close.
// - The unbounded (force-balanced) optimum has Fsh_rms = 0, where the magnitude has a kink: the
//   objective smooths it as sqrt(r² + ε²) (optimize/nlp.hpp), a smooth function with the same
//   minimiser but curvature ~1/ε there, which costs evaluations (SLSQP 109 against 15 on the
//   squared objective), not accuracy: measured <= 4e-10 in the moments.
// - Verification: the optimiser's metrics (regressor, complex-masses formulation) and the
//   re-simulated ones (mass-matrix formulation) are both exact; they differ by round-off, so
//   1e-9 relative (the brief's figure).
// - Constraints at the optimum: 1e-8 scaled (options.constraint_tolerance = 1e-9 is asked for).
// - The objective: the linear weighted sum Σ w metric/original with each magnitude smoothed as
//   sqrt(r² + ε²), ε = kDefaultSmoothing = 1e-6 (optimize/nlp.hpp), so the reported value lies
//   in [f, f + ε Σ w] for the exact sum f of the optimum's metrics; with the re-simulated
//   metrics, 1e-9 of f more (the verification's figure). For a single term the smoothed and
//   the exact objective have the same minimiser, so the closed forms hold as they are.
#include "optimize/optimize.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <ostream>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "balance/conditions.hpp"
#include "balance/counterweight.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/input_error.hpp"
#include "optimize/first_order.hpp"
#include "optimize/nlopt_driver.hpp"
#include "optimize/nlp.hpp"

namespace bd::optimize {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::DrivenScene one_revolution() {
  return core::DrivenScene{.theta1 = 0.0, .omega1 = kTwoPi, .revolutions = 1, .samples = 72};
}

// counterweights on crank and rocker of the paper's four-bar (no loads), Fsh_rms alone
DesignProblem counterweight_problem(double crank_mass_max = 10.0, double rocker_mass_max = 10.0) {
  DesignProblem p;
  p.original = core::samples::paper_fourbar_unloaded();
  p.scene = one_revolution();
  p.formulation = core::Formulation::kComplexMasses;
  p.counterweights = {
      CounterweightVariables{.link = 1, .mass_max = crank_mass_max, .distance_max = 1.0},
      CounterweightVariables{.link = 3, .mass_max = rocker_mass_max, .distance_max = 1.0}};
  p.objective = {Term{Metric::kFshRms, 1.0}};
  return p;
}

OptimizeOptions options_for(Algorithm a) {
  OptimizeOptions o;
  o.algorithm = a;
  o.relative_tolerance = 1e-10;
  o.max_evaluations = 4000;
  return o;
}

// the mass moments (crank m_c p, rocker m_c q) [kg m] of a result's counterweights
Eigen::Vector4d mass_moments(const OptimizeResult& r) {
  Eigen::Vector4d z = Eigen::Vector4d::Zero();
  for (const PlacedCounterweight& c : r.counterweights) {
    const Vec2 moment = c.counterweight.mass * c.counterweight.position;
    z.segment<2>(c.link == 1 ? 0 : 2) += moment;
  }
  return z;
}

// Fsh_rms^2 = z'Hz + 2 g'z + c, assembled from simulations of unit counterweights
struct LeastSquares {
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d g = Eigen::Vector4d::Zero();
  double c{};
  // the samples: Fsh_i(z) = F0_i + A_i z
  std::vector<Eigen::Matrix<double, 2, 4>> A;
  std::vector<Vec2> F0;
  double peak(const Eigen::Vector4d& z) const {
    double worst = 0;
    for (size_t i = 0; i < A.size(); ++i) worst = std::max(worst, (F0[i] + A[i] * z).norm());
    return worst;
  }
  double rms(const Eigen::Vector4d& z) const {
    return std::sqrt(std::max(0.0, z.dot(H * z) + 2 * g.dot(z) + c));
  }
};

// the model with a unit point counterweight at (1, 0) or (0, 1) from A0 (j = 0, 1) or A3 (2, 3)
core::FourBar with_unit_counterweight(const core::FourBar& model, int j) {
  const balance::Counterweight unit{
      .mass = 1.0, .position = j % 2 == 0 ? Vec2(1, 0) : Vec2(0, 1), .distance = 1.0};
  core::FourBar m = model;
  if (j < 2) {
    m.crank = balance::merged(model.crank, unit, false);
  } else {
    m.rocker = balance::merged(model.rocker, unit, true);
  }
  return m;
}

// Rows of the peak (not of the RMS) at further crank angles [rad]: Fsh from core's inverse
// dynamics of the same models at each angle (an optimum's peak_angles).
void add_peak_angles(LeastSquares& ls, const core::FourBar& model, double omega1,
                     const std::vector<double>& angles) {
  constexpr auto kF = core::Formulation::kMassMatrix;
  for (const double angle : angles) {
    const auto base = core::inverse_dynamics(model, angle, omega1, 0.0, kF);
    ASSERT_TRUE(base.has_value());
    Eigen::Matrix<double, 2, 4> A;
    for (int j = 0; j < 4; ++j) {
      const auto d =
          core::inverse_dynamics(with_unit_counterweight(model, j), angle, omega1, 0.0, kF);
      ASSERT_TRUE(d.has_value());
      A.col(j) = d->Fsh - base->Fsh;
    }
    ls.A.push_back(A);
    ls.F0.push_back(base->Fsh);
  }
}

LeastSquares assemble(const core::FourBar& model, const core::DrivenScene& scene) {
  const core::SimulateOptions simulate{.formulation = core::Formulation::kMassMatrix};
  const core::Trajectory base = core::simulate_driven(model, scene, simulate);
  EXPECT_TRUE(base.ok()) << base.message;
  const size_t n = base.samples.size();
  std::vector<Eigen::Matrix<double, 2, 4>> A(n);
  for (int j = 0; j < 4; ++j) {
    const core::Trajectory t =
        core::simulate_driven(with_unit_counterweight(model, j), scene, simulate);
    EXPECT_TRUE(t.ok()) << t.message;
    for (size_t i = 0; i < n; ++i) A[i].col(j) = t.samples[i].Fsh - base.samples[i].Fsh;
  }
  LeastSquares ls;
  ls.A = A;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 F0 = base.samples[i].Fsh;
    ls.F0.push_back(F0);
    ls.H += A[i].transpose() * A[i];
    ls.g += A[i].transpose() * F0;
    ls.c += F0.squaredNorm();
  }
  const double N = static_cast<double>(n);
  ls.H /= N;
  ls.g /= N;
  ls.c /= N;
  return ls;
}

// the minimiser of the quadratic with |z_crank| <= cap (KKT with bisection on the multiplier)
Eigen::Vector4d minimiser(const LeastSquares& ls, double cap) {
  auto solve = [&ls](double lambda) {
    Eigen::Matrix4d K = ls.H;
    K(0, 0) += lambda;
    K(1, 1) += lambda;
    return Eigen::Vector4d(K.ldlt().solve(-ls.g));
  };
  Eigen::Vector4d z = solve(0.0);
  if (z.head<2>().norm() <= cap) return z;
  double lo = 0.0, hi = 1.0;
  while (solve(hi).head<2>().norm() > cap) hi *= 2;
  for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    (solve(mid).head<2>().norm() > cap ? lo : hi) = mid;
  }
  return solve(hi);
}

double relative(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  return (a - b).norm() / b.norm();
}

// ---------------------------------------------------------------------------------------------
// names and options

TEST(Optimize, AlgorithmNamesRoundTrip) {
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt, Algorithm::kMlsl,
                      Algorithm::kIsres, Algorithm::kCobyla}) {
    ASSERT_TRUE(algorithm_named(to_string(a)).has_value()) << to_string(a);
    EXPECT_EQ(*algorithm_named(to_string(a)), a);
  }
  EXPECT_FALSE(algorithm_named("SLSQP").has_value());
  EXPECT_FALSE(algorithm_named("").has_value());
  EXPECT_TRUE(uses_gradients(Algorithm::kSlsqp));
  EXPECT_TRUE(uses_gradients(Algorithm::kMma));
  EXPECT_TRUE(uses_gradients(Algorithm::kIpopt));
  EXPECT_TRUE(uses_gradients(Algorithm::kMlsl));
  EXPECT_FALSE(uses_gradients(Algorithm::kIsres));
  EXPECT_FALSE(uses_gradients(Algorithm::kCobyla));
  EXPECT_STREQ(to_string(Termination::kConverged), "converged");
  EXPECT_STREQ(to_string(Termination::kStoppedShort), "stopped short");
  EXPECT_TRUE(found_design(Termination::kStoppedShort));
  EXPECT_FALSE(found_design(Termination::kInfeasible));
  // the methods worth suggesting after one found nothing: never the one used, never a gradient
  // method in a free scene
  EXPECT_EQ(other_algorithms(Algorithm::kSlsqp, false), "ipopt, mlsl, cobyla");
  EXPECT_EQ(other_algorithms(Algorithm::kCobyla, true), "isres");
  EXPECT_EQ(default_algorithm(true), Algorithm::kCobyla);
  EXPECT_EQ(default_algorithm(false), Algorithm::kSlsqp);
  EXPECT_STREQ(to_string(Termination::kInfeasible), "infeasible");
}

TEST(Optimize, OptionsValidate) {
  EXPECT_FALSE(OptimizeOptions{}.validate());
  // the problem's text, and its field
  auto problem = [](const OptimizeOptions& o) {
    const Problem e = o.validate();
    return e ? e->text() + " | " + e->field : std::string();
  };
  OptimizeOptions o;
  o.max_evaluations = 0;
  EXPECT_EQ(problem(o), "max_evaluations must be >= 1, got 0 | max_evaluations");
  o = {};
  o.relative_tolerance = -1;
  EXPECT_EQ(problem(o), "relative_tolerance must be in (0, 1), got -1 | relative_tolerance");
  o = {};
  o.algorithm = Algorithm{17};
  EXPECT_EQ(problem(o),
            "algorithm must be one of slsqp, mma, ipopt, mlsl, isres, cobyla | algorithm");
  o = {};
  o.constraint_tolerance = 0;
  EXPECT_EQ(problem(o), "constraint_tolerance must be > 0, got 0 | constraint_tolerance");
  // starts are mlsl's: another algorithm's evaluations need not cover them (the default 8)
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt, Algorithm::kMlsl,
                      Algorithm::kIsres, Algorithm::kCobyla}) {
    OptimizeOptions few;
    few.algorithm = a;
    few.max_evaluations = 5;
    EXPECT_EQ(problem(few), a == Algorithm::kMlsl
                                ? "starts must be >= 1 and <= max_evaluations (5: each start "
                                  "needs an evaluation), got 8 | starts"
                                : "")
        << to_string(a);
  }
  try {
    (void)optimize(counterweight_problem(), o);
    FAIL() << "invalid options accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "optimize options: constraint_tolerance must be > 0, got 0");
  }
}

TEST(Optimize, InvalidProblemThrows) {
  DesignProblem p = counterweight_problem();
  p.objective.clear();
  EXPECT_THROW((void)optimize(p, OptimizeOptions{}), InputError);
}

TEST(Optimize, NotRunResult) {
  const OptimizeResult r;
  EXPECT_EQ(r.termination, Termination::kNotRun);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.brief_report().find("not run"), std::string::npos) << r.brief_report();
}

// ---------------------------------------------------------------------------------------------
// the reference is right: its unbounded minimiser is the force-balanced design of the balance
// layer (two independent routes to the same four numbers), where Fsh_rms vanishes

TEST(Optimize, LeastSquaresReferenceIsTheForceBalancedDesign) {
  const DesignProblem p = counterweight_problem();
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d z = minimiser(ls, 1e300);
  const balance::ForceBalancedDesign fb = balance::force_balance(p.original, {}, {});
  ASSERT_TRUE(fb.crank && fb.rocker);
  Eigen::Vector4d expected;
  expected << fb.crank->mass * fb.crank->position, fb.rocker->mass * fb.rocker->position;
  EXPECT_LT(relative(z, expected), 1e-10) << z.transpose() << " vs " << expected.transpose();
  EXPECT_LT(ls.rms(z), 1e-6 * std::sqrt(ls.c));  // sqrt of a difference of O(c) terms
}

// ---------------------------------------------------------------------------------------------
// every algorithm against the closed form, on two problems:
// - unbounded: the minimiser is the force-balanced design (Fsh_rms = 0), convex in the mass
//   moments, with no constraint active there;
// - capped: the crank counterweight capped at 1 kg at up to 1 m, where full balance needs about
//   2.6 kg m: a non-zero optimum on the boundary (mass at its bound, the envelope active).

struct Case {
  Algorithm algorithm;
  int budget;               // objective evaluations
  double unbounded;         // tolerance on the mass moments, relative to |z_ref|
  double capped;            // the same on the capped problem
};

// Gradient methods: 1e-6 (the brief's figure) except MMA on the capped problem: its
// conservative separable approximations creep onto the active envelope from outside (its last
// iterates violate it by ~2e-8, so the best feasible iterate is returned) and it stalls at
// 9.7e-6 on the linear objective (1.4e-6 on the squared one); 1e-5 states that, with little
// margin. COBYLA (linear models, measured 4.6e-7 capped) and ISRES (a stochastic evolution
// strategy, 2e-3) are derivative-free: the tolerances are what they reach within the budgets,
// with a margin of ~10.
const Case kCases[] = {
    {Algorithm::kSlsqp, 4000, 1e-6, 1e-6},  {Algorithm::kIpopt, 4000, 1e-6, 1e-6},
    {Algorithm::kMma, 4000, 1e-6, 1e-5},    {Algorithm::kMlsl, 4000, 1e-6, 1e-6},
    {Algorithm::kCobyla, 4000, 1e-6, 1e-5}, {Algorithm::kIsres, 20000, 2e-2, 2e-2},
};

void PrintTo(const Case& c, std::ostream* os) { *os << to_string(c.algorithm); }

class ClosedForm : public ::testing::TestWithParam<Case> {};

TEST_P(ClosedForm, UnboundedOptimumIsTheForceBalancedDesign) {
  const Case c = GetParam();
  const DesignProblem p = counterweight_problem();
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d z_ref = minimiser(ls, 1e300);
  OptimizeOptions o = options_for(c.algorithm);
  o.max_evaluations = c.budget;
  const OptimizeResult r = optimize(p, o);
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  EXPECT_TRUE(r.ok());
  EXPECT_LT(relative(mass_moments(r), z_ref), c.unbounded)
      << mass_moments(r).transpose() << " vs " << z_ref.transpose();
  // Fsh_rms of a moment error δz is sqrt(δz'Hδz) <= sqrt(λmax(H)) |δz|
  const double lambda_max = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(ls.H).eigenvalues()(3);
  EXPECT_LE(r.metrics.Fsh_rms, std::sqrt(lambda_max) * c.unbounded * z_ref.norm());
  // the objective is the smoothed normalised metric sqrt(r² + ε²), r = Fsh_rms / Fsh_rms of the
  // original: here r ~ 1e-10 at most, so the value is ε to ~1e-14 (the smoothing's price at a
  // vanishing metric, the bound of optimize/nlp.hpp)
  const double r_fsh = r.metrics.Fsh_rms / std::sqrt(ls.c);
  EXPECT_NEAR(r.objective, std::hypot(r_fsh, kDefaultSmoothing), 1e-15);
  EXPECT_GE(r.objective, r_fsh);
  EXPECT_LE(r.objective, r_fsh + kDefaultSmoothing);
  EXPECT_LE(r.constraint_violation, 1e-9);
  EXPECT_LT(r.verification_error, 1e-9);
  EXPECT_LE(r.evaluations, c.budget + 1);
}

TEST_P(ClosedForm, CappedOptimumIsTheConstrainedLeastSquares) {
  const Case c = GetParam();
  const DesignProblem p = counterweight_problem(1.0, 10.0);
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d z_ref = minimiser(ls, 1.0);
  ASSERT_GT(minimiser(ls, 1e300).head<2>().norm(), 1.5);  // the cap binds
  ASSERT_LT(z_ref.tail<2>().norm(), 9.0);                  // the rocker's does not

  OptimizeOptions o = options_for(c.algorithm);
  o.max_evaluations = c.budget;
  const OptimizeResult r = optimize(p, o);
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  EXPECT_TRUE(r.ok());
  EXPECT_LT(relative(mass_moments(r), z_ref), c.capped)
      << mass_moments(r).transpose() << " vs " << z_ref.transpose();
  // Fsh_rms is first order in the moments on the boundary (the cap's multiplier is not zero),
  // and no feasible design beats the global optimum
  const double Fsh_ref = ls.rms(z_ref);
  EXPECT_NEAR(r.metrics.Fsh_rms, Fsh_ref, 10 * c.capped * Fsh_ref);
  EXPECT_GE(r.metrics.Fsh_rms, Fsh_ref * (1 - 1e-9));
  // the objective is the normalised metric r = Fsh_rms / Fsh_rms of the original, smoothed as
  // sqrt(r² + ε²): r ~ 0.36 here, so within ε²/(2r) ~ 1.4e-12 of r itself
  EXPECT_NEAR(r.objective, r.metrics.Fsh_rms / std::sqrt(ls.c), 2e-12);
  EXPECT_LE(r.constraint_violation, 1e-9);
  EXPECT_LT(r.verification_error, 1e-9);
  EXPECT_EQ(r.verified_with, core::Formulation::kMassMatrix);
  EXPECT_GT(r.evaluations, 0);
  EXPECT_LE(r.evaluations, c.budget + 1);
}

INSTANTIATE_TEST_SUITE_P(Algorithms, ClosedForm, ::testing::ValuesIn(kCases),
                         [](const auto& p) { return std::string(to_string(p.param.algorithm)); });

// ---------------------------------------------------------------------------------------------
// An added-mass budget that rules out full force balance: a convex problem in the counterweights'
// mass moments z (Fsh_rms² is a convex quadratic in z, and the least mass for a mass moment is
// |z_c| / distance_max, so the budget is Σ |z_c| / D_c <= M). The reference below solves it
// independently of the optimiser: projected gradient descent on the quadratic assembled from
// simulations of unit counterweights, with the exact projection onto that weighted ball.

// the projection of y onto {Σ |z_c| / D_c <= M} (crank z(0, 1), rocker z(2, 3)): each group's
// length shrunk by τ / D_c, τ by bisection
Eigen::Vector4d project_on_budget(const Eigen::Vector4d& y, const Eigen::Vector2d& D, double M) {
  const Eigen::Vector2d length(y.head<2>().norm(), y.tail<2>().norm());
  auto used = [&](double tau) {
    return std::max(length[0] - tau / D[0], 0.0) / D[0] + std::max(length[1] - tau / D[1], 0.0) / D[1];
  };
  if (used(0) <= M) return y;
  double lo = 0, hi = std::max(length[0] * D[0], length[1] * D[1]);
  for (int k = 0; k < 200; ++k) (used(0.5 * (lo + hi)) > M ? lo : hi) = 0.5 * (lo + hi);
  Eigen::Vector4d z = y;
  for (int c = 0; c < 2; ++c) {
    const double shrunk = std::max(length[c] - hi / D[c], 0.0);
    z.segment<2>(2 * c) *= length[c] > 0 ? shrunk / length[c] : 0.0;
  }
  return z;
}

// min z'Hz + 2 g'z + c over the budget, by projected gradient steps 1 / (2 λmax(H)) to a fixed
// point (the problem is strongly convex: H is positive definite here)
Eigen::Vector4d budget_minimiser(const LeastSquares& ls, const Eigen::Vector2d& D, double M) {
  const double L = 2 * Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(ls.H).eigenvalues().maxCoeff();
  Eigen::Vector4d z = Eigen::Vector4d::Zero();
  for (int k = 0; k < 2'000'000; ++k) {
    const Eigen::Vector4d next = project_on_budget(z - 2 * (ls.H * z + ls.g) / L, D, M);
    const bool still = (next - z).norm() <= 1e-16 * (1 + z.norm());
    z = next;
    if (still) break;
  }
  return z;
}

// Issue 15's finding: slsqp (the default) ended "infeasible" and mma "converged" at 4x the
// optimum on such problems, both started at half of mass_max, outside the budget. Every method
// now starts from a feasible design and has its end checked against the first-order conditions.
TEST(Optimize, BudgetThatRulesOutFullBalanceReachesTheIndependentOptimum) {
  const Eigen::Vector2d D(0.8, 1.2);
  DesignProblem p = counterweight_problem();
  p.counterweights[0].distance_max = D[0];
  p.counterweights[1].distance_max = D[1];
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d full = minimiser(ls, 1e300);
  const double budget_full = full.head<2>().norm() / D[0] + full.tail<2>().norm() / D[1];
  for (double fraction : {0.2, 0.6, 1.5}) {
    const double M = fraction * budget_full;
    p.limits = {Limit{Metric::kAddedMass, M}};
    const Eigen::Vector4d z = budget_minimiser(ls, D, M);
    const double reference = ls.rms(z), original = std::sqrt(ls.c);
    for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt}) {
      OptimizeOptions o;  // the defaults a study gets, but for the method
      o.algorithm = a;
      const OptimizeResult r = optimize(p, o);
      SCOPED_TRACE(std::string("budget ") + std::to_string(fraction) + " x full balance's | " +
                   r.brief_report() + " | " + r.message);
      EXPECT_EQ(r.termination, Termination::kConverged);
      // 1e-6 of the original's RMS: what the optimum's objective can show with the smoothing
      // ε = 1e-6 at a balanced design (fraction 1.5), far tighter where the budget binds
      EXPECT_NEAR(r.metrics.Fsh_rms, reference, 1e-6 * original) << reference;
      // the design itself to about sqrt(1e-8), what an objective converged to 1e-8 can fix
      if (fraction < 1) {
        EXPECT_LT(relative(mass_moments(r), z), 2e-4) << z.transpose();
      }
      EXPECT_LE(r.metrics.Fsh_rms, r.verified.Fsh_rms * (1 + 1e-9) + 1e-12 * original);
    }
  }
}

// Issue 15, item 1, on random linkages: driven crank-rockers (random lengths, masses, centres of
// mass, inertias; Grashof with the crank shortest) with point counterweights on crank and rocker
// and an added-mass budget that binds (0.3, 0.7 of the least mass of full force balance) or not
// (1.5). The problem is convex in the counterweights' masses and mass moments, the optimiser
// solves it in those variables and says its optimum is global; every gradient method reaches the
// independent optimum (budget_minimiser above) to 1e-6 of it where the budget binds, and to 1e-6
// of the original's RMS where it does not (the smoothing's ε at a force-balanced design). None
// ends infeasible. COBYLA (derivative-free, linear models) within 1e-5, as on the closed forms.
core::FourBar random_crank_rocker(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  core::FourBar m;
  // s + l <= 1.0 + 3.4 < 2.6 + 2.2 <= p + q: Grashof, the crank the shortest: a crank-rocker
  m.crank = {in(0.6, 1.0), in(0.5, 3.0), in(0.1, 0.8), in(-0.3, 0.3), in(0.05, 0.5)};
  m.coupler = {in(2.6, 3.4), in(1.0, 4.0), in(0.5, 2.5), in(-0.5, 0.5), in(0.5, 3.0)};
  m.rocker = {in(2.2, 2.6), in(1.0, 3.0), in(0.3, 1.8), in(-0.5, 0.5), in(0.3, 2.0)};
  m.frame_length = in(2.8, 3.4);
  return core::make_fourbar(m);
}

TEST(Optimize, RandomConvexCounterweightProblemsReachTheGlobalOptimum) {
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int gradient_runs = 0, certified = 0;
  for (int linkage = 0; linkage < 4; ++linkage) {
    DesignProblem p = counterweight_problem();
    p.original = random_crank_rocker(rng);
    const Eigen::Vector2d D(0.5 + u(rng), 0.5 + u(rng));
    p.counterweights[0].distance_max = D[0];
    p.counterweights[1].distance_max = D[1];
    const LeastSquares ls = assemble(p.original, one_revolution());
    const Eigen::Vector4d full = minimiser(ls, 1e300);
    const double budget_full = full.head<2>().norm() / D[0] + full.tail<2>().norm() / D[1];
    // mass_max above what the budget allows (1.5 x full balance's least mass at distance_max)
    p.counterweights[0].mass_max = p.counterweights[1].mass_max = 2 * budget_full;
    const double original = std::sqrt(ls.c);
    for (double fraction : {0.3, 0.7, 1.5}) {
      p.limits = {Limit{Metric::kAddedMass, fraction * budget_full}};
      // where the budget does not bind, full force balance (Fsh = 0) is the optimum
      const double reference =
          fraction < 1 ? ls.rms(budget_minimiser(ls, D, fraction * budget_full)) : 0.0;
      const double tolerance = fraction < 1 ? 1e-6 * reference : 1e-6 * original;
      for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt,
                          Algorithm::kMlsl, Algorithm::kCobyla}) {
        OptimizeOptions o;  // the defaults a study gets, but for the method
        o.algorithm = a;
        const OptimizeResult r = optimize(p, o);
        SCOPED_TRACE("linkage " + std::to_string(linkage) + ", budget " +
                     std::to_string(fraction) + " x full balance's | " + r.brief_report() + " | " +
                     r.message + " | " + r.optimality);
        ASSERT_TRUE(r.ok());
        EXPECT_LE(r.constraint_violation, o.constraint_tolerance);
        EXPECT_NEAR(r.metrics.Fsh_rms, reference, a == Algorithm::kCobyla ? 10 * tolerance : tolerance);
        // no design within the budget beats the global optimum (the reference is exact to ~1e-13)
        EXPECT_GE(r.metrics.Fsh_rms, reference - 1e-9 * original);
        if (a != Algorithm::kCobyla) {
          ++gradient_runs;
          // the global optimum's objective (smoothed ratio to the original's Fsh_rms)
          const double exact = std::sqrt(reference * reference / (original * original) +
                                         p.smoothing * p.smoothing);
          if (r.global) {
            ++certified;
            EXPECT_EQ(r.optimality.rfind("global: ", 0), 0u);
            // the Lagrangian bound of the convex problem meets the optimum
            EXPECT_NEAR(r.lower_bound, exact, 1e-6 * std::max(1.0, exact));
          }
          // a bound, certified or not, never exceeds the global optimum's objective
          EXPECT_LE(r.lower_bound, exact * (1 + 1e-9));
        }
      }
    }
  }
  // the certificate is never wrong (every value above is the global optimum's); it may be
  // missing where a counterweight ends at the cone's apex (no mass: the direction of its mass
  // moment is round-off, measured 1 of 48 runs), which the result then says ("not proven")
  EXPECT_GE(certified, gradient_runs - 2) << certified << " of " << gradient_runs;
}

// The peak of the shaking force under a budget: convex as well (the largest of the samples'
// magnitudes, each a norm of an affine map), through the bound variable t. No independent closed
// form, so: SLSQP and Ipopt agree, their optimum is global by the project's own check, and no
// feasible design near it does better (random designs within the budget, evaluated from the
// test's own simulations of unit counterweights at the samples and at the crank angles the
// exchange step added, where the optimiser bounds the peak too). MMA (one conservative
// approximation per sample's row) may spend the default 2000 evaluations short of the
// first-order conditions (measured once: 0.0013 against 1e-4): where it does not claim a global
// optimum it must still not beat it, and come within 1 %.
// With the peaks resolved (the default) the same problem is checked below, by Ipopt.
TEST(Optimize, PeakUnderABudgetIsGlobalAndNoNearbyDesignBeatsIt) {
  DesignProblem p = counterweight_problem();
  p.objective = {Term{Metric::kFshMax, 1.0}};
  p.resolve_peaks = false;  // the samples' peak
  const Eigen::Vector2d D(1.0, 1.0);
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d full = minimiser(ls, 1e300);
  const double M = 0.5 * (full.head<2>().norm() + full.tail<2>().norm());
  p.limits = {Limit{Metric::kAddedMass, M}};
  std::vector<double> peaks;
  Eigen::Vector4d best = Eigen::Vector4d::Zero();
  LeastSquares at_best = ls;  // with the best run's peak angles
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt, Algorithm::kMma}) {
    OptimizeOptions o;
    o.algorithm = a;
    const OptimizeResult r = optimize(p, o);
    SCOPED_TRACE(r.brief_report() + " | " + r.message + " | " + r.optimality);
    ASSERT_TRUE(r.ok());
    // the optimiser's peak is the test's own of its design, over the same instants
    LeastSquares at = ls;
    add_peak_angles(at, p.original, one_revolution().omega1, r.peak_angles);
    EXPECT_NEAR(r.metrics.Fsh_max, at.peak(mass_moments(r)), 1e-9 * r.metrics.Fsh_max);
    if (a == Algorithm::kMma && !r.global) {
      EXPECT_GE(r.metrics.Fsh_max, peaks[0] * (1 - 1e-9));
      EXPECT_LE(r.metrics.Fsh_max, peaks[0] * (1 + 1e-2));
      continue;
    }
    EXPECT_TRUE(r.global);
    peaks.push_back(r.metrics.Fsh_max);
    best = mass_moments(r);
    at_best = at;
  }
  for (double peak : peaks) EXPECT_NEAR(peak, peaks[0], 1e-6 * peaks[0]);
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const double scale = std::pow(10.0, -1 - 4 * (k % 5) / 4.0) * best.norm();  // 0.1 ... 1e-5
    const Eigen::Vector4d trial =
        project_on_budget(best + scale * Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)), D, M);
    EXPECT_GE(at_best.peak(trial), peaks[0] * (1 - 1e-6)) << trial.transpose();
  }

  // The motion's peak (resolved, the default): Ipopt's optimum is certified global, the peak it
  // bounds is its design's resolved peak, no lower than the samples' optimum (more constraints),
  // and no nearby design in the budget does better over the instants it bounded. SLSQP ends
  // there too, certified: its quasi-Newton steps stall among the nearly equal rows of its peaks
  // (first-order conditions to 0.06), where the rocker's counterweight vanishes; put on the apex,
  // whose subgradients the check reads, the rest solves to 2.4e-5 (measured: 749 evaluations;
  // before the apex's subgradients, stopped short after 1455).
  DesignProblem resolved = p;
  resolved.resolve_peaks = true;
  OptimizeOptions by_ipopt;
  by_ipopt.algorithm = Algorithm::kIpopt;
  const OptimizeResult r = optimize(resolved, by_ipopt);
  SCOPED_TRACE("resolved: " + r.brief_report() + " | " + r.message + " | " + r.optimality);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.global);
  const double original = Nlp(resolved).original(Metric::kFshMax);
  const core::SimulateOptions simulate{.formulation = resolved.formulation};
  const core::Trajectory run = core::simulate_driven(r.design, one_revolution(), simulate);
  ASSERT_TRUE(run.ok()) << run.message;
  EXPECT_NEAR(r.metrics.Fsh_max,
              core::metrics(r.design, one_revolution(), run, resolved.formulation, nullptr).Fsh_max,
              1e-9 * original);
  EXPECT_GE(r.metrics.Fsh_max, peaks[0] * (1 - 1e-9));
  LeastSquares at_r = ls;
  add_peak_angles(at_r, p.original, one_revolution().omega1, r.peak_angles);
  const Eigen::Vector4d z = mass_moments(r);
  for (int k = 0; k < 500; ++k) {
    const double scale = std::pow(10.0, -1 - 4 * (k % 5) / 4.0) * z.norm();
    const Eigen::Vector4d trial =
        project_on_budget(z + scale * Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)), D, M);
    EXPECT_GE(at_r.peak(trial), r.metrics.Fsh_max * (1 - 1e-6)) << trial.transpose();
  }
  OptimizeOptions by_slsqp;
  const OptimizeResult s = optimize(resolved, by_slsqp);
  SCOPED_TRACE("slsqp: " + s.brief_report() + " | " + s.message + " | " + s.optimality);
  EXPECT_EQ(s.termination, Termination::kConverged);
  EXPECT_TRUE(s.global);
  EXPECT_GE(s.metrics.Fsh_max, r.metrics.Fsh_max * (1 - 1e-9));
  EXPECT_NEAR(s.metrics.Fsh_max, r.metrics.Fsh_max, 1e-8 * original);
}

// The exchange step (resolve_peaks): with 24 samples a revolution, the optimum of the samples'
// peak has peaks between them (the optimiser evens out the sampled peaks, and the motion rises
// above them); optimize() adds crank angles around them and solves again until the peak it
// bounds is the motion's.
// Checked against core's resolved peak of the design (a search between the samples by its own
// inverse dynamics), against the same problem on 360 samples (another discretisation, the same
// optimum to the peaks' smoothing), and against random designs within the budget, which do no
// better over the samples and the added angles (the test's own simulations of unit
// counterweights) nor over 3600 samples beyond a discretisation's undershoot.
// the least Fsh_max on 24 samples a revolution, the motion's peaks bounded
DesignProblem coarse_peak_problem() {
  DesignProblem p = counterweight_problem();
  core::DrivenScene coarse = one_revolution();
  coarse.samples = 24;
  p.scene = coarse;
  p.objective = {Term{Metric::kFshMax, 1.0}};
  p.resolve_peaks = true;
  return p;
}

// the same under an added-mass budget of half what full force balance needs (returned in M)
DesignProblem budget_peak_problem(double* M) {
  DesignProblem p = coarse_peak_problem();
  const Eigen::Vector4d full = minimiser(assemble(p.original, one_revolution()), 1e300);
  *M = 0.5 * (full.head<2>().norm() + full.tail<2>().norm());
  p.limits = {Limit{Metric::kAddedMass, *M}};
  return p;
}

TEST(Optimize, APeakObjectiveBoundsTheMotionsPeakNotTheSamples) {
  constexpr auto kF = core::Formulation::kMassMatrix;
  double M = 0;
  DesignProblem p = budget_peak_problem(&M);
  const core::DrivenScene coarse = std::get<core::DrivenScene>(p.scene);
  const OptimizeResult r = optimize(p, OptimizeOptions{});
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  ASSERT_TRUE(r.ok());
  ASSERT_FALSE(r.peak_angles.empty()) << "24 samples hold the optimum's peaks";
  // the console's line counts them
  EXPECT_NE(r.brief_report().find(", peaks bounded at " + std::to_string(r.peak_angles.size()) +
                                  " crank angles besides the samples"),
            std::string::npos)
      << r.brief_report();
  // the peak bounded is the design's resolved peak
  const core::Trajectory run = core::simulate_driven(r.design, coarse, {.formulation = kF});
  ASSERT_TRUE(run.ok()) << run.message;
  const core::Metrics resolved = core::metrics(r.design, coarse, run, kF, nullptr);
  EXPECT_NEAR(r.metrics.Fsh_max, resolved.Fsh_max, 1e-9 * resolved.Fsh_max);
  EXPECT_LT(r.verification_error, 1e-9);
  // the 24 samples fall short of this design's peak (what a sampled objective would report)
  LeastSquares samples_only = assemble(p.original, coarse);
  EXPECT_GT(resolved.Fsh_max, samples_only.peak(mass_moments(r)) * (1 + 1e-6));
  // 360 samples: the same optimum
  DesignProblem fine = p;
  core::DrivenScene fine_scene = one_revolution();
  fine_scene.samples = 360;
  fine.scene = fine_scene;
  const OptimizeResult rf = optimize(fine, OptimizeOptions{});
  ASSERT_TRUE(rf.ok()) << rf.message;
  EXPECT_NEAR(rf.metrics.Fsh_max, r.metrics.Fsh_max, 1e-8 * r.metrics.Fsh_max);
  // no design in the budget nearby does better over the optimiser's instants, nor over 3600
  // samples (whose peak is below the motion's by at most ~h² f''/8, ~1e-6 of it)
  LeastSquares at = samples_only;
  add_peak_angles(at, p.original, coarse.omega1, r.peak_angles);
  core::DrivenScene finest = one_revolution();
  finest.samples = 3600;
  const LeastSquares dense = assemble(p.original, finest);
  const Eigen::Vector4d best = mass_moments(r);
  const Eigen::Vector2d D(1.0, 1.0);
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const double scale = std::pow(10.0, -1 - 4 * (k % 5) / 4.0) * best.norm();  // 0.1 ... 1e-5
    const Eigen::Vector4d trial =
        project_on_budget(best + scale * Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)), D, M);
    EXPECT_GE(at.peak(trial), r.metrics.Fsh_max * (1 - 1e-9)) << trial.transpose();
    EXPECT_GE(dense.peak(trial), r.metrics.Fsh_max * (1 - 1e-5)) << trial.transpose();
  }
}

// An optimum on the cones' apex: weighing the added mass three times against the peak shaking
// force, no counterweight pays (the original design is the optimum). The mass moment of a
// counterweight on its apex has no direction; the first-order check there reads the cone's
// subgradients (a disc of them: cone_first_order_row()), so the design is certified: converged,
// proven global, the lower bound within round-off of the objective. Before, SLSQP ended "stopped
// short" (first-order conditions to 0.03) with a lower bound of -2.8. The referee: core's own
// resolved peaks of random designs within the envelopes, none better than the original.
TEST(Optimize, AnOptimumOnTheApexIsCertified) {
  DesignProblem p = counterweight_problem();
  core::DrivenScene scene = one_revolution();
  scene.samples = 36;
  p.scene = scene;
  p.counterweights[1].distance_max = 2.0;
  p.objective = {Term{Metric::kFshMax, 1.0}, Term{Metric::kAddedMass, 3.0}};
  OptimizeOptions o;
  o.relative_tolerance = 1e-10;
  const OptimizeResult r = optimize(p, o);
  SCOPED_TRACE(r.brief_report() + " | " + r.message + " | " + r.optimality);
  ASSERT_EQ(r.termination, Termination::kConverged);
  EXPECT_TRUE(r.global);
  EXPECT_NEAR(r.objective, 1.0, 1e-9);
  EXPECT_LE(r.lower_bound, r.objective + 1e-12);
  EXPECT_GE(r.lower_bound, 1.0 - 1e-9);
  EXPECT_NEAR(core::total_mass(r.design) - core::total_mass(p.original), 0.0, 1e-9);
  // no design within the envelopes does better, by core's simulations and resolved peaks
  constexpr auto kF = core::Formulation::kMassMatrix;
  auto objective = [&](const core::FourBar& design) {
    const core::Trajectory run = core::simulate_driven(design, scene, {.formulation = kF});
    return core::metrics(design, scene, run, kF, nullptr).Fsh_max;
  };
  const double original = objective(p.original);
  const double mass = core::total_mass(p.original);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    const double scale = std::pow(10.0, -3.0 * (k % 4) / 3.0);  // 1 ... 1e-3 of the limits
    core::FourBar design = p.original;
    double added = 0;
    for (const CounterweightVariables& c : p.counterweights) {
      balance::Counterweight w;
      w.mass = scale * c.mass_max * 0.5 * (1 + u(rng));
      const Vec2 at(u(rng), u(rng));
      w.position = at / std::max(1.0, at.norm()) * c.distance_max;
      added += w.mass;
      core::Link& link = c.link == 1 ? design.crank : design.rocker;
      link = balance::merged(link, w, c.link == 3);
    }
    EXPECT_GE(objective(design) / original + 3 * added / mass, r.objective - 1e-9);
  }
}

// A counterweight the problem reads only by its mass moment takes the least mass for it: the
// shaking force of a driven linkage depends on the links' mass moments only (the momentum
// Σ m v_G), so for the least Fsh_rms each counterweight's mass and distance trade off freely, and
// SLSQP left both where its path stopped. Each is now moved out to its distance_max with the mass
// that keeps its moment. The referee: the least-squares minimiser of the samples' shaking force
// in the four mass moments (assemble(), an independent route), whose least mass at distance 1 m
// is |z_crank| + |z_rocker| kilograms.
TEST(Optimize, ACounterweightReadOnlyByItsMassMomentTakesTheLeastMass) {
  const DesignProblem p = counterweight_problem();
  const OptimizeResult r = optimize(p, OptimizeOptions{});
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  ASSERT_EQ(r.termination, Termination::kConverged);
  EXPECT_NE(r.message.find("is moved out to its distance_max"), std::string::npos);
  const Eigen::Vector4d z = minimiser(assemble(p.original, one_revolution()), 1e300);
  EXPECT_LT(relative(mass_moments(r), z), 1e-6) << mass_moments(r).transpose();
  ASSERT_EQ(r.counterweights.size(), 2u);
  for (const PlacedCounterweight& c : r.counterweights) {
    EXPECT_NEAR(c.counterweight.distance, 1.0, 1e-12) << c.link;  // distance_max
  }
  const double least = z.head<2>().norm() + z.tail<2>().norm();
  EXPECT_NEAR(core::total_mass(r.design) - core::total_mass(p.original), least, 1e-6 * least);
  // what the problem reads is the same: the objective is the closed form's
  EXPECT_LT(r.verification_error, 1e-9);
}

// A counterweight that changes nothing the problem reads is left out: the crank turns at constant
// speed about A0, the origin, so a crank counterweight's centripetal force passes through the
// moment's reference point and changes no shaking moment, and no other link's motion (driven).
// The solver left it where its start put it (half its mass_max at half its distance_max: 5 kg of
// no use); the result now has none, and says so. Checked by core's own simulations: the design
// with that counterweight has the same RMS shaking moment as without it.
TEST(Optimize, ACounterweightThatChangesNothingIsLeftOut) {
  DesignProblem p = counterweight_problem();
  p.objective = {Term{Metric::kMshRms, 1.0}};
  const OptimizeResult r = optimize(p, OptimizeOptions{});
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.counterweights.size(), 2u);
  EXPECT_EQ(r.counterweights[0].link, 1);
  EXPECT_EQ(r.counterweights[0].counterweight.mass, 0.0);
  EXPECT_GT(r.counterweights[1].counterweight.mass, 0.1);  // the rocker's does the work
  EXPECT_EQ(r.design.crank.mass, p.original.crank.mass);
  EXPECT_NE(r.message.find("the crank counterweight changed nothing the problem reads "
                           "(objective and constraints the same without it) and is left out"),
            std::string::npos);
  // the start's crank counterweight added to the optimum changes its Msh_rms by round-off only
  core::FourBar with = r.design;
  with.crank = balance::merged(
      with.crank, balance::Counterweight{.mass = 5.0, .position = Vec2(-0.5, 0.0), .distance = 0.5},
      false);
  const core::SimulateOptions simulate{.formulation = core::Formulation::kMassMatrix};
  const double without_it =
      core::metrics(core::simulate_driven(r.design, one_revolution(), simulate)).Msh_rms;
  const double with_it =
      core::metrics(core::simulate_driven(with, one_revolution(), simulate)).Msh_rms;
  EXPECT_NEAR(with_it, without_it, 1e-12 * without_it);
  EXPECT_GT(with.crank.mass, r.design.crank.mass + 4.9);
}

// A minimax optimum: the shaking moment's peak under the budget, which the counterweights trade
// between its local maxima until they are equal. The exchange rounds' grids of added angles make
// their rows nearly equal constraints, at which the first-order conditions are degenerate (met
// to ~1e-2: not certified, and the bound's refining runs took seconds); the result is the lean
// program's at that design, the samples and one angle per peak, whose conditions are regular.
TEST(Optimize, AMinimaxOptimumOfResolvedPeaksIsCertified) {
  constexpr auto kF = core::Formulation::kMassMatrix;
  double M = 0;
  DesignProblem p = budget_peak_problem(&M);
  p.objective = {Term{Metric::kMshMax, 1.0}};
  const core::DrivenScene coarse = std::get<core::DrivenScene>(p.scene);
  DesignProblem fine = p;
  core::DrivenScene fine_scene = coarse;
  fine_scene.samples = 360;
  fine.scene = fine_scene;
  const OptimizeResult rf = optimize(fine, OptimizeOptions{});
  ASSERT_TRUE(rf.ok()) << rf.message;
  const double original = Nlp(p).original(Metric::kMshMax);  // resolved
  for (const Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt}) {
    OptimizeOptions o;
    o.algorithm = a;
    const OptimizeResult r = optimize(p, o);
    SCOPED_TRACE(r.brief_report() + " | " + r.message + " | " + r.optimality);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.termination, Termination::kConverged);
    EXPECT_TRUE(r.global);
    // one angle per peak, not the grids (near two hundred)
    EXPECT_GE(r.peak_angles.size(), 1u);
    EXPECT_LE(r.peak_angles.size(), 6u);
    EXPECT_EQ(r.message.find("still rose above its bound"), std::string::npos);
    // the lower bound meets the objective (which may dip below it by the constraint
    // violation the solvers leave, ~1e-9 of t)
    EXPECT_LE(std::abs(r.objective - r.lower_bound), 1e-8);
    // the peak bounded is the design's resolved peak (core's search between the samples), to
    // the exchange's tolerance: 1e-9 of the original's peak
    const core::Trajectory run = core::simulate_driven(r.design, coarse, {.formulation = kF});
    ASSERT_TRUE(run.ok()) << run.message;
    const core::Metrics resolved = core::metrics(r.design, coarse, run, kF, nullptr);
    EXPECT_NEAR(r.metrics.Msh_max, resolved.Msh_max, 1e-9 * original);
    // 360 samples: the same optimum (to the exchange's tolerance, 1e-9 of the original's peak)
    EXPECT_NEAR(r.objective, rf.objective, 3e-9);
  }
}

// The exchange rounds share the evaluation budget: a budget the first solve spends leaves the
// peaks bounded at the samples, and the message says so.
TEST(Optimize, ExchangeRoundsShareTheEvaluationBudget) {
  double M = 0;
  const DesignProblem p = budget_peak_problem(&M);
  OptimizeOptions o;
  o.algorithm = Algorithm::kCobyla;
  o.max_evaluations = 100;
  const OptimizeResult r = optimize(p, o);
  EXPECT_LE(r.evaluations, 100);
  EXPECT_TRUE(r.peak_angles.empty());
  EXPECT_NE(r.message.find("the evaluation budget was spent before every resolved peak was "
                           "bounded (the peaks are bounded at the samples only)"),
            std::string::npos)
      << r.message;
}

// A peak the optimum makes vanish (full force balance within reach: Fsh_max -> 0) ends the
// exchange: its excess is measured against the original's peak, the objective's unit. Measured
// against the bounded peak itself (round-off at a balanced design) a user's run added 512 angles
// over 9 solves and stopped short after 21 s.
TEST(Optimize, AVanishingPeakEndsTheExchange) {
  const DesignProblem p = coarse_peak_problem();  // no budget: full force balance reachable
  const OptimizeResult r = optimize(p, OptimizeOptions{});
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.termination, Termination::kConverged);
  const Nlp nlp(p);
  EXPECT_LE(r.metrics.Fsh_max, 1e-6 * nlp.original(Metric::kFshMax));
  EXPECT_EQ(r.message.find("still rose above its bound"), std::string::npos);
  // each added angle once
  std::vector<double> angles = r.peak_angles;
  std::sort(angles.begin(), angles.end());
  EXPECT_EQ(std::adjacent_find(angles.begin(), angles.end()), angles.end());
}

// What is convex and what is not, decided from the regressor: the shaking force reads only the
// masses and first moments; the shaking moment and the support reactions read the rocker's
// inertia about A3 (its moment equation gives the pin forces), which varies with the square of
// its counterweight's position; no metric reads the crank's, as the crank turns at a constant
// rate (its angular acceleration, the factor of its inertia, is zero). A problem that is not
// convex says why and is never called global.
TEST(Optimize, WhatIsConvexIsDecidedFromTheMetricsItReads) {
  DesignProblem p = counterweight_problem();
  EXPECT_EQ(Nlp(p).why_not_convex(), "");
  // a limit counts as the objective does
  p.limits = {Limit{Metric::kMshMax, 2.0}};
  EXPECT_EQ(Nlp(p).why_not_convex(),
            "Msh_max depends on the rocker's inertia about A3, which varies with the square of its "
            "counterweight's position");
  p.limits.clear();
  p.objective = {Term{Metric::kRA0Rms, 1.0}};
  EXPECT_EQ(Nlp(p).why_not_convex(),
            "RA0_rms depends on the rocker's inertia about A3, which varies with the square of its "
            "counterweight's position");
  p.objective = {Term{Metric::kMshRms, 1.0}, Term{Metric::kTauMax, 1.0}};
  p.counterweights.pop_back();  // the crank's alone
  EXPECT_EQ(Nlp(p).why_not_convex(), "");
  // a link's own mass alone keeps it affine; with its e as well, its first moments are not
  p = counterweight_problem();
  p.counterweights.clear();
  p.link_parameters = {LinkParameterVariable{.link = 2,
                                             .parameter = LinkParameterVariable::Parameter::kMass,
                                             .lower = 1.0,
                                             .upper = 5.0}};
  EXPECT_EQ(Nlp(p).why_not_convex(), "");
  p.link_parameters.push_back(LinkParameterVariable{
      .link = 2, .parameter = LinkParameterVariable::Parameter::kE, .lower = 0.5, .upper = 2.0});
  EXPECT_EQ(Nlp(p).why_not_convex(),
            "Fsh_rms depends on the coupler's first moments, its mass times e or f, both varied");
  // which no relaxation of the counterweights' inertias mends: no lower bound, and why
  {
    const OptimizeResult r = optimize(p, OptimizeOptions{});
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_FALSE(r.global);
    EXPECT_TRUE(std::isnan(r.lower_bound));
    EXPECT_EQ(r.lower_bound_source,
              "no lower bound: even with the counterweights' inertias relaxed, Fsh_rms depends on "
              "the coupler's first moments, its mass times e or f, both varied");
  }
  // free scenes: never
  p = counterweight_problem();
  p.scene = core::FreeScene{.theta1 = 0.0, .omega1 = 6.0, .duration = 0.5, .samples = 21};
  p.objective = {Term{Metric::kFshRms, 1.0}};
  EXPECT_NE(Nlp(p).why_not_convex().find("free scene"), std::string::npos);

  // the result of a problem that is not convex says so, and why; this one's convex relaxation
  // (NonConvexProblemsGetALowerBoundThatNoDesignBeats) meets its optimum, which proves it global
  // to that, in words that still say why the problem is not convex
  p = counterweight_problem();
  p.objective = {Term{Metric::kMshRms, 1.0}};
  const OptimizeResult r = optimize(p, OptimizeOptions{});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_TRUE(r.global);
  EXPECT_EQ(r.optimality.rfind("global to within ", 0), 0u) << r.optimality;
  EXPECT_NE(r.optimality.find("the problem is not convex (Msh_rms depends on the rocker's inertia"),
            std::string::npos)
      << r.optimality;
}

// The lower bound of a problem that is not convex (issue 15, item 2): the shaking moment and the
// drive torque read the rocker's inertia about A3, m |r|² of its counterweight (and a disc's own
// m² / (2 π ρ t)). The bound comes from the convex relaxation that lets those inertias take any
// value their counterweight's mass and mass moment allow. Checked against the engine's own
// simulations of real designs (core::simulate_driven with the counterweights merged, another
// formulation than the optimiser's regressor): no design within the budget, random or near the
// optimum, has an objective below the bound, and the optimum found lies at or above it.
TEST(Optimize, NonConvexProblemsGetALowerBoundThatNoDesignBeats) {
  struct BoundCase {
    const char* name;
    std::vector<Term> objective;
    balance::CounterweightShape shape;
  };
  const BoundCase cases[] = {
      {"Msh_rms", {Term{Metric::kMshRms, 1.0}}, balance::CounterweightShape::kPoint},
      {"tau_rms + Fsh_rms", {Term{Metric::kTauRms, 1.0}, Term{Metric::kFshRms, 1.0}},
       balance::CounterweightShape::kPoint},
      {"Msh_rms, discs", {Term{Metric::kMshRms, 1.0}}, balance::CounterweightShape::kDisc},
      {"tau_rms", {Term{Metric::kTauRms, 1.0}}, balance::CounterweightShape::kPoint},
      {"RA0_rms", {Term{Metric::kRA0Rms, 1.0}}, balance::CounterweightShape::kPoint},
      {"RA3_max", {Term{Metric::kRA3Max, 1.0}}, balance::CounterweightShape::kPoint},
      {"Msh_max + tau_max", {Term{Metric::kMshMax, 1.0}, Term{Metric::kTauMax, 1.0}},
       balance::CounterweightShape::kPoint},
      {"RA3_rms, discs", {Term{Metric::kRA3Rms, 1.0}}, balance::CounterweightShape::kDisc},
  };
  const core::SimulateOptions simulate{.formulation = core::Formulation::kMassMatrix};
  for (const BoundCase& k : cases) {
    SCOPED_TRACE(k.name);
    DesignProblem p = counterweight_problem(2.0, 2.0);
    p.objective = k.objective;
    for (CounterweightVariables& c : p.counterweights) {
      c.shape = k.shape;
      c.density = 7800;
      c.thickness = 0.02;
    }
    const double budget = 1.0;  // kg
    p.limits = {Limit{Metric::kAddedMass, budget}};
    const OptimizeResult r = optimize(p, OptimizeOptions{});
    SCOPED_TRACE(r.brief_report() + " | " + r.optimality + " | " + r.lower_bound_source);
    ASSERT_TRUE(r.ok());
    ASSERT_TRUE(std::isfinite(r.lower_bound));
    EXPECT_EQ(r.lower_bound_source.rfind("from the convex relaxation", 0), 0u);
    // (a design may exceed a limit by the constraint tolerance, 1e-9 scaled, and gain as much)
    const double slack = 1e-8 * std::max(1.0, r.objective);
    EXPECT_LE(r.lower_bound, r.objective + slack);

    // the objective of a real design, from the engine's simulation (the linear form's smoothed
    // ratios to the original's values), its peaks resolved between the samples as the optimiser
    // bounds them (resolve_peaks, the default)
    const core::Metrics original = core::metrics(
        p.original, one_revolution(), core::simulate_driven(p.original, one_revolution(), simulate),
        simulate.formulation, nullptr);
    auto objective = [&](const std::array<balance::Counterweight, 2>& w) {
      core::FourBar m = p.original;
      m.crank = balance::merged(m.crank, w[0], false);
      m.rocker = balance::merged(m.rocker, w[1], true);
      const core::Trajectory t = core::simulate_driven(m, one_revolution(), simulate);
      EXPECT_TRUE(t.ok()) << t.message;
      const core::Metrics got =
          core::metrics(m, one_revolution(), t, simulate.formulation, nullptr);
      double f = 0;
      for (const Term& term : p.objective) {
        const double ratio = value(got, term.metric) / value(original, term.metric);
        f += term.weight * std::sqrt(ratio * ratio + p.smoothing * p.smoothing);
      }
      return f;
    };
    auto counterweight = [&](double mass, const Vec2& at) {
      balance::Counterweight w{.mass = mass, .position = at, .distance = at.norm()};
      if (k.shape == balance::CounterweightShape::kDisc) {
        w.thickness = 0.02;
        w.radius = std::sqrt(mass / (7800 * std::numbers::pi * 0.02));
        w.inertia = 0.5 * mass * w.radius * w.radius;
      }
      return w;
    };
    // the optimum as simulated
    std::array<balance::Counterweight, 2> best;
    for (const PlacedCounterweight& c : r.counterweights) best[c.link == 1 ? 0 : 1] = c.counterweight;
    const double found = objective(best);
    EXPECT_NEAR(found, r.objective, 1e-9 * r.objective);
    EXPECT_LE(r.lower_bound, found + slack);

    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> n(0.0, 1.0);
    double least = HUGE_VAL;
    for (int trial = 0; trial < 300; ++trial) {
      std::array<balance::Counterweight, 2> w;
      if (trial % 2 == 0) {  // anywhere within the budget and the envelopes
        const double m1 = budget * u(rng), m2 = (budget - m1) * u(rng);
        const double masses[2] = {m1, m2};
        for (int i = 0; i < 2; ++i) {
          const double radius = std::sqrt(u(rng)), angle = 2 * std::numbers::pi * u(rng);
          w[i] = counterweight(masses[i], radius * Vec2(std::cos(angle), std::sin(angle)));
        }
      } else {  // near the optimum, back within the budget and the envelopes
        const double scale = std::pow(10.0, -1.0 - 3.0 * u(rng));
        double masses[2];
        Vec2 at[2];
        for (int i = 0; i < 2; ++i) {
          masses[i] = std::max(0.0, best[i].mass + scale * n(rng));
          at[i] = best[i].position + scale * Vec2(n(rng), n(rng));
          if (at[i].norm() > 1.0) at[i] /= at[i].norm();
        }
        const double total = masses[0] + masses[1];
        for (int i = 0; i < 2; ++i) {
          w[i] = counterweight(total > budget ? masses[i] * budget / total : masses[i], at[i]);
        }
      }
      const double f = objective(w);
      least = std::min(least, f);
      EXPECT_GE(f, r.lower_bound) << trial;
    }
    // where the bound meets the optimum (to 1e-6), the optimum is global: said so, and no trial
    // beats it
    if (r.objective - r.lower_bound <= 1e-6 * std::max(1.0, r.objective)) {
      EXPECT_TRUE(r.global);
      EXPECT_EQ(r.optimality.rfind("global to within ", 0), 0u);
      EXPECT_LE(found, least * (1 + 1e-9));
      continue;
    }
    // where it does not (a disc on the rocker against RA3_rms: a small mass anywhere makes the
    // rocker's pin force worse, a larger one better, so SLSQP stays at no counterweight, 1.0,
    // while trials find 0.966 and the bound is 0.949), the result is not called global, and the
    // multistart finds a better design, above the bound, and says how many starts reached it
    EXPECT_FALSE(r.global);
    EXPECT_EQ(r.optimality.rfind("not proven global: ", 0), 0u);
    EXPECT_STREQ(k.name, "RA3_rms, discs");
    EXPECT_GT(r.objective - r.lower_bound, 0.01);
    OptimizeOptions multistart;
    multistart.algorithm = Algorithm::kMlsl;
    const OptimizeResult m = optimize(p, multistart);
    SCOPED_TRACE("mlsl: " + m.brief_report() + " | " + m.message);
    ASSERT_TRUE(m.ok());
    EXPECT_LT(m.objective, least);
    EXPECT_GE(m.objective, r.lower_bound);
    EXPECT_LE(m.lower_bound, m.objective);
    EXPECT_GT(m.lower_bound, 0.9) << "the relaxation's bound from the multistart's design";
    EXPECT_EQ(m.starts, 8);
    EXPECT_GE(m.starts_at_best, 1);
    EXPECT_LE(m.starts_at_best, m.starts);
    EXPECT_NE(m.message.find(std::to_string(m.starts_at_best) + " reaching the best value"),
              std::string::npos);
  }
}

// A multistart's local runs each depend on their index alone: computed by a StartPool in reverse
// order on another thread (as an MPI job's ranks compute them, in any order, elsewhere) they give
// the very bits of the runs made one after the other here; each start is asked for once, each
// run keeps to its share of the budget, and the count of starts at the best value is the
// runs' own.
TEST(Optimize, MultistartGivesTheSameBitsWhereverItsRunsAreComputed) {
  class ReversedPool final : public StartPool {
   public:
    std::vector<LocalRun> run_all(int count, const std::function<LocalRun(int)>& run) override {
      std::vector<LocalRun> runs(static_cast<std::size_t>(count));
      std::thread([&] {
        for (int i = count - 1; i >= 0; --i) {
          runs[static_cast<std::size_t>(i)] = run(i);
          asked.push_back(i);
        }
      }).join();
      seen = runs;
      return runs;
    }
    std::vector<int> asked;
    std::vector<LocalRun> seen;
  };
  DesignProblem p = counterweight_problem(1.0, 10.0);
  p.objective = {Term{Metric::kMshRms, 1.0}, Term{Metric::kTauMax, 0.5}};
  OptimizeOptions o = options_for(Algorithm::kMlsl);
  o.max_evaluations = 1003;
  o.starts = 5;
  {
    // the peaks resolved (the default): a multistart in each exchange round, the same bits
    const OptimizeResult here = optimize(p, o);
    ReversedPool pool;
    OptimizeOptions elsewhere = o;
    elsewhere.start_pool = &pool;
    const OptimizeResult there = optimize(p, elsewhere);
    ASSERT_TRUE(here.ok()) << here.message;
    EXPECT_GT(pool.asked.size(), 5u) << "more than one round";
    ASSERT_EQ(here.x.size(), there.x.size());
    for (Eigen::Index i = 0; i < here.x.size(); ++i) EXPECT_EQ(here.x[i], there.x[i]) << i;
    EXPECT_EQ(here.objective, there.objective);
    EXPECT_EQ(here.message, there.message);
    EXPECT_EQ(here.evaluations, there.evaluations);
  }
  // the samples' peaks: one multistart, whose runs are counted below
  p.resolve_peaks = false;
  const OptimizeResult here = optimize(p, o);
  ReversedPool pool;
  o.start_pool = &pool;
  const OptimizeResult there = optimize(p, o);
  SCOPED_TRACE(here.brief_report() + " | " + here.message);
  ASSERT_TRUE(here.ok());
  EXPECT_EQ(pool.asked, (std::vector<int>{4, 3, 2, 1, 0}));
  ASSERT_EQ(here.x.size(), there.x.size());
  for (Eigen::Index i = 0; i < here.x.size(); ++i) EXPECT_EQ(here.x[i], there.x[i]) << i;
  EXPECT_EQ(here.objective, there.objective);
  EXPECT_EQ(here.message, there.message);
  EXPECT_EQ(here.evaluations, there.evaluations);
  EXPECT_EQ(here.starts, 5);
  EXPECT_EQ(there.starts, 5);
  EXPECT_EQ(here.starts_at_best, there.starts_at_best);
  // 1003 evaluations over 5 starts: 201, 201, 201, 200, 200, whatever each run spends
  int spent = 0, at_best = 0;
  double best = HUGE_VAL;
  for (const LocalRun& r : pool.seen) {
    if (r.violation <= o.constraint_tolerance) best = std::min(best, r.objective);
  }
  for (std::size_t s = 0; s < pool.seen.size(); ++s) {
    const LocalRun& r = pool.seen[s];
    EXPECT_LE(r.evaluations, s < 3 ? 201 : 200) << s;
    spent += r.evaluations;
    if (r.violation <= o.constraint_tolerance && r.objective <= best + 1e-6 * std::max(best, 1.0))
      ++at_best;
  }
  EXPECT_LE(spent, here.evaluations);  // the multistart's, and any continuation after it
  EXPECT_EQ(here.starts_at_best, at_best);
  EXPECT_GE(at_best, 1);
  EXPECT_NE(here.message.find(std::to_string(at_best) + " reaching the best value"),
            std::string::npos);
  // the objective reported is the best run's (the continuation after it can only improve it)
  EXPECT_LE(here.objective, best * (1 + 1e-12));

  // more starts than evaluations: refused, naming the field
  o.starts = 2000;
  o.max_evaluations = 1000;
  const bd::Problem e = o.validate();
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field, "starts");
}

// The relaxation itself: at a real design (its inertias at their real values) the relaxed
// program's objective and constraints are the real program's, the design meets the relaxation's
// own rows, and its derivatives agree with central differences.
TEST(Optimize, TheRelaxationHoldsEveryRealDesign) {
  DesignProblem p = counterweight_problem(2.0, 2.0);
  p.objective = {Term{Metric::kMshRms, 1.0}, Term{Metric::kTauMax, 0.5}};
  p.counterweights[1].shape = balance::CounterweightShape::kDisc;
  p.counterweights[1].density = 7800;
  p.counterweights[1].thickness = 0.02;
  p.limits = {Limit{Metric::kAddedMass, 1.0}, Limit{Metric::kRA3Max, 3.0}};
  const Nlp real(p), relaxed(p, CounterweightVariablesAs::kRelaxation);
  EXPECT_EQ(relaxed.why_not_convex(), "");
  EXPECT_NE(real.why_not_convex(), "");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd x = real.start();
    x(0) = 0.5 + 0.4 * u(rng);
    x(1) = 0.6 * u(rng);
    x(2) = 0.6 * u(rng);
    x(3) = 0.5 + 0.4 * u(rng);
    x(4) = 0.6 * u(rng);
    x(5) = 0.6 * u(rng);
    x = real.start_at(x);
    const Eigen::VectorXd z = relaxed.start_at(relaxed.from_positions(x));
    EXPECT_NEAR(relaxed.objective(z, nullptr), real.objective(x, nullptr),
                1e-12 * real.objective(x, nullptr));
    Eigen::VectorXd c_real, c_relaxed;
    real.inequalities(x, c_real, nullptr);
    relaxed.inequalities(z, c_relaxed, nullptr);
    // the relaxation's rows: the limits as the real ones, its own rows met (to round-off)
    for (int i = 0; i < c_relaxed.size(); ++i) {
      const std::string& name = relaxed.constraint_names()[static_cast<std::size_t>(i + relaxed.n_eq())];
      if (name.find("(relaxed)") != std::string::npos || name.find("pro rata") != std::string::npos ||
          name.find("distance_max²") != std::string::npos) {
        EXPECT_LE(c_relaxed(i), 1e-12) << name;
      }
    }
    EXPECT_NEAR(relaxed.metric(z, Metric::kRA3Max), real.metric(x, Metric::kRA3Max),
                1e-12 * real.metric(x, Metric::kRA3Max));
    // derivatives against central differences
    Eigen::VectorXd g;
    relaxed.objective(z, &g);
    Eigen::MatrixXd jac;
    Eigen::VectorXd c;
    relaxed.inequalities(z, c, &jac);
    for (int j = 0; j < relaxed.n(); ++j) {
      const double h = 1e-6 * std::max(1.0, std::abs(z(j)));
      Eigen::VectorXd a = z, b = z;
      a(j) += h;
      b(j) -= h;
      const double fd = (relaxed.objective(a, nullptr) - relaxed.objective(b, nullptr)) / (2 * h);
      EXPECT_NEAR(g(j), fd, 1e-6 * std::max(1.0, std::abs(fd))) << relaxed.variable_names()[static_cast<std::size_t>(j)];
      Eigen::VectorXd ca, cb;
      relaxed.inequalities(a, ca, nullptr);
      relaxed.inequalities(b, cb, nullptr);
      const Eigen::VectorXd dc = (ca - cb) / (2 * h);
      EXPECT_LE((jac.col(j) - dc).cwiseAbs().maxCoeff(), 1e-5 * std::max(1.0, dc.cwiseAbs().maxCoeff()))
          << relaxed.variable_names()[static_cast<std::size_t>(j)];
    }
  }
}

// the check itself: from the natural start (half of mass_max, outside a small budget) MMA alone
// stopped at 0.96 of the original, 1.2 x the optimum, and said it had converged; the
// first-order check sees that and the run goes on to the optimum
TEST(Optimize, AConvergedEndIsCheckedAgainstTheFirstOrderConditions) {
  DesignProblem p = counterweight_problem();
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d full = minimiser(ls, 1e300);
  const double M = 0.3 * (full.head<2>().norm() + full.tail<2>().norm());
  p.limits = {Limit{Metric::kAddedMass, M}};
  const Nlp nlp(p);
  OptimizeOptions o;
  o.algorithm = Algorithm::kMma;
  const detail::Solved s = detail::solve(nlp, nlp.start(), o);
  SCOPED_TRACE(s.message);
  // MMA's own end is the one the check refused: the run went on from there
  EXPECT_NE(s.message.find("the first-order conditions held to"), std::string::npos);
  const Eigen::Vector4d z = budget_minimiser(ls, Eigen::Vector2d(1.0, 1.0), M);
  ASSERT_TRUE(found_design(s.termination));
  if (s.termination == Termination::kConverged) {
    EXPECT_LE(s.stationarity, detail::stationarity_tolerance(o.relative_tolerance));
    EXPECT_NEAR(nlp.metric(s.x, Metric::kFshRms), ls.rms(z), 1e-6 * std::sqrt(ls.c));
  }
  // at the original design (no counterweight mass) more mass lowers the objective: the
  // residual is far from 0 there
  EXPECT_GT(detail::stationarity_residual(nlp, nlp.start(true)), 1e-2);
}

// The budget of the optimisation benchmark (docs/performance.md, "A budget that rules out full
// balance"): 2 kg, a third of what full balance needs. The whole budget goes to the crank, the
// rocker's counterweight vanishes at the optimum: the apex of its cone, where the cone has no
// gradient. SLSQP and MMA used to end there with its mass moment pointing in a direction of
// round-off, meeting the first-order conditions to 0.56 only, and some 400 evaluations of slsqp
// and ipopt continuations (most of a second) settled it as a degenerate optimum with a lower
// bound 4e-8 below. Now the vanishing counterweight is put on the apex and the rest solved again
// with it held there: the rocker gets exactly no counterweight, the design is the independent
// optimum, proven global, and the bound meets it to round-off.
TEST(Optimize, AVanishingCounterweightIsPutOnItsApexAndTheBoundMeetsTheOptimum) {
  DesignProblem p = counterweight_problem();
  const double M = 2.0;
  p.limits = {Limit{Metric::kAddedMass, M}};
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d z = budget_minimiser(ls, Eigen::Vector2d(1.0, 1.0), M);
  ASSERT_EQ(z.tail<2>().norm(), 0.0) << "the independent optimum has no rocker counterweight";
  const double original = std::sqrt(ls.c);
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt}) {
    OptimizeOptions o;
    o.algorithm = a;
    const OptimizeResult r = optimize(p, o);
    SCOPED_TRACE(std::string(to_string(a)) + " | " + r.brief_report() + " | " + r.message);
    EXPECT_EQ(r.termination, Termination::kConverged);
    EXPECT_TRUE(r.global) << r.optimality;
    EXPECT_NEAR(r.metrics.Fsh_rms, ls.rms(z), 1e-9 * original);
    EXPECT_LT(relative(mass_moments(r), z), 1e-6) << mass_moments(r).transpose();
    if (a != Algorithm::kIpopt) {  // an interior point stays inside, 1e-9 from the apex
      EXPECT_EQ(mass_moments(r).tail<2>().norm(), 0.0);
    }
    // the bound: below the objective, and within 1e-9 of it (before: 4e-8)
    EXPECT_LE(r.lower_bound, r.objective);
    EXPECT_GT(r.lower_bound, r.objective - 1e-9 * std::max(1.0, r.objective));
  }
}

// newton_polish() on a program with a known optimum: a convex quadratic on a disc,
// f = (x - 2)² + 10 (y - 1)² + x y, x² + y² <= 1, whose minimum lies on the circle (the
// unconstrained one is outside). The reference: the angle where f's derivative along the circle
// vanishes, by bisection of that derivative (an independent route); the polish starts 1e-4
// along the circle from it, where the first-order conditions hold to ~1e-5 only.
class DiscQuadratic final : public Program {
 public:
  int n() const override { return 2; }
  int n_eq() const override { return 0; }
  int n_ineq() const override { return 1; }
  const Eigen::VectorXd& lower() const override { return lower_; }
  const Eigen::VectorXd& upper() const override { return upper_; }
  const std::vector<std::string>& variable_names() const override { return names_; }
  const std::vector<std::string>& constraint_names() const override { return constraints_; }
  bool has_gradients() const override { return true; }
  double objective(const Eigen::VectorXd& x, Eigen::VectorXd* g) const override {
    if (g != nullptr) {
      *g = Eigen::Vector2d(2 * (x[0] - 2) + x[1], 20 * (x[1] - 1) + x[0]);
    }
    return (x[0] - 2) * (x[0] - 2) + 10 * (x[1] - 1) * (x[1] - 1) + x[0] * x[1];
  }
  void equalities(const Eigen::VectorXd&, Eigen::VectorXd& c, Eigen::MatrixXd* j) const override {
    c.resize(0);
    if (j != nullptr) j->resize(0, 2);
  }
  void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                    Eigen::MatrixXd* j) const override {
    c = Eigen::VectorXd::Constant(1, x.squaredNorm() - 1);
    if (j != nullptr) *j = 2 * x.transpose();
  }

 private:
  Eigen::VectorXd lower_ = Eigen::Vector2d(-5, -5), upper_ = Eigen::Vector2d(5, 5);
  std::vector<std::string> names_{"x", "y"}, constraints_{"disc"};
};

TEST(Optimize, NewtonPolishTakesANearlyStationaryPointToTheOptimum) {
  const DiscQuadratic program;
  // d f(cos a, sin a) / da, bisected on a bracket of the minimum (f along the circle is smooth)
  const auto slope = [&](double a) {
    Eigen::VectorXd g;
    program.objective(Eigen::Vector2d(std::cos(a), std::sin(a)), &g);
    return -g[0] * std::sin(a) + g[1] * std::cos(a);
  };
  double lo = 0.0, hi = 0.5 * std::numbers::pi;
  ASSERT_LT(slope(lo), 0.0);
  ASSERT_GT(slope(hi), 0.0);
  for (int k = 0; k < 200; ++k) (slope(0.5 * (lo + hi)) < 0 ? lo : hi) = 0.5 * (lo + hi);
  const double a = 0.5 * (lo + hi);
  const Eigen::Vector2d optimum(std::cos(a), std::sin(a));
  const Eigen::VectorXd start = Eigen::Vector2d(std::cos(a + 1e-4), std::sin(a + 1e-4));
  const double before = detail::stationarity_residual(program, start);
  ASSERT_GT(before, 1e-6);
  const Eigen::VectorXd x = detail::newton_polish(program, start, 1e-9);
  EXPECT_LT(detail::stationarity_residual(program, x), 1e-12);
  EXPECT_LT((x - optimum).norm(), 1e-10) << x.transpose() << " vs " << optimum.transpose();
  EXPECT_LE(detail::constraint_violation(program, x), 1e-9);
  // the Lagrangian bound there meets the optimum's value (a convex program)
  const double f = program.objective(optimum, nullptr);
  EXPECT_NEAR(detail::first_order(program, x).lower_bound, f, 1e-9);
  EXPECT_LE(detail::first_order(program, x).lower_bound, f + 1e-12);
}

// The peak of the shaking force alone, unbounded: the same force-balanced optimum (Fsh = 0 at
// every sample), now through the bound variable t and the constraints sqrt(|Fsh_i|² + δ²) <= t
// (linear in t: their gradient does not vanish at the optimum, where |Fsh_i|² <= t² has none).
// This is where the linear form stalled before: SLSQP stopped on ftol_rel after 12 evaluations
// at 0.35 of the original (a lower bound t >= 0 it kept landing on), Ipopt needed ~1000
// iterations, and MMA took from 22 s to over 10 minutes (its dual subproblem, one multiplier
// per sample, ran to NLopt's default budget; capped now). ISRES gets within ~10 % only: left
// out. Measured: moments within 1e-7 (SLSQP, mlsl) and 2e-9 (the others).
TEST(Optimize, PeakOptimumIsTheForceBalancedDesign) {
  DesignProblem p = counterweight_problem();
  p.objective = {Term{Metric::kFshMax, 1.0}};
  const LeastSquares ls = assemble(p.original, one_revolution());
  const Eigen::Vector4d z_ref = minimiser(ls, 1e300);
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt, Algorithm::kMma, Algorithm::kMlsl,
                      Algorithm::kCobyla}) {
    const OptimizeResult r = optimize(p, options_for(a));
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    // MMA (one conservative approximation per sample's row, in the mass-moment variables) can
    // spend the budget 3e-10 short of the optimum's objective: it says so (max evaluations)
    if (a == Algorithm::kMma && r.termination == Termination::kMaxEvaluations) {
      EXPECT_LT(relative(mass_moments(r), z_ref), 1e-6);
      EXPECT_NEAR(r.objective, kDefaultSmoothing, 1e-9);
      continue;
    }
    EXPECT_EQ(r.termination, Termination::kConverged);
    EXPECT_LT(relative(mass_moments(r), z_ref), 1e-6)
        << mass_moments(r).transpose() << " vs " << z_ref.transpose();
    // the objective t / original is the smoothed peak sqrt(r² + ε²) ~ ε, up to the constraint
    // tolerance (1e-10 of the original's peak on t)
    EXPECT_NEAR(r.objective, kDefaultSmoothing, 1e-9);
    EXPECT_LE(r.constraint_violation, 1e-9);
    EXPECT_LT(r.verification_error, 1e-9);
  }
}

// Three terms (the weighted-counterweights example on 72 samples): no term vanishes at the
// optimum, so the smoothing moves the objective by at most Σ w ε²/(2 r) ~ 1e-12. The value
// reported is Σ w metric/original of the re-simulated optimum, and every gradient method finds
// the same optimum.
DesignProblem weighted_problem() {
  DesignProblem p = counterweight_problem();
  p.counterweights[1].distance_max = 2.0;
  p.counterweights[1].shape = balance::CounterweightShape::kDisc;  // steel, 20 mm
  p.objective = {Term{Metric::kFshRms, 1.0}, Term{Metric::kMshRms, 1.0},
                 Term{Metric::kTauRms, 1.0}};
  return p;
}

// Σ w metric/original, and Σ w (metric/original)², of metrics m against the original's o
double weighted_sum(const DesignProblem& p, const core::Metrics& m, const core::Metrics& o,
                    bool squared = false) {
  const double r[] = {m.Fsh_rms / o.Fsh_rms, m.Msh_rms / o.Msh_rms, m.tau_rms / o.tau_rms};
  double f = 0;
  for (std::size_t i = 0; i < p.objective.size(); ++i) {
    f += p.objective[i].weight * (squared ? r[i] * r[i] : r[i]);
  }
  return f;
}

core::Metrics original_metrics(const DesignProblem& p) {
  const core::SimulateOptions simulate{.formulation = p.formulation};
  return core::metrics(core::simulate_driven(p.original, one_revolution(), simulate));
}

TEST(Optimize, ObjectiveIsTheWeightedSumOfTheVerifiedMetrics) {
  const DesignProblem p = weighted_problem();
  const core::Metrics o = original_metrics(p);
  std::vector<OptimizeResult> results;
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt, Algorithm::kMma, Algorithm::kMlsl}) {
    results.push_back(optimize(p, options_for(a)));
    const OptimizeResult& r = results.back();
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    EXPECT_EQ(r.termination, Termination::kConverged);
    ASSERT_LT(r.verification_error, 1e-9);
    // f <= reported <= f + ε Σ w, f from the re-simulated metrics (1e-9 of f for the
    // verification's round-off)
    const double f = weighted_sum(p, r.verified, o);
    EXPECT_GE(r.objective, f * (1 - 1e-9));
    EXPECT_LE(r.objective, f * (1 + 1e-9) + 3 * kDefaultSmoothing);
    // (measured: the reported value is f to ~1e-12)
    EXPECT_NEAR(r.objective, f, 1e-9 * f);
    EXPECT_LT(f, 3.0);  // better than the original
  }
  // one optimum: the linear sum agrees to 1e-8 (MMA, first order, stops ~2e-11 above SLSQP)
  for (const OptimizeResult& r : results) {
    EXPECT_NEAR(weighted_sum(p, r.metrics, o), weighted_sum(p, results[0].metrics, o),
                1e-8 * weighted_sum(p, results[0].metrics, o))
        << r.brief_report();
  }
}

// The linear sum and the sum of squares have different minimisers when there are several terms
// (the squares weigh a term's large ratio more): each optimum is better than the other in its
// own measure, by far more than the solver's tolerance (1e-10), and the designs differ. A
// default that slipped back to the squared form fails the first expectation.
TEST(Optimize, LinearAndSquaredFormsHaveDifferentOptima) {
  DesignProblem p = weighted_problem();
  const core::Metrics o = original_metrics(p);
  const OptimizeResult linear = optimize(p, options_for(Algorithm::kSlsqp));  // the default form
  p.objective_form = ObjectiveForm::kSquared;
  const OptimizeResult squared = optimize(p, options_for(Algorithm::kSlsqp));
  ASSERT_EQ(linear.termination, Termination::kConverged) << linear.message;
  ASSERT_EQ(squared.termination, Termination::kConverged) << squared.message;
  const double lin_at_lin = weighted_sum(p, linear.metrics, o);
  const double lin_at_sq = weighted_sum(p, squared.metrics, o);
  const double sq_at_lin = weighted_sum(p, linear.metrics, o, true);
  const double sq_at_sq = weighted_sum(p, squared.metrics, o, true);
  // measured (360 samples, the example): 1.94232 against 1.94479, and 1.49104 against 1.49367
  EXPECT_LT(lin_at_lin, lin_at_sq - 1e-4) << lin_at_lin << " vs " << lin_at_sq;
  EXPECT_LT(sq_at_sq, sq_at_lin - 1e-4) << sq_at_sq << " vs " << sq_at_lin;
  EXPECT_NEAR(linear.objective, lin_at_lin, 1e-9);
  EXPECT_NEAR(squared.objective, sq_at_sq, 1e-9);
  EXPECT_GT(relative(mass_moments(linear), mass_moments(squared)), 1e-2);
}

// ---------------------------------------------------------------------------------------------
// constraints: the Berkof–Lowen problem (force balance as equalities, least RMS shaking moment)

TEST(Optimize, ForceBalanceHoldsAtTheOptimumAndSolversAgree) {
  DesignProblem p = counterweight_problem();
  p.force_balance = true;
  p.objective = {Term{Metric::kMshRms, 1.0}};
  std::vector<OptimizeResult> results;
  // (isres is left out: an evolution strategy does not meet equalities to 1e-9; mma refuses
  // equalities, below)
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt, Algorithm::kMlsl, Algorithm::kCobyla}) {
    OptimizeOptions o = options_for(a);
    o.check_gradients = true;
    results.push_back(optimize(p, o));
    const OptimizeResult& r = results.back();
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    EXPECT_TRUE(r.ok());
    EXPECT_LE(r.constraint_violation, 1e-8);
    // the design is force balanced by the balance layer's own residuals, and by its simulation
    const balance::ForceBalanceResiduals res = balance::force_balance_residuals(r.design);
    const balance::ForceBalanceScales scales = balance::force_balance_scales(r.design);
    EXPECT_LT(std::abs(res.crank), 1e-8 * scales.crank);
    EXPECT_LT(std::abs(res.rocker), 1e-8 * scales.rocker);
    EXPECT_LT(r.verified.Fsh_rms, 1e-7 * r.verified.RA0_rms);
    EXPECT_LT(r.verification_error, 1e-9);
  }
  // the same optimum by every method (force balance increases the shaking moment: the
  // objective, Msh_rms / Msh_rms of the original, is ~3)
  for (const OptimizeResult& r : results) {
    EXPECT_NEAR(r.objective, results[0].objective, 1e-6 * results[0].objective)
        << r.brief_report() << " | " << r.message;
  }
}

TEST(Optimize, MmaRefusesEqualities) {
  DesignProblem p = counterweight_problem();
  p.force_balance = true;
  const Problem refused = check_algorithm(p, options_for(Algorithm::kMma));
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->field, "algorithm");
  EXPECT_FALSE(check_algorithm(p, options_for(Algorithm::kSlsqp)));
  try {
    (void)optimize(p, options_for(Algorithm::kMma));
    FAIL() << "mma accepted equality constraints";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "algorithm 'mma' takes inequality constraints only, and force_balance adds "
                 "equalities; use slsqp, ipopt, mlsl or cobyla");
  }
}

TEST(Optimize, InfeasibleSpecificationIsReportedWithTheBindingConstraint) {
  DesignProblem p = counterweight_problem(0.01, 0.01);  // 0.01 kg m where ~3 kg m are needed
  p.force_balance = true;
  p.objective = {Term{Metric::kMshRms, 1.0}};
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt, Algorithm::kCobyla}) {
    OptimizeOptions o = options_for(a);
    o.max_evaluations = 500;
    const OptimizeResult r = optimize(p, o);
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    EXPECT_EQ(r.termination, Termination::kInfeasible);
    EXPECT_FALSE(r.ok());
    EXPECT_GT(r.constraint_violation, 1e-3);
    EXPECT_NE(r.message.find("binding constraint is 'force balance"), std::string::npos);
    // in kg, the scaled violation times the original's total mass (six digits printed)
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.message, m,
                                  std::regex(R"(': the condition is off by (-?[0-9.e+-]+) kg \()")))
        << r.message;
    const double total = core::total_mass(core::make_fourbar(p.original));
    EXPECT_NEAR(std::abs(std::stod(m[1].str())), r.constraint_violation * total,
                1e-5 * r.constraint_violation * total);
  }
}

// ---------------------------------------------------------------------------------------------
// free scenes: simulations, derivative-free methods only

DesignProblem free_problem() {
  DesignProblem p = counterweight_problem();
  p.counterweights.resize(1);  // the crank's
  p.scene = core::FreeScene{.theta1 = 1.0, .omega1 = 3.0, .duration = 1.0, .samples = 51};
  p.tolerance = 1e-10;
  return p;
}

TEST(Optimize, FreeSceneWithCobylaRunsAndReports) {
  OptimizeOptions o;
  o.algorithm = Algorithm::kCobyla;
  o.max_evaluations = 60;
  const OptimizeResult r = optimize(free_problem(), o);
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  EXPECT_TRUE(r.ok());
  EXPECT_LE(r.evaluations, 61);
  EXPECT_LT(r.objective, 1.0);  // better than the original
  // two integrations at tolerance 1e-10 by two formulations
  EXPECT_LT(r.verification_error, 1e-6);
  EXPECT_NE(r.brief_report().find("cobyla"), std::string::npos);
}

TEST(Optimize, GradientMethodOnAFreeSceneNeedsTheReducedEquation) {
  const std::string opened =
      "' needs gradients, which a free scene on the opened loop (method opened-loop) does not "
      "provide; use cobyla or isres, or the method mass-matrix or complex-masses";
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kIpopt}) {
    OptimizeOptions o;
    o.algorithm = a;
    // the reduced equation has forward sensitivities (tests/optimize/free_nlp_test.cpp)
    EXPECT_FALSE(check_algorithm(free_problem(), o));
    // the opened loop's DAE has none: said without solving anything, in optimize()'s words
    DesignProblem p = free_problem();
    p.formulation = core::Formulation::kOpenedLoop;
    const Problem refused = check_algorithm(p, o);
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->field, "algorithm");
    EXPECT_EQ(refused->text(), std::string("algorithm '") + to_string(a) + opened);
    try {
      (void)optimize(p, o);
      FAIL() << "a gradient method on the opened loop's free scene was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("algorithm '") + to_string(a) + opened);
    }
  }
  // the words any linkage type's scene without gradients gets (the general planar linkage's:
  // tests/optimize/planar_free_test.cpp)
  OptimizeOptions o;
  o.algorithm = Algorithm::kSlsqp;
  const Problem refused = check_algorithm(o, "a free scene on the dae route", "", false);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->text(),
            "algorithm 'slsqp' needs gradients, which a free scene on the dae route does not "
            "provide; use cobyla or isres");
  EXPECT_FALSE(check_algorithm(o, "", "", false));
}

// ---------------------------------------------------------------------------------------------
// reporting

TEST(Optimize, BriefReportIsOneLineWithTheEssentials) {
  const OptimizeResult r =
      optimize(counterweight_problem(1.0, 10.0), options_for(Algorithm::kSlsqp));
  const std::string line = r.brief_report();
  EXPECT_EQ(line.find('\n'), std::string::npos);
  for (const char* part : {"slsqp", "converged", "iterations", "evaluations", " s,", "objective",
                           "constraint violation", "verified by mass-matrix"}) {
    EXPECT_NE(line.find(part), std::string::npos) << part << " in: " << line;
  }
  EXPECT_GT(r.seconds, 0.0);
}

TEST(Optimize, GradientCheckPassesOnAPeakObjective) {
  DesignProblem p = counterweight_problem(1.0, 10.0);
  p.objective = {Term{Metric::kFshMax, 1.0}, Term{Metric::kMshRms, 0.5}};
  OptimizeOptions o = options_for(Algorithm::kSlsqp);
  o.check_gradients = true;
  const OptimizeResult r = optimize(p, o);
  SCOPED_TRACE(r.brief_report() + " | " + r.message);
  EXPECT_EQ(r.message.find("gradient check failed"), std::string::npos);
  EXPECT_TRUE(r.ok());
  EXPECT_LT(r.verification_error, 1e-9);
}

}  // namespace
}  // namespace bd::optimize
