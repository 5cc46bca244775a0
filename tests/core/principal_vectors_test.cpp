// Principal vectors and points (eqs. 12-17, 30-33), equivalent masses (eq. 29), and the centre
// of mass S by both constructions, against the definition Σ m_k r̄_k / m_tot.
#include "core/fourbar/principal_vectors.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/detail/complex_vector.hpp"
#include "core/fourbar/energy.hpp"
#include "core/fourbar/samples.hpp"

namespace bd::core {
namespace {

// the paper's complex notation for planar vectors
using detail::Complex;
using detail::to_complex;
using detail::to_vec;

FourBarState random_state(const FourBar& m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  const double theta1 = 3.14159 * u(rng);
  return solve_acceleration(m, solve_velocity(m, *solve_position(m, theta1), 3 * u(rng)),
                            10 * u(rng));
}

Vec2 mass_weighted_acceleration(const FourBar& m, const FourBarState& s) {
  Vec2 sum(0, 0);
  for (int k = 1; k <= 3; ++k) sum += link(m, k).mass * centre_of_mass_acceleration(m, k, s);
  return sum / total_mass(m);
}

TEST(PrincipalVectors, BothConstructionsTraceTheCentreOfMass) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 200; ++trial) {
    const FourBar m = samples::random_crank_rocker(rng);
    const FourBarState s = random_state(m, rng);
    const Vec2 r = system_centre_of_mass(m, pose_of(s));
    const Vec2 v = linear_momentum(m, s) / total_mass(m);
    const Vec2 a = mass_weighted_acceleration(m, s);
    // sums of a few terms of size <= ~4 m: round-off a few eps times that
    const double lscale = 10, vscale = 10 * (1 + v.norm()), ascale = 10 * (1 + a.norm());
    for (const PointKinematics& S :
         {centre_of_mass_opened_loop(m, s), centre_of_mass_frame(m, s)}) {
      EXPECT_LT((S.r - r).norm(), 1e-14 * lscale) << "trial " << trial;
      EXPECT_LT((S.v - v).norm(), 1e-14 * vscale) << "trial " << trial;
      EXPECT_LT((S.a - a).norm(), 1e-13 * ascale) << "trial " << trial;
    }
  }
}

TEST(PrincipalVectors, LinkVectorsAreDifferencesOfPrincipalVectors) {
  std::mt19937_64 rng(32);
  const FourBar m = samples::random_crank_rocker(rng);
  const Pose p = *solve_position(m, 0.7);
  const Joints j = joint_positions(m, p);
  const OpenedLoopVectors o = opened_loop_vectors(m, p);
  const FrameVectors f = frame_vectors(m, p);
  const double tol = 1e-14 * 10;
  EXPECT_LT((o.a12 - o.a14p - (j.A1 - j.A0)).norm(), tol);  // eq. 13
  EXPECT_LT((o.a23 - o.a21 - (j.A2 - j.A1)).norm(), tol);   // eq. 12
  EXPECT_LT((o.a34p - o.a32 - (j.A3 - j.A2)).norm(), tol);  // eq. 13
  EXPECT_LT((f.a41 - f.a43 - (j.A0 - j.A3)).norm(), tol);   // l̄4 = ā41 - ā43
  EXPECT_LT((f.a12p - f.a14 - (j.A1 - j.A0)).norm(), tol);  // eq. 31
  EXPECT_LT((f.a34 - f.a32p - (j.A3 - j.A2)).norm(), tol);  // eq. 31
  // principal points: P_k + ā_kj lands on the joint
  const PrincipalPoints P = opened_loop_principal_points(m, p);
  EXPECT_LT((P.P1 + o.a12 - j.A1).norm(), tol);
  EXPECT_LT((P.P2 + o.a23 - j.A2).norm(), tol);
  EXPECT_LT((P.P3 + o.a34p - j.A3).norm(), tol);
  const FramePrincipalPoints Q = frame_principal_points(m, p);
  EXPECT_LT((Q.P1 + f.a12p - j.A1).norm(), tol);
  EXPECT_LT((Q.P3 + f.a32p - j.A2).norm(), tol);
  EXPECT_LT((Q.P4 + f.a43 - j.A3).norm(), tol);
}

TEST(PrincipalVectors, CentresOfMassOfTheLinksFromPrincipalVectors) {
  // eq. 17 (opened loop, r̄_A0 = 0) and eq. 33 (frame set)
  std::mt19937_64 rng(33);
  for (int trial = 0; trial < 50; ++trial) {
    const FourBar m = samples::random_crank_rocker(rng);
    const Pose p = *solve_position(m, 6.28 * trial / 50);
    const Joints j = joint_positions(m, p);
    const OpenedLoopVectors o = opened_loop_vectors(m, p);
    const FrameVectors f = frame_vectors(m, p);
    const double m1 = m.crank.mass, m2 = m.coupler.mass, m3 = m.rocker.mass, mt = total_mass(m);
    const Vec2 l1 = j.A1 - j.A0, l2 = j.A2 - j.A1, l3 = j.A3 - j.A2, l4 = j.A0 - j.A3;
    const Vec2 r1 = centre_of_mass(m, 1, p), r2 = centre_of_mass(m, 2, p),
               r3 = centre_of_mass(m, 3, p);
    const double tol = 1e-13 * mt;
    EXPECT_LT((m1 * r1 - (-m1 * o.a14p - (m2 + m3) * o.a12)).norm(), tol);
    EXPECT_LT((m2 * r2 - (m2 * l1 - (m1 + m2) * o.a21 - m3 * o.a23)).norm(), tol);
    EXPECT_LT((m3 * r3 - (m3 * (l1 + l2) - mt * o.a32)).norm(), tol);
    // eq. 33, complex products written out
    const EquivalentMasses e2 = equivalent_masses(m.coupler);
    auto mul = [](const Complex& c, const Vec2& v) { return to_vec(c * to_complex(v)); };
    EXPECT_LT((m1 * r1 - (-mul(m1 + e2.mq + m3, f.a14) - mul(e2.mp, f.a12p))).norm(), tol);
    EXPECT_LT((m2 * r2 - (mul(e2.mp, l1) + mul(e2.mq, -l4 - l3))).norm(), tol);
    EXPECT_LT((m3 * r3 - (-m3 * l4 - mul(m1 + e2.mp + m3, f.a34) - mul(e2.mq, f.a32p))).norm(),
              tol);
  }
}

TEST(PrincipalVectors, EquivalentMassesSumToTheMassAndLocateTheCentreOfMass) {
  const Link l = samples::paper_fourbar().coupler;
  const EquivalentMasses e = equivalent_masses(l);
  EXPECT_NEAR(std::abs(e.mp + e.mq - l.mass), 0.0, 1e-15);
  EXPECT_NEAR(e.ma + e.mb, l.mass, 1e-15);
  EXPECT_NEAR(e.mp.real(), e.ma, 1e-15);
  EXPECT_NEAR(e.mp.imag(), -e.mc, 1e-15);
  EXPECT_NEAR(e.mq.imag(), e.mc, 1e-15);
  // eq. 29: m r̄ = m̄_p r̄_p + m̄_q r̄_q for a link from p to q
  const Vec2 p(0.3, -0.2), q = p + l.length * unit(0.9);
  const Vec2 com = p + l.e * unit(0.9) + l.f * perp(unit(0.9));
  EXPECT_LT((to_vec(e.mp * to_complex(p) + e.mq * to_complex(q)) - l.mass * com).norm(), 1e-14);
}

TEST(PrincipalVectors, ForceBalancedDesignKeepsTheCentreOfMassStill) {
  // eq. 58: choose e1, f1 and e3, f3 so that ā14 = ā34 = 0; then S does not move
  FourBar m = samples::paper_fourbar_unloaded();
  const Link& c = m.coupler;
  const double l1 = m.crank.length, l2 = c.length, l3 = m.rocker.length;
  m.crank.e = -c.mass * (l2 - c.e) / l2 * l1 / m.crank.mass;
  m.crank.f = c.mass * c.f / l2 * l1 / m.crank.mass;
  m.rocker.e = l3 + c.mass * c.e / l2 * l3 / m.rocker.mass;
  m.rocker.f = c.mass * c.f / l2 * l3 / m.rocker.mass;
  const FrameFactors f = frame_factors(m);
  EXPECT_LT(std::abs(f.a14), 1e-16);
  EXPECT_LT(std::abs(f.a34), 1e-16);
  const Vec2 S0 = system_centre_of_mass(m, *solve_position(m, 0.0));
  for (int i = 1; i < 24; ++i) {
    const Vec2 S = system_centre_of_mass(m, *solve_position(m, 6.283185307179586 * i / 24));
    EXPECT_LT((S - S0).norm(), 1e-14);
  }
}

}  // namespace
}  // namespace bd::core
