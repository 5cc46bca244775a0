// The constant equivalent mass matrix (paper eq. 45), its assembly (eqs. 48, 53), the nodal
// forces (eq. 46), and the evidence for the reaction-force erratum of eqs. 52-54.
#include "core/fourbar/mass_matrix.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/samples.hpp"

namespace bd::core {
namespace {

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

// Kinetic energy of a pseudo-rigid link (rotation + uniform dilatation) computed from a point-mass
// model with the same mass, centre of mass and polar moment: two masses m/2 at the centre of
// mass ± r along the link with r = sqrt(I/m). A material point at complex link coordinate
// w = (x + i y)/l moves with v = v_p + w·(v_q - v_p) (eq. 42).
double point_mass_kinetic_energy(const Link& link, const Vec4& rdot) {
  const double r = std::sqrt(link.inertia / link.mass);
  const Vec2 vp = rdot.head<2>(), dv = rdot.tail<2>() - vp;
  double T = 0;
  for (double sgn : {-1.0, 1.0}) {
    const double x = (link.e + sgn * r) / link.length, y = link.f / link.length;
    const Vec2 v = vp + Vec2(x * dv.x() - y * dv.y(), x * dv.y() + y * dv.x());  // vp + w·dv
    T += 0.5 * (link.mass / 2) * v.squaredNorm();
  }
  return T;
}

TEST(MassMatrix, LinkMatrixGivesKineticEnergyOfEveryPseudoRigidMotion) {
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 200; ++trial) {
    const Link link{uniform(rng, 0.3, 3), uniform(rng, 0.1, 5), uniform(rng, -1, 3),
                    uniform(rng, -1, 1), uniform(rng, 0.01, 2)};
    const Vec4 rdot = Vec4::Random() * 3;  // any joint velocities: rotation, translation, dilatation
    const Mat4 Me = link_mass_matrix(link);
    const double T = point_mass_kinetic_energy(link, rdot);
    EXPECT_NEAR(0.5 * rdot.dot(Me * rdot), T, 1e-13 * std::max(1.0, T)) << "trial " << trial;
    EXPECT_LT((Me - Me.transpose()).norm(), 1e-15 * Me.norm());
  }
}

TEST(MassMatrix, RigidMotionEnergyMatchesKoenig) {
  // for a rigid motion T = ½ m |v_c|² + ½ I ω² (König)
  const Link link = samples::paper_fourbar().coupler;
  const double theta = 0.7, omega = -1.9;
  const Vec2 vp(0.4, -1.1), d = link.length * unit(theta);
  Vec4 rdot;
  rdot << vp, vp + omega * perp(d);
  const Vec2 rho = link.e * unit(theta) + link.f * perp(unit(theta));
  const Vec2 vc = vp + omega * perp(rho);
  const double T = 0.5 * link.mass * vc.squaredNorm() + 0.5 * link.inertia * omega * omega;
  EXPECT_NEAR(0.5 * rdot.dot(link_mass_matrix(link) * rdot), T, 1e-14 * T);
}

TEST(MassMatrix, AssemblyMatchesPaperEquations48And53) {
  const FourBar m = samples::paper_fourbar();
  const SystemMassMatrices s = system_mass_matrices(m);
  const Link &L1 = m.crank, &L2 = m.coupler, &L3 = m.rocker;
  auto sq = [](double x) { return x * x; };
  const double l1 = L1.length, l2 = L2.length, l3 = L3.length;
  // eq. 48 as printed
  const double M11 = (L1.inertia + L1.mass * (sq(L1.e) + sq(L1.f))) / sq(l1) +
                     (L2.inertia + L2.mass * (sq(l2 - L2.e) + sq(L2.f))) / sq(l2);
  const double M13 = (L2.mass * L2.e * (l2 - L2.e) - L2.mass * sq(L2.f) - L2.inertia) / sq(l2);
  const double M14 = -L2.mass * L2.f / l2;
  const double M33 = (L2.inertia + L2.mass * (sq(L2.e) + sq(L2.f))) / sq(l2) +
                     (L3.inertia + L3.mass * (sq(l3 - L3.e) + sq(L3.f))) / sq(l3);
  Mat4 M;
  M << M11, 0, M13, M14,  //
      0, M11, -M14, M13,  //
      M13, -M14, M33, 0,  //
      M14, M13, 0, M33;
  EXPECT_LT((s.M - M).norm(), 1e-15 * M.norm());
  // eq. 53 as printed
  const double Mr11 = (L1.mass * L1.e * (l1 - L1.e) - L1.mass * sq(L1.f) - L1.inertia) / sq(l1);
  const double Mr12 = -L1.mass * L1.f / l1;
  const double Mr33 = (L3.mass * L3.e * (l3 - L3.e) - L3.mass * sq(L3.f) - L3.inertia) / sq(l3);
  const double Mr34 = L3.mass * L3.f / l3;
  Mat4 Mr;
  Mr << Mr11, Mr12, 0, 0,  //
      -Mr12, Mr11, 0, 0,   //
      0, 0, Mr33, Mr34,    //
      0, 0, -Mr34, Mr33;
  EXPECT_LT((s.Mr - Mr).norm(), 1e-15 * Mr.norm());
}

TEST(MassMatrix, NodalForcesDoTheSameVirtualWorkInRigidMotion) {
  std::mt19937_64 rng(22);
  for (int trial = 0; trial < 100; ++trial) {
    const Link link{uniform(rng, 0.3, 3), 1.0, uniform(rng, -1, 3), uniform(rng, -1, 1), 0.1};
    const double theta = uniform(rng, -3, 3);
    const Vec2 p(uniform(rng, -2, 2), uniform(rng, -2, 2)), q = p + link.length * unit(theta);
    const Vec2 F(uniform(rng, -5, 5), uniform(rng, -5, 5));
    const double M = uniform(rng, -3, 3);
    const Vec2 dp(uniform(rng, -1, 1), uniform(rng, -1, 1));
    const double dtheta = uniform(rng, -1, 1);
    const Vec2 rho = link.e * unit(theta) + link.f * perp(unit(theta));
    const double work = F.dot(dp + dtheta * perp(rho)) + M * dtheta;
    Vec4 dr;
    dr << dp, dp + dtheta * perp(q - p);
    EXPECT_NEAR(link_nodal_forces(link, F, M, p, q).dot(dr), work, 1e-13) << "trial " << trial;
  }
}

// Erratum evidence (docs/paper-errata.md): eqs. 52-54 vary one support joint alone, which
// stretches the crank (or rocker) truss element, so the element's axial force belongs in the
// equation. Without it, eq. 54 gives a reaction that differs from the true one by a force
// along the link. Here: the printed eq. 54 vs the formulation (checked against Newton-Euler in
// dynamics_test), at a driven state of the paper example.
TEST(MassMatrix, PaperEquation54MissesTheAxialForceAlongTheLink) {
  const FourBar m = samples::paper_fourbar();
  const double theta1 = 1.0, omega1 = 2.0, alpha1 = 0.5;
  const DynamicsSample s = *inverse_dynamics(m, theta1, omega1, alpha1);
  const Joints j = joint_positions(m, pose_of(s.state));
  // joint accelerations of A1 and A2 (eq. 51)
  const Vec2 l1v = j.A1 - j.A0, l3v = j.A3 - j.A2;
  const FourBarState& st = s.state;
  Vec4 rdd;
  rdd << st.alpha1 * perp(l1v) - st.omega1 * st.omega1 * l1v,
      -(st.alpha3 * perp(l3v) - st.omega3 * st.omega3 * l3v);
  const SystemMassMatrices mm = system_mass_matrices(m);
  // eq. 54 with the applied loads of link 1 at A0 and link 3 at A3, plus the drive moment tau
  // on the crank (a moment on link 1 like M1), solved for R̄A0, R̄A3
  const Vec4 n1 = link_nodal_forces(m.crank, m.loads.crank.force, m.loads.crank.moment + s.tau,
                                    j.A0, j.A1);
  const Vec4 n3 = link_nodal_forces(m.rocker, m.loads.rocker.force, m.loads.rocker.moment, j.A2,
                                    j.A3);
  const Vec4 Mr_rdd = mm.Mr * rdd;
  const Vec2 RA0_paper = n1.head<2>() - Mr_rdd.head<2>();
  const Vec2 RA3_paper = n3.tail<2>() - Mr_rdd.tail<2>();
  const Vec2 dA0 = s.RA0 - RA0_paper, dA3 = s.RA3 - RA3_paper;
  // the printed formula is off by a force of order of the reactions themselves ...
  EXPECT_GT(dA0.norm(), 1e-2 * s.RA0.norm());
  EXPECT_GT(dA3.norm(), 1e-2 * s.RA3.norm());
  // ... and only along the link: exactly the missing axial-force term
  EXPECT_LT(std::abs(cross(dA0, unit(st.theta1))), 1e-12 * s.RA0.norm());
  EXPECT_LT(std::abs(cross(dA3, unit(st.theta3))), 1e-12 * s.RA3.norm());
}

}  // namespace
}  // namespace bd::core
