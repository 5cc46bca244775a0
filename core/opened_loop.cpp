#include "core/opened_loop.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/formulation_support.hpp"
#include "core/principal_vectors.hpp"

namespace bd::core {

namespace {

// which of θ̈1 and tau is the first unknown of the 5x5 solve
enum class Unknown { kAlpha1, kTau };

// ⟨i x̄, ȳ⟩ of the paper: the inner product of i·x̄ (x̄ turned by +90°) with ȳ, = x̄ × ȳ
double inner_i(const Vec2& x, const Vec2& y) { return cross(x, y); }

// eq. 22's terms from the link vectors and the opened-loop vectors of the same angles
// (opened_loop_terms() without the trigonometry)
OpenedLoopTerms terms(const FourBar& model, const LinkVectors& l, const OpenedLoopVectors& a);

// Solves eqs. 22 and 27 at the angles and rates of `s` (taken as independent), whose link vectors
// are `l` (computed once by the caller). Unknowns
// x = [u, θ̈2, θ̈3, RA3x, RA3y] with u = θ̈1 (forward, tau = 0) or u = tau (inverse, θ̈1 given in
// s.alpha1). Fills the acceleration stage, the reactions and tau.
Expected<DynamicsSample, DynamicsError> solve(const FourBar& model, FourBarState s,
                                              const LinkVectors& l, Unknown unknown,
                                              const Vec2& closure_bias) {
  // the 5x5 matrix [M D; Dᵀ 0] is regular iff D = [i l̄1; i l̄2; i l̄3] has rank 2 (M is positive
  // definite), i.e. unless all three moving links are parallel
  // |sin(theta_k - theta_j)| = |l̄j × l̄k| / (lj lk)
  const double l1 = model.crank.length, l2 = model.coupler.length, l3 = model.rocker.length;
  const double sin12 = std::abs(cross(l.l1, l.l2)) / (l1 * l2);
  const double sin13 = std::abs(cross(l.l1, l.l3)) / (l1 * l3);
  const double sin23 = std::abs(cross(l.l2, l.l3)) / (l2 * l3);
  if (!(std::max({sin12, sin13, sin23}) >= kSingularSin)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "all three moving links are parallel (largest |sin| of their relative angles "
                  "%.3g): the opened-loop 5x5 system is singular",
                  std::max({sin12, sin13, sin23}));
    return Unexpected(DynamicsError{DynamicsError::Kind::kSingular, s.theta1, buf});
  }

  // eq. 22 (three rows) and eq. 27 (two rows): [M D; Dᵀ 0] [θ̈; R̄A3] = [Q - C θ̇²; Σ l̄k θ̇k²]
  const OpenedLoopVectors a = opened_loop_vectors(model, l);  // eqs. 12-13, also for eq. 28
  const OpenedLoopTerms t = terms(model, l, a);
  const Eigen::Vector3d omega_sq(s.omega1 * s.omega1, s.omega2 * s.omega2, s.omega3 * s.omega3);
  Mat5 A = Mat5::Zero();
  A.topLeftCorner<3, 3>() = t.M;
  A.topRightCorner<3, 2>() = t.D;
  A.bottomLeftCorner<2, 3>() = t.D.transpose();
  Vec5 b;
  b.head<3>() = t.Q - t.C * omega_sq;
  // eq. 27: Σ l̄k (i θ̈k - θ̇k²) = 0, i.e. Σ (i l̄k) θ̈k = Σ l̄k θ̇k² (+ the stabilisation bias)
  b.tail<2>() = l.l1 * omega_sq(0) + l.l2 * omega_sq(1) + l.l3 * omega_sq(2) + closure_bias;

  if (unknown == Unknown::kTau) {
    // θ̈1 known: its column moves to the right-hand side; tau enters Q1, so the first equation
    // gains -tau on the left
    b -= A.col(0) * s.alpha1;
    A.col(0).setZero();
    A(0, 0) = -1.0;
  }

  // fixed-size LU with partial pivoting: no heap allocation
  const Vec5 x = Eigen::PartialPivLU<Mat5>(A).solve(b);

  DynamicsSample out;
  if (unknown == Unknown::kAlpha1) {
    s.alpha1 = x(0);
  } else {
    out.tau = x(0);
  }
  s.alpha2 = x(1);
  s.alpha3 = x(2);
  out.RA3 = x.tail<2>();

  // eq. 28: m_tot r̈_S = ΣF̄k - R̄A0 - R̄A3 (F̄k with the weights), r̈_S from eq. 16
  const Vec2 a_S = centre_of_mass_opened_loop(a, s).a;
  Vec2 applied = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) {
    applied += link_load(model, k).force + link(model, k).mass * model.loads.gravity;
  }
  out.RA0 = applied - out.RA3 - total_mass(model) * a_S;
  out.state = s;
  return completed_sample(model, out);
}

OpenedLoopTerms terms(const FourBar& model, const LinkVectors& l, const OpenedLoopVectors& a) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m1 = L1.mass, m2 = L2.mass, m3 = L3.mass, mt = m1 + m2 + m3;
  const Vec2 &l1 = l.l1, &l2 = l.l2, &l3 = l.l3;
  OpenedLoopTerms t;

  // mass matrix (unnumbered equation after eq. 22). The diagonal uses the paper's simplified
  // forms, the reduced systems' moments of inertia about the first joint, which divide by no
  // mass; the principal-vector forms printed first divide by m1 (M11: (m2+m3)²/m1·a12²), m2
  // (M22: (m1+m2)²/m2·a21², 2(m1+m2)m3/m2·<ā21, ā23>, m3²/m2·a23²) and m3 (M33: m_tot²/m3·a32²)
  // and equal these (tests/core/opened_loop_test.cpp).
  auto sq = [](double v) { return v * v; };
  t.M(0, 0) = L1.inertia + m1 * (sq(L1.e) + sq(L1.f)) + (m2 + m3) * sq(L1.length);
  t.M(1, 1) = L2.inertia + m2 * (sq(L2.e) + sq(L2.f)) + m3 * sq(L2.length);
  t.M(2, 2) = L3.inertia + m3 * (sq(L3.e) + sq(L3.f));
  // off-diagonal terms: minus the total mass times <link vector, principal vector of the other
  // link pointing towards it>
  t.M(0, 1) = t.M(1, 0) = -mt * l1.dot(a.a21);
  t.M(0, 2) = t.M(2, 0) = -mt * l1.dot(a.a32);
  t.M(1, 2) = t.M(2, 1) = -mt * l2.dot(a.a32);

  // eq. 23: convective coefficients, skew-symmetric
  t.C.setZero();
  t.C(0, 1) = mt * inner_i(l1, a.a21);
  t.C(0, 2) = mt * inner_i(l1, a.a32);
  t.C(1, 2) = mt * inner_i(l2, a.a32);
  t.C(1, 0) = -t.C(0, 1);
  t.C(2, 0) = -t.C(0, 2);
  t.C(2, 1) = -t.C(1, 2);

  // eq. 24: D_j = i l̄_j = (-l_j sin θ_j, l_j cos θ_j)
  t.D.row(0) = perp(l1).transpose();
  t.D.row(1) = perp(l2).transpose();
  t.D.row(2) = perp(l3).transpose();

  // eq. 25 with F̄k = applied force + m_k ḡ: the moments about each link's first joint, with the
  // forces on the links beyond shifted to its second joint. The paper prints them in principal
  // vectors divided by a mass ((m2+m3)/m1 <i ā12, F̄1>, (m1+m2)/m2 <i ā21, F̄2> + m3/m2 <i ā23,
  // F̄2>, m_tot/m3 <i ā32, F̄3>); those quotients are differences of O(m_tot) terms that are
  // O(m_k), so at a small mass they lose ~eps·m_tot/m_k (measured: 8e-7 at m2 = 1e-8 kg,
  // docs/failure-domains.md). Here the same moments, m_k r̄_k - m_k r̄_joint = m_k s̄_k l̄_k/l_k
  // divided through exactly: <i s̄_k l̄_k/l_k, F̄k>, which divide by no mass.
  const Vec2 F1 = model.loads.crank.force + m1 * model.loads.gravity;
  const Vec2 F2 = model.loads.coupler.force + m2 * model.loads.gravity;
  const Vec2 F3 = model.loads.rocker.force + m3 * model.loads.gravity;
  auto com_from_first_joint = [](const Link& link, const Vec2& lk) {
    return Vec2(link.e / link.length * lk + link.f / link.length * perp(lk));
  };
  t.Q(0) = model.loads.crank.moment + cross(com_from_first_joint(model.crank, l1), F1) +
           cross(l1, F2 + F3);
  t.Q(1) = model.loads.coupler.moment + cross(com_from_first_joint(model.coupler, l2), F2) +
           cross(l2, F3);
  t.Q(2) = model.loads.rocker.moment + cross(com_from_first_joint(model.rocker, l3), F3);
  return t;
}

// The link vectors of a state, from its angles. Also on a closed state, where the position
// solve has them already: the state form (the DAE's right-hand side) must give bit for bit what
// the closed form gives on the same state (opened_loop_test), so both take them from the angles,
// three cos/sin pairs per evaluation.
LinkVectors link_vectors_of(const FourBar& model, const FourBarState& s) {
  return link_vectors(model, pose_of(s));
}

}  // namespace

OpenedLoopTerms opened_loop_terms(const FourBar& model, const Pose& pose) {
  const LinkVectors l = link_vectors(model, pose);
  return terms(model, l, opened_loop_vectors(model, l));
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1) {
  const auto instant = nonsingular_instant(model, theta1, omega1);
  if (!instant) return Unexpected(instant.error());
  return solve(model, instant->state, link_vectors_of(model, instant->state), Unknown::kAlpha1,
               Vec2::Zero());
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1) {
  const auto instant = nonsingular_instant(model, theta1, omega1);
  if (!instant) return Unexpected(instant.error());
  FourBarState s = instant->state;
  s.alpha1 = alpha1;
  return solve(model, s, link_vectors_of(model, s), Unknown::kTau, Vec2::Zero());
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     const FourBarState& state,
                                                                     const Vec2& closure_bias) {
  FourBarState s = state;
  s.alpha1 = s.alpha2 = s.alpha3 = 0.0;
  return solve(model, s, link_vectors_of(model, s), Unknown::kAlpha1, closure_bias);
}

}  // namespace bd::core
