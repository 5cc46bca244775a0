// The complex-mass formulation (paper §4.1, eqs. 29-40) against the Newton–Euler referee and the
// mass-matrix formulation, its coefficients against independent checks (kinetic energy,
// Lagrange's convective terms, the paper's alternative lines), and the evidence for the
// misprints of eqs. 39 (Q3) and 40 (m3 δr̄3).
//
// Tolerances. All three solvers are exact; only round-off separates them: ~eps times a modest
// condition number (the worst measured here is ~1e-14 of the sample's size; RecordProperty
// "worst_relative" in the XML output). 1e-10 of the size leaves a wide margin while a formula
// error (a sign, a lever arm, a mass) shows at order one. Sizes as in dynamics_test: forces
// against max(1 N, |RA0|, |RA3|, |Fsh|), moments and torques against that times
// max(1 m, longest link), accelerations against max(1 rad/s^2, |alpha_k|).
#include "core/fourbar/complex_masses.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "core/detail/complex_vector.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/energy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/fourbar/samples.hpp"
#include "tests/reference/newton_euler.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/scales.hpp"

namespace bd::core {
namespace {

// the paper's complex notation for planar vectors
using detail::Complex;
using detail::to_complex;
using detail::to_vec;

using testing::acceleration_scale;
using testing::force_scale;
using testing::longest_link;
using testing::moment_scale;
using testing::other;
using testing::rate_scale;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRel = 1e-10;  // see the file comment
constexpr Complex kI{0.0, 1.0};

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
double inner(const Complex& x, const Complex& y) { return std::real(std::conj(x) * y); }
std::string where(const FourBar& m, double theta1, double omega1) {
  return "branch " + std::to_string(static_cast<int>(m.branch)) +
         ", theta1 = " + std::to_string(theta1) + ", omega1 = " + std::to_string(omega1);
}

// worst disagreement relative to each quantity's size, over all comparisons of one test
struct Worst {
  double value = 0.0;
  void add(double error, double scale) { value = std::max(value, error / scale); }
  std::string text() const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", value);
    return buf;
  }
};

// θ̈1..3, RA0, RA3, Fsh, Msh, tau of `got` against `ref`
void expect_matches(const FourBar& model, const DynamicsSample& got, const DynamicsSample& ref,
                    const std::string& at, Worst& worst) {
  const double F = force_scale(ref), M = moment_scale(model, ref), A = acceleration_scale(ref);
  const FourBarState &g = got.state, &r = ref.state;
  const double errors[] = {std::abs(g.alpha1 - r.alpha1) / A, std::abs(g.alpha2 - r.alpha2) / A,
                           std::abs(g.alpha3 - r.alpha3) / A, (got.RA0 - ref.RA0).norm() / F,
                           (got.RA3 - ref.RA3).norm() / F,    (got.Fsh - ref.Fsh).norm() / F,
                           std::abs(got.Msh - ref.Msh) / M,   std::abs(got.tau - ref.tau) / M};
  const char* names[] = {"alpha1", "alpha2", "alpha3", "RA0", "RA3", "Fsh", "Msh", "tau"};
  for (int i = 0; i < 8; ++i) {
    EXPECT_LT(errors[i], kRel) << at << ": " << names[i];
    worst.add(errors[i], 1.0);
  }
}

// forward and inverse dynamics against the referee and the mass-matrix formulation
void check_state(const FourBar& model, double theta1, double omega1, double alpha1, Worst& worst) {
  const std::string at = where(model, theta1, omega1);
  const auto fwd = forward_dynamics_complex_masses(model, theta1, omega1);
  ASSERT_TRUE(fwd.has_value()) << at << ": " << fwd.error().what();
  EXPECT_EQ(fwd->tau, 0.0) << at;
  expect_matches(model, *fwd, reference::newton_euler_forward(model, theta1, omega1),
                 at + " (forward vs Newton-Euler)", worst);
  expect_matches(model, *fwd, *forward_dynamics(model, theta1, omega1),
                 at + " (forward vs mass matrix)", worst);

  const auto inv = inverse_dynamics_complex_masses(model, theta1, omega1, alpha1);
  ASSERT_TRUE(inv.has_value()) << at << ": " << inv.error().what();
  EXPECT_EQ(inv->state.alpha1, alpha1) << at;
  expect_matches(model, *inv, reference::newton_euler_inverse(model, theta1, omega1, alpha1),
                 at + " (inverse vs Newton-Euler)", worst);
  expect_matches(model, *inv, *inverse_dynamics(model, theta1, omega1, alpha1),
                 at + " (inverse vs mass matrix)", worst);
}

// a random closed state of a model: angles, rates, accelerations
FourBarState random_state(const FourBar& model, std::mt19937_64& rng) {
  const auto pose = solve_position(model, uniform(rng, 0.0, kTwoPi));
  FourBarState s = solve_velocity(model, *pose, uniform(rng, -5, 5));
  return solve_acceleration(model, s, uniform(rng, -20, 20));
}

TEST(ComplexMasses, MatchesNewtonEulerAndMassMatrixOnRandomLinkages) {
  std::mt19937_64 rng(20240612);
  Worst worst;
  int plus = 0, minus = 0;
  for (int i = 0; i < 150; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    (model.branch == Branch::kPlus ? plus : minus)++;
    const double theta1 = uniform(rng, 0, kTwoPi), omega1 = uniform(rng, -5, 5),
                 alpha1 = uniform(rng, -20, 20);
    check_state(model, theta1, omega1, alpha1, worst);
    FourBar mirrored = model;  // a crank-rocker assembles on both branches
    mirrored.branch = other(model.branch);
    check_state(mirrored, theta1, omega1, alpha1, worst);
  }
  EXPECT_GT(plus, 0);
  EXPECT_GT(minus, 0);
  RecordProperty("worst_relative", worst.text());
}

TEST(ComplexMasses, MatchesNewtonEulerAndMassMatrixOnPaperFourBar) {
  Worst worst;
  for (Branch branch : {Branch::kPlus, Branch::kMinus}) {
    FourBar model = samples::paper_fourbar();
    model.branch = branch;
    for (int i = 0; i < 72; ++i) {
      const double theta1 = kTwoPi * i / 72.0;
      check_state(model, theta1, 2.0, -3.0, worst);
      check_state(model, theta1, -4.5, 11.0, worst);
    }
  }
  // and with gravity, which the paper's example leaves out
  FourBar heavy = samples::paper_fourbar();
  heavy.loads.gravity = Vec2(0.0, -9.81);
  for (int i = 0; i < 36; ++i) check_state(heavy, kTwoPi * i / 36.0, 3.0, 1.0, worst);
  RecordProperty("worst_relative", worst.text());
}

TEST(ComplexMasses, InverseAtForwardAccelerationNeedsNoTorque) {
  std::mt19937_64 rng(8);
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const double theta1 = uniform(rng, 0, kTwoPi), omega1 = uniform(rng, -5, 5);
    const auto fwd = forward_dynamics_complex_masses(model, theta1, omega1);
    ASSERT_TRUE(fwd.has_value());
    const auto inv = inverse_dynamics_complex_masses(model, theta1, omega1, fwd->state.alpha1);
    ASSERT_TRUE(inv.has_value());
    EXPECT_LT(std::abs(inv->tau), kRel * moment_scale(model, *fwd));
    EXPECT_LT((inv->RA0 - fwd->RA0).norm(), kRel * force_scale(*fwd));
    EXPECT_LT((inv->RA3 - fwd->RA3).norm(), kRel * force_scale(*fwd));
  }
}

// ---- eq. 37-39: the coefficients ----

TEST(ComplexMasses, MassMatrixIsSymmetricWithThePaperStructure) {
  std::mt19937_64 rng(31);
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const Pose pose = pose_of(random_state(model, rng));
    const Eigen::Matrix3d M = complex_mass_equations(model, pose).M;
    EXPECT_EQ(M(0, 2), M(2, 0));
    EXPECT_EQ(M(0, 1), 0.0);  // M12 = M21 = M23 = M32 = 0
    EXPECT_EQ(M(1, 0), 0.0);
    EXPECT_EQ(M(1, 2), 0.0);
    EXPECT_EQ(M(2, 1), 0.0);
    EXPECT_EQ(M(1, 1), model.coupler.inertia);
    // positive definite: it is the kinetic energy of the relaxed model (next test)
    EXPECT_GT(M.determinant(), 0.0);
    EXPECT_GT(M(0, 0), 0.0);
  }
}

// ½ θ̇ᵀ M θ̇ with θ̇ = (ω1, ω2, ω3) on a closed state is the kinetic energy computed link by link
// from the mass-centre velocities (core/fourbar/energy.hpp), which shares no code with eq. 37.
TEST(ComplexMasses, MassMatrixGivesTheKineticEnergy) {
  std::mt19937_64 rng(32);
  for (int i = 0; i < 200; ++i) {
    FourBar model = samples::random_crank_rocker(rng);
    if (i % 2 == 1) model.branch = other(model.branch);
    const FourBarState s = random_state(model, rng);
    const Eigen::Vector3d w(s.omega1, s.omega2, s.omega3);
    const double T = kinetic_energy(model, s);
    EXPECT_NEAR(0.5 * w.dot(complex_mass_equations(model, pose_of(s)).M * w), T, 1e-13 * T)
        << "linkage " << i;
  }
}

// The principal-vector lines of eq. 37 (M11, M33) and eq. 39 (Q1, Q3) against the simplified
// lines, and the cos/sin lines of M13 (eq. 37), C13 (eq. 38), Q1 and Q3 (eq. 39) as printed.
TEST(ComplexMasses, PaperAlternativeLinesAgree) {
  std::mt19937_64 rng(33);
  for (int i = 0; i < 200; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const Pose pose = pose_of(random_state(model, rng));
    const ComplexMassEquations eq = complex_mass_equations(model, pose);
    const PrincipalVectorForms pv = principal_vector_forms(model, pose);
    const double size_M = eq.M.norm();
    EXPECT_NEAR(pv.M11, eq.M(0, 0), 1e-13 * size_M) << "linkage " << i;
    EXPECT_NEAR(pv.M33, eq.M(2, 2), 1e-13 * size_M) << "linkage " << i;

    const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
    const EquivalentMasses e2 = equivalent_masses(L2);
    const double m2 = L2.mass, ma = e2.ma, mb = e2.mb, mc = e2.mc;
    const double l1 = L1.length, l3 = L3.length, d = pose.theta3 - pose.theta1;
    const double M13 = l1 * l3 * (mc * m2 * std::sin(d) - (ma * mb - mc * mc) * std::cos(d)) / m2;
    const double C13 = l1 * l3 * (mc * m2 * std::cos(d) + (ma * mb - mc * mc) * std::sin(d)) / m2;
    EXPECT_NEAR(eq.M(0, 2), M13, 1e-13 * size_M) << "linkage " << i;
    EXPECT_NEAR(eq.C13, C13, 1e-13 * size_M) << "linkage " << i;

    const Vec2 g = model.loads.gravity;
    const Vec2 F1 = model.loads.crank.force + L1.mass * g, F2 = model.loads.coupler.force + m2 * g,
               F3 = model.loads.rocker.force + L3.mass * g;
    const double s1 = L1.s(), sig1 = L1.sigma(), s3 = L3.s(), sig3 = L3.sigma();
    const double th1 = pose.theta1, th3 = pose.theta3;
    const double Q1 = model.loads.crank.moment - s1 * F1.x() * std::sin(th1 + sig1) +
                      s1 * F1.y() * std::cos(th1 + sig1) -
                      l1 * (ma * F2.x() - mc * F2.y()) * std::sin(th1) / m2 +
                      l1 * (ma * F2.y() + mc * F2.x()) * std::cos(th1) / m2;
    const double Q3 = model.loads.rocker.moment - s3 * F3.x() * std::sin(th3 + sig3) +
                      s3 * F3.y() * std::cos(th3 + sig3) +
                      l3 * (F3.x() + (mb * F2.x() + mc * F2.y()) / m2) * std::sin(th3) -
                      l3 * (F3.y() + (mb * F2.y() - mc * F2.x()) / m2) * std::cos(th3);
    const double size_Q = eq.Q.norm() + 1.0;
    EXPECT_NEAR(eq.Q(0), Q1, 1e-13 * size_Q) << "linkage " << i;
    EXPECT_NEAR(eq.Q(2), Q3, 1e-13 * size_Q) << "linkage " << i;
    EXPECT_NEAR(pv.Q1, Q1, 1e-12 * size_Q) << "linkage " << i;
    EXPECT_NEAR(pv.Q3, Q3, 1e-12 * size_Q) << "linkage " << i;
    EXPECT_EQ(eq.Q(1), model.loads.coupler.moment);
  }
}

// Erratum evidence (eq. 39, Q3): the printed principal-vector line
//   Q3 = M3 + ⟨-i l̄3 m̄2q, F̄2/m2⟩ - ⟨i (m1 + m2a - i m2c + m3) ā34 + (m2b + i m2c) ā32', F̄3/m3⟩
// puts i on the first term only. The moment of F̄3 about A3 needs i on the whole bracket,
// -⟨i [(…) ā34 + (…) ā32'], F̄3/m3⟩ (as Q1 has it), which is -m3 (r̄3 - A3) by eq. 33.
TEST(ComplexMasses, PaperEquation39Q3NeedsBracketsAroundTheImaginaryUnit) {
  const FourBar model = samples::paper_fourbar();
  const Pose pose = *solve_position(model, 1.0);
  const EquivalentMasses e2 = equivalent_masses(model.coupler);
  const FrameVectors v = frame_vectors(model, pose);
  const Complex k34 = model.crank.mass + e2.mp + model.rocker.mass;
  const Complex F3 = to_complex(model.loads.rocker.force);
  const Complex l3 = std::polar(model.rocker.length, pose.theta3);
  const Complex F2 = to_complex(model.loads.coupler.force);
  const double m2 = model.coupler.mass, m3 = model.rocker.mass;
  const double printed = model.loads.rocker.moment + inner(-kI * l3 * e2.mq, F2 / m2) -
                         inner(kI * k34 * to_complex(v.a34) + e2.mq * to_complex(v.a32p), F3 / m3);
  const double corrected = principal_vector_forms(model, pose).Q3;
  const double truth = complex_mass_equations(model, pose).Q(2);
  EXPECT_NEAR(corrected, truth, 1e-13 * std::abs(truth));
  EXPECT_GT(std::abs(printed - truth), 1e-2 * std::abs(truth));
}

// C13 from Lagrange's equations of the relaxed model T = ½ θ̇ᵀ M(θ) θ̇: M11, M33 are constant and
// M13 depends on θ3 - θ1 only, so row 1 gets ∂M13/∂θ3 θ̇3² and row 3 gets ∂M13/∂θ1 θ̇1², i.e.
// C13 = ∂M13/∂θ3 and C31 = ∂M13/∂θ1 = -C13. Central differences, h = 1e-5: truncation
// ~h² M13''' ~ 1e-10 |M13|, round-off ~eps |M13| / h ~ 1e-11 |M13|.
TEST(ComplexMasses, ConvectiveTermIsTheDerivativeOfTheMassMatrix) {
  std::mt19937_64 rng(34);
  const double h = 1e-5;
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const Pose pose = pose_of(random_state(model, rng));
    auto M13 = [&model, &pose](double d1, double d3) {
      return complex_mass_equations(model, {pose.theta1 + d1, pose.theta2, pose.theta3 + d3})
          .M(0, 2);
    };
    const ComplexMassEquations eq = complex_mass_equations(model, pose);
    const double size = eq.M.norm();
    EXPECT_NEAR(eq.C13, (M13(0, h) - M13(0, -h)) / (2 * h), 1e-8 * size);
    EXPECT_NEAR(-eq.C13, (M13(h, 0) - M13(-h, 0)) / (2 * h), 1e-8 * size);
  }
}

// ---- eq. 40 and the reactions ----

// Erratum evidence (eq. 40): a rigid rotation δθ_S about S moves the mass centres by
// δr̄_k = i δθ_S (r̄_k - r̄_S), so c̄_k = m_k (r̄_k - r̄_S). The corrected lines satisfy this; the
// printed m3 line, with (m1 + m2a + i m2c) ā34, is off by exactly -2 i m2c ā34.
TEST(ComplexMasses, PaperEquation40HasTheWrongSignOfTheVirtualMassInTheRockerLine) {
  std::mt19937_64 rng(35);
  for (int i = 0; i < 100; ++i) {
    FourBar model = i == 0 ? samples::paper_fourbar() : samples::random_crank_rocker(rng);
    const Pose pose = i == 0 ? *solve_position(model, 1.0) : pose_of(random_state(model, rng));
    const RotationAboutCentreOfMass c = rotation_about_centre_of_mass(model, pose);
    const Complex rS = to_complex(system_centre_of_mass(model, pose));
    const double size = total_mass(model) * longest_link(model);
    const Complex expected[3] = {
        model.crank.mass * (to_complex(centre_of_mass(model, 1, pose)) - rS),
        model.coupler.mass * (to_complex(centre_of_mass(model, 2, pose)) - rS),
        model.rocker.mass * (to_complex(centre_of_mass(model, 3, pose)) - rS)};
    EXPECT_LT(std::abs(to_complex(c.c1) - expected[0]), 1e-14 * size) << "linkage " << i;
    EXPECT_LT(std::abs(to_complex(c.c2) - expected[1]), 1e-14 * size) << "linkage " << i;
    EXPECT_LT(std::abs(to_complex(c.c3) - expected[2]), 1e-14 * size) << "linkage " << i;

    // the printed rocker line
    const EquivalentMasses e2 = equivalent_masses(model.coupler);
    const FrameVectors v = frame_vectors(model, pose);
    const Complex a14 = to_complex(v.a14), a43 = to_complex(v.a43), a34 = to_complex(v.a34),
                  a32p = to_complex(v.a32p);
    const Complex printed = model.rocker.mass * (a14 + a43) -
                            (model.crank.mass + e2.ma + kI * e2.mc) * a34 - e2.mq * a32p;
    EXPECT_LT(std::abs(printed - expected[2] + 2.0 * kI * e2.mc * a34), 1e-14 * size);
    EXPECT_GT(std::abs(printed - expected[2]), 1e-3 * std::abs(expected[2])) << "linkage " << i;
  }
}

// The reaction split (complex_masses.cpp, (c)): the generalised constraint forces vanish along
// the admissible direction Θ, are l̄_j × μ̄ with one force μ̄, and μ̄ is the complex-mass-weighted
// mean of the coupler's pin forces, -(m̄2q* P̄1 + m̄2p* P̄2)/m2, with the pin forces from the
// referee's reactions. The rocker side's translation then gives both components of R̄A3
// (the formulation uses only x; y is its redundant check against eq. 40).
TEST(ComplexMasses, LoopClosureForceSplitsTheReactions) {
  std::mt19937_64 rng(36);
  for (int i = 0; i < 100; ++i) {
    const FourBar model = samples::random_crank_rocker(rng);
    const double theta1 = uniform(rng, 0, kTwoPi), omega1 = uniform(rng, -5, 5),
                 alpha1 = uniform(rng, -20, 20);
    const DynamicsSample ref = reference::newton_euler_inverse(model, theta1, omega1, alpha1);
    const FourBarState& s = ref.state;
    const Eigen::Vector3d Qc = generalised_constraint_forces(model, s, ref.tau);
    const TransferFunctions tf = transfer_functions(model, pose_of(s));
    const double size_Q = moment_scale(model, ref);
    EXPECT_LT(std::abs(Qc(0) + tf.dtheta2_dtheta1 * Qc(1) + tf.dtheta3_dtheta1 * Qc(2)),
              kRel * size_Q);

    const Complex l1 = std::polar(model.crank.length, s.theta1),
                  l2 = std::polar(model.coupler.length, s.theta2),
                  l3 = std::polar(model.rocker.length, s.theta3);
    const Complex mu = (Qc(1) * l3 - Qc(2) * l2) / inner(kI * l2, l3);
    EXPECT_LT(std::abs(inner(kI * l1, mu) - Qc(0)), kRel * size_Q);  // row 1: l̄1 × μ̄

    // pin forces from the referee's reactions (Newton for the rocker and the coupler)
    const Vec2 g = model.loads.gravity;
    const Complex F2 = to_complex(model.loads.coupler.force + model.coupler.mass * g),
                  F3 = to_complex(model.loads.rocker.force + model.rocker.mass * g);
    const Complex m2a2 = model.coupler.mass * to_complex(centre_of_mass_acceleration(model, 2, s));
    const Complex m3a3 = model.rocker.mass * to_complex(centre_of_mass_acceleration(model, 3, s));
    const Complex P2 = m3a3 - F3 + to_complex(ref.RA3);  // coupler on rocker at A2
    const Complex P1 = P2 + m2a2 - F2;                   // crank on coupler at A1
    const EquivalentMasses e2 = equivalent_masses(model.coupler);
    const Complex mu_pins = -(std::conj(e2.mq) * P1 + std::conj(e2.mp) * P2) / model.coupler.mass;
    const double F = force_scale(ref);
    EXPECT_LT(std::abs(mu - mu_pins), kRel * F) << "linkage " << i;

    const Complex s2 = Complex(model.coupler.e, model.coupler.f) / model.coupler.length;
    const Complex RA3 = F3 - m3a3 + std::conj(s2) * (F2 - m2a2) - mu;
    EXPECT_LT(std::abs(RA3 - to_complex(ref.RA3)), kRel * F) << "linkage " << i;
  }
}

// ---- errors, purity, allocation ----

TEST(ComplexMasses, ReportsAnUnreachableCrankAngle) {
  const FourBar model = samples::triple_rocker();  // swings within |theta1| < 1.553 rad
  const auto f = forward_dynamics_complex_masses(model, 2.5, 1.0);
  ASSERT_FALSE(f.has_value());
  EXPECT_EQ(f.error().kind, DynamicsError::Kind::kAssembly);
  const auto g = inverse_dynamics_complex_masses(model, 2.5, 1.0, 0.0);
  ASSERT_FALSE(g.has_value());
  EXPECT_EQ(g.error().kind, DynamicsError::Kind::kAssembly);
}

TEST(ComplexMasses, DynamicsOfOneInstantAllocatesNothing) {
  const FourBar m = samples::paper_fourbar();
  double sink = 0;
  const long before = testing::allocations();
  for (int i = 0; i < 360; ++i) {
    const double theta1 = kTwoPi * i / 360;
    const auto f = forward_dynamics_complex_masses(m, theta1, 2.0);
    const auto g = inverse_dynamics_complex_masses(m, theta1, 2.0, 0.5);
    sink += f->state.alpha1 + g->tau + f->RA0.x() + g->RA3.y();
  }
  EXPECT_EQ(testing::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace bd::core
