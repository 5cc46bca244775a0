#include "core/fourbar/opened_loop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/principal_vectors.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::ClosedInstant;
using detail::CrankInput;
using detail::evaluated;
using detail::Failure;
using detail::opened_loop_constants;
using detail::OpenedLoopConstants;
using detail::Xy;
using detail::xy;

namespace {

// The link vectors l̄1, l̄2, l̄3 [m].
struct Links {
  Xy l[3];
};

// eq. 22's terms (OpenedLoopTerms) in plain doubles; D_j = i l̄_j is not stored.
struct Terms {
  double M[3][3];  // [kg m^2]
  double C[3][3];  // [kg m^2]
  double Q[3];     // [N m]
};

// eq. 22's terms at the link vectors l (opened_loop_terms() without the trigonometry). The pose
// enters the off-diagonal terms only through ζ_jk = conj(l̄_j) l̄_k = (l̄_j·l̄_k, l̄_j × l̄_k),
// since every principal vector is a constant factor times its link vector: m_tot ā21 =
// kappa12 l̄2 and m_tot ā32 = kappa13 l̄3.
Terms terms(const OpenedLoopConstants& c, const FourBar& model, const Links& links) {
  const Xy &l1 = links.l[0], &l2 = links.l[1], &l3 = links.l[2];
  Terms t;

  // mass matrix (unnumbered equation after eq. 22). The diagonal uses the paper's simplified
  // forms, the reduced systems' moments of inertia about the first joint, which divide by no
  // mass; the principal-vector forms printed first divide by m1 (M11: (m2+m3)²/m1·a12²), m2
  // (M22: (m1+m2)²/m2·a21², 2(m1+m2)m3/m2·<ā21, ā23>, m3²/m2·a23²) and m3 (M33: m_tot²/m3·a32²)
  // and equal these (tests/core/opened_loop_test.cpp). Off the diagonal: minus the total mass
  // times <link vector, principal vector of the other link pointing towards it>.
  const Xy k12 = cmul(c.kappa12, cmul_conj(l1, l2));  // m_tot conj(l̄1) ā21
  const Xy k13 = cmul(c.kappa13, cmul_conj(l1, l3));  // m_tot conj(l̄1) ā32
  const Xy k23 = cmul(c.kappa13, cmul_conj(l2, l3));  // m_tot conj(l̄2) ā32
  t.M[0][0] = c.M11;
  t.M[1][1] = c.M22;
  t.M[2][2] = c.M33;
  t.M[0][1] = t.M[1][0] = -k12.x;
  t.M[0][2] = t.M[2][0] = -k13.x;
  t.M[1][2] = t.M[2][1] = -k23.x;

  // eq. 23: convective coefficients m_tot <i l̄_j, ā_kj>, skew-symmetric
  t.C[0][0] = t.C[1][1] = t.C[2][2] = 0.0;
  t.C[0][1] = k12.y;
  t.C[0][2] = k13.y;
  t.C[1][2] = k23.y;
  t.C[1][0] = -t.C[0][1];
  t.C[2][0] = -t.C[0][2];
  t.C[2][1] = -t.C[1][2];

  // eq. 25: the moments about each link's first joint of its force and of the forces on the
  // links beyond, shifted to its second joint (opened_loop_constants() explains the form)
  t.Q[0] = model.loads.crank.moment + cross(l1, c.H1);
  t.Q[1] = model.loads.coupler.moment + cross(l2, c.H2);
  t.Q[2] = model.loads.rocker.moment + cross(l3, c.H3);
  return t;
}

// Solves eqs. 22 and 27 at the angles and rates of `s` (taken as independent), whose link vectors
// are `links`:
//   [M D; Dᵀ 0] [θ̈; R̄A3] = [b1; b2],  b1 = Q - C θ̇² (+ tau e1),  b2 = Σ l̄k θ̇k² + closure_bias,
// with D_j = i l̄_j (eq. 24). Forward (tau = 0): θ̈ and R̄A3 unknown. Inverse: θ̈1 = input.alpha1
// given, tau, θ̈2, θ̈3, R̄A3 unknown. Fills the acceleration stage, the reactions and tau.
//
// The 5x5 system is solved exactly by eliminating the constraint rows (a null-space method)
// rather than by an LU of the whole matrix: Dᵀθ̈ = b2 reads Σ_k i l̄_k θ̈_k = b2, two equations
// that fix two accelerations θ̈_i, θ̈_j in terms of the third, θ̈ = Θ θ̈_k + g, by Cramer's rule
// with the determinant l̄_i × l̄_j; the pair is the one with the largest |sin| of its relative
// angle (pivoting: at a crank's limit position, l̄2 ∥ l̄3, it is a pair with the crank). Then
// Θᵀ(M θ̈ + D R̄ - b1) = 0 with ΘᵀD = 0 gives θ̈_k = Θᵀ(b1 - M g)/(Θᵀ M Θ), and rows i, j of
// M θ̈ + D R̄ = b1 give R̄ by Cramer's rule with the same determinant. Θᵀ M Θ > 0 whenever the
// 5x5 matrix is regular, also where M itself is only semidefinite (a link with zero inertia
// and its centre of mass on its first joint), which rules out a Cholesky factor of M.
std::optional<Failure> solve(const OpenedLoopConstants& c, const FourBar& model,
                             const FourBarState& s, const Links& links, CrankInput input,
                             const Xy& closure_bias, DynamicsSample& out) {
  const Xy* l = links.l;
  // the 5x5 matrix is regular iff D = [i l̄1; i l̄2; i l̄3] has rank 2 (given Θᵀ M Θ > 0),
  // i.e. unless all three moving links are parallel
  // |sin(theta_k - theta_j)| = |l̄j × l̄k| / (lj lk)
  const double sin12 = std::abs(cross(l[0], l[1])) * c.inv_l1l2;
  const double sin13 = std::abs(cross(l[0], l[2])) * c.inv_l1l3;
  const double sin23 = std::abs(cross(l[1], l[2])) * c.inv_l2l3;
  if (!(std::max({sin12, sin13, sin23}) >= kSingularSin)) {
    return Failure{Failure::Reason::kAllParallel, s.theta1, std::max({sin12, sin13, sin23})};
  }

  // eq. 22 (three rows) and eq. 27 (two rows): [M D; Dᵀ 0] [θ̈; R̄A3] = [Q - C θ̇²; Σ l̄k θ̇k²]
  const Terms t = terms(c, model, links);
  const double omega_sq[3] = {s.omega1 * s.omega1, s.omega2 * s.omega2, s.omega3 * s.omega3};
  double b1[3];
  for (int r = 0; r < 3; ++r) {
    b1[r] = t.Q[r] - (t.C[r][0] * omega_sq[0] + t.C[r][1] * omega_sq[1] + t.C[r][2] * omega_sq[2]);
  }
  // eq. 27: Σ l̄k (i θ̈k - θ̇k²) = 0, i.e. Σ (i l̄k) θ̈k = Σ l̄k θ̇k² (+ the stabilisation bias)
  const Xy b2 = l[0] * omega_sq[0] + l[1] * omega_sq[1] + l[2] * omega_sq[2] + closure_bias;

  // the free acceleration k and the pair i < j solved for; the inverse problem gives θ̈1, so
  // there k = 0 (its pair, coupler and rocker, is regular wherever the closed form is evaluated)
  int k = 0;
  if (!input.torque_unknown && !(sin23 >= sin12 && sin23 >= sin13)) k = sin13 >= sin12 ? 1 : 2;
  const int i = k == 0 ? 1 : 0, j = k == 2 ? 1 : 2;
  const Xy &li = l[i], &lj = l[j], &lk = l[k];
  const double inv_det = 1.0 / cross(li, lj);
  // Σ i l̄ θ̈ = b2 with θ̈_k = 1, b2 = 0 (Θ) and with θ̈_k = 0 (g); i l̄ crossed with i l̄' is
  // l̄ × l̄', and x × i l̄ = x·l̄
  double dtheta_dthetak[3], g[3];
  dtheta_dthetak[k] = 1.0;
  dtheta_dthetak[i] = -cross(lk, lj) * inv_det;
  dtheta_dthetak[j] = -cross(li, lk) * inv_det;
  g[k] = 0.0;
  g[i] = dot(b2, lj) * inv_det;
  g[j] = -dot(b2, li) * inv_det;
  auto M_times = [&t](const double* v, int r) {
    return t.M[r][0] * v[0] + t.M[r][1] * v[1] + t.M[r][2] * v[2];
  };
  auto dot3 = [](const double* a, const double* b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };

  double alpha[3];
  double tau = 0.0;
  const double M_dtheta_dthetak[3] = {M_times(dtheta_dthetak, 0), M_times(dtheta_dthetak, 1),
                                      M_times(dtheta_dthetak, 2)};
  const double alpha_k = !input.torque_unknown
                             ? (dot3(dtheta_dthetak, b1) - dot3(M_dtheta_dthetak, g)) /
                                   dot3(dtheta_dthetak, M_dtheta_dthetak)
                             : input.alpha1;
  for (int r = 0; r < 3; ++r) alpha[r] = dtheta_dthetak[r] * alpha_k + g[r];
  // rows i and j for R̄A3: i l̄_i · R̄ = q_i, i l̄_j · R̄ = q_j, so R̄ = (q_i l̄_j - q_j l̄_i)/det
  const double q[3] = {b1[0] - M_times(alpha, 0), b1[1] - M_times(alpha, 1),
                       b1[2] - M_times(alpha, 2)};
  const Xy RA3 = (q[i] * lj - q[j] * li) * inv_det;
  // inverse: the crank's row, with tau on its right-hand side
  if (input.torque_unknown) tau = -q[0] + dot(perp(l[0]), RA3);

  FourBarState& x = out.state;
  x.theta1 = s.theta1;
  x.theta2 = s.theta2;
  x.theta3 = s.theta3;
  x.omega1 = s.omega1;
  x.omega2 = s.omega2;
  x.omega3 = s.omega3;
  x.alpha1 = alpha[0];
  x.alpha2 = alpha[1];
  x.alpha3 = alpha[2];

  // eq. 28: m_tot r̈_S = ΣF̄k - R̄A0 - R̄A3 (F̄k with the weights), r̈_S from eq. 16:
  // r̄_S = -ā14' - ā21 - ā32, each a constant factor times its link vector
  auto link_acc = [](const Xy& lv, double w, double a) { return a * perp(lv) - w * w * lv; };
  const Xy a_S = -(cmul(c.a14p, link_acc(l[0], s.omega1, alpha[0])) +
                   cmul(c.a21, link_acc(l[1], s.omega2, alpha[1])) +
                   cmul(c.a32, link_acc(l[2], s.omega3, alpha[2])));
  return complete_sample(model, c.F_sum - RA3 - c.total_mass * a_S, RA3, tau, out);
}

// The link vectors of a state, from its angles. Also on a closed state, where the position
// solve has them already: the state form (the DAE's right-hand side) must give bit for bit what
// the closed form gives on the same state (opened_loop_test), so both take them from the angles,
// three cos/sin pairs per evaluation.
Links links_of(const FourBar& model, const FourBarState& s) {
  const LinkVectors v = link_vectors(model, pose_of(s));
  return {{xy(v.l1), xy(v.l2), xy(v.l3)}};
}

Expected<DynamicsSample, DynamicsError> one_instant(const FourBar& model, double theta1,
                                                    double omega1, CrankInput input) {
  const OpenedLoopConstants c = opened_loop_constants(model);
  return evaluated(model, theta1, omega1, [&](const ClosedInstant& instant, DynamicsSample& out) {
    return opened_loop_at(model, c, instant, input, out);
  });
}

}  // namespace

namespace detail {

OpenedLoopConstants opened_loop_constants(const FourBar& model) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m1 = L1.mass, m2 = L2.mass, m3 = L3.mass, mt = m1 + m2 + m3;
  const OpenedLoopFactors f = opened_loop_factors(model);
  auto sq = [](double v) { return v * v; };
  OpenedLoopConstants c;
  c.M11 = L1.inertia + m1 * (sq(L1.e) + sq(L1.f)) + (m2 + m3) * sq(L1.length);
  c.M22 = L2.inertia + m2 * (sq(L2.e) + sq(L2.f)) + m3 * sq(L2.length);
  c.M33 = L3.inertia + m3 * (sq(L3.e) + sq(L3.f));
  c.kappa12 = mt * xy(f.a21);
  c.kappa13 = mt * xy(f.a32);
  // eq. 25 with F̄k = applied force + m_k ḡ. The paper prints the moments in principal vectors
  // divided by a mass ((m2+m3)/m1 <i ā12, F̄1>, (m1+m2)/m2 <i ā21, F̄2> + m3/m2 <i ā23, F̄2>,
  // m_tot/m3 <i ā32, F̄3>); those quotients are differences of O(m_tot) terms that are O(m_k),
  // so at a small mass they lose ~eps·m_tot/m_k (docs/failure-domains.md). Here the same moments,
  // m_k r̄_k - m_k r̄_joint = m_k s̄_k l̄_k/l_k divided through exactly: <i s̄_k l̄_k/l_k, F̄k> = l̄_k ×
  // conj(s̄_k/l_k) F̄k, which divide by no mass; the forces on the links beyond act at the second
  // joint, l̄_k × F̄.
  const Xy F1 = xy(model.loads.crank.force + m1 * model.loads.gravity);
  const Xy F2 = xy(model.loads.coupler.force + m2 * model.loads.gravity);
  const Xy F3 = xy(model.loads.rocker.force + m3 * model.loads.gravity);
  auto relative_com = [](const Link& link) {
    return Xy{link.e / link.length, link.f / link.length};
  };
  c.H1 = cmul_conj(relative_com(L1), F1) + (F2 + F3);
  c.H2 = cmul_conj(relative_com(L2), F2) + F3;
  c.H3 = cmul_conj(relative_com(L3), F3);
  c.a14p = xy(f.a14p);
  c.a21 = xy(f.a21);
  c.a32 = xy(f.a32);
  c.F_sum = F1 + F2 + F3;
  c.total_mass = mt;
  c.inv_l1l2 = 1.0 / (L1.length * L2.length);
  c.inv_l1l3 = 1.0 / (L1.length * L3.length);
  c.inv_l2l3 = 1.0 / (L2.length * L3.length);
  return c;
}

}  // namespace detail

OpenedLoopTerms opened_loop_terms(const FourBar& model, const Pose& pose) {
  const LinkVectors v = link_vectors(model, pose);
  const Terms t = terms(opened_loop_constants(model), model, {{xy(v.l1), xy(v.l2), xy(v.l3)}});
  OpenedLoopTerms out;
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) {
      out.M(r, col) = t.M[r][col];
      out.C(r, col) = t.C[r][col];
    }
    out.Q(r) = t.Q[r];
  }
  // eq. 24: D_j = i l̄_j = (-l_j sin θ_j, l_j cos θ_j)
  out.D.row(0) = perp(v.l1).transpose();
  out.D.row(1) = perp(v.l2).transpose();
  out.D.row(2) = perp(v.l3).transpose();
  return out;
}

namespace detail {

std::optional<Failure> opened_loop_at(const FourBar& model, const OpenedLoopConstants& c,
                                      const ClosedInstant& instant, CrankInput input,
                                      DynamicsSample& out) {
  return solve(c, model, instant.state, links_of(model, instant.state), input, Xy{}, out);
}

}  // namespace detail

Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1) {
  return one_instant(model, theta1, omega1, CrankInput::forward());
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1) {
  return one_instant(model, theta1, omega1, CrankInput::inverse(alpha1));
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     const FourBarState& state,
                                                                     const Vec2& closure_bias) {
  Expected<DynamicsSample, DynamicsError> result;
  if (const auto failure = solve(opened_loop_constants(model), model, state, links_of(model, state),
                                 CrankInput::forward(), xy(closure_bias), *result)) {
    result = Unexpected(failure->error());
  }
  return result;
}

}  // namespace bd::core
