// The closed loop with complex equivalent masses (paper §4.1).
//
// Notation. Planar vectors are complex numbers; ⟨x̄, ȳ⟩ = Re(x̄* ȳ) (§2.1), so ⟨i x̄, ȳ⟩ = x̄ × ȳ.
// In the per-instant code they are Xy (core/detail/xy.hpp): x̄ ȳ is cmul(x, y), x̄* ȳ cmul_conj.
// Link k has the complex masses m̄kp = m_k (1 - s̄k/lk) at its first joint and m̄kq = m_k s̄k/lk at
// its second (eq. 29); for the coupler m̄2p = m2a - i m2c at A1 and m̄2q = m2b + i m2c at A2.
// With A0 = 0 and A2 = A3 - l̄3 the mass centres, times their masses, are (eq. 33)
//   m1 r̄1 = m̄1q l̄1,   m2 r̄2 = m̄2p l̄1 + m̄2q (A3 - l̄3),   m3 r̄3 = m3 A3 - m̄3p l̄3,
// so θ2 enters only through the coupler's rotation (M12 = M23 = 0, M22 = I2) and the coupler's
// translation couples θ1 and θ3 through m̄2p l̄1 and m̄2q l̄3 (M13, C13).
//
// Reactions R̄A0, R̄A3 (four unknowns; forces of the mechanism ON the ground).
// (a) A translation δr̄_S of the whole mechanism (eq. 28):
//       R̄A0 + R̄A3 = Σ F̄_k - m_tot r̈_S = F̄sh.
// (b) A rotation δθ_S of the whole mechanism about S (eq. 40): δθ_k = δθ_S,
//     m_k δr̄_k = c̄_k i δθ_S, and the supports move by i δθ_S (r̄_A - r̄_S) with
//     r̄_A0 - r̄_S = ā14 + ā41 + ā34, r̄_A3 - r̄_S = ā14 + ā43 + ā34 (eq. 32). The virtual work
//       W_S = τ + Σ_k [M_k - I_k θ̈_k + ⟨i c̄_k, F̄_k - m_k r̈_k⟩/m_k]
//           = ⟨i(ā14 + ā41 + ā34), R̄A0⟩ + ⟨i(ā14 + ā43 + ā34), R̄A3⟩,
//     and with (a) and ā43 - ā41 = -l̄4 = l4:  l4 R_A3y = W_S - ⟨i(ā14 + ā41 + ā34), F̄sh⟩.
//     (a) and (b) fix the resultant force and moment (F̄sh and Msh) but not how R̄A0 and R̄A3
//     share the force along the frame.
// (c) The fourth relation. In eq. 36 the angles are independent; the loop closure
//     c̄ = l̄1 + l̄2 + l̄3 + l̄4 = 0 (eq. 1) is held by a force μ̄ whose virtual work ⟨μ̄, δc̄⟩
//     gives Q^c_j = ⟨μ̄, i l̄_j⟩ = l̄_j × μ̄. With the accelerations known, Q^c_2 and Q^c_3 are the
//     residuals of rows 2 and 3 of eq. 36 (the coupler's rotation, and the rotation about A3 of
//     the rocker side: link 3 with the coupler's complex mass m̄2q at A2), and
//       μ̄ = (Q^c_2 l̄3 - Q^c_3 l̄2) / (l̄2 × l̄3),   l̄2 × l̄3 = l2 l3 sin(θ3 - θ2),
//     regular wherever the dynamics is (row 1 follows from Σ Θ_j Q^c_j = 0). Now release A3 and
//     translate the rocker side - link 3 with the coupler's complex mass m̄2q at A2 - by δr̄,
//     crank and θ2 held: A2 and A3 move by δr̄, the coupler's centre of mass by (m̄2q/m2) δr̄ and
//     the closure by δc̄ = -δr̄. Its virtual work
//       ⟨δr̄, F̄3 - m3 r̈3⟩ + ⟨(m̄2q/m2) δr̄, F̄2 - m2 r̈2⟩ - ⟨δr̄, R̄A3⟩ - ⟨μ̄, δr̄⟩ = 0
//     gives R̄A3 = F̄3 - m3 r̈3 + (s̄2/l2)* (F̄2 - m2 r̈2) - μ̄   (m̄2q*/m2 = (s̄2/l2)*).
//     Check by Newton–Euler: with P̄1 the pin force of the crank on the coupler at A1 and P̄2 that
//     of the coupler on the rocker at A2, rows 1-3 of eq. 36 reduce to Q^c_j = l̄_j × μ̄ with
//     μ̄ = -(m̄2q* P̄1 + m̄2p* P̄2)/m2; the coupler's P̄1 - P̄2 = m2 r̈2 - F̄2 and the rocker's
//     P̄2 - R̄A3 = m3 r̈3 - F̄3 turn this into the same R̄A3.
//     We take its component along the frame (x), which (a) and (b) leave open; its y component
//     is then redundant and equals (b)'s (complex_masses_test checks both against Newton–Euler).
#include "core/fourbar/complex_masses.hpp"

#include <cmath>

#include "core/detail/complex_vector.hpp"
#include "core/fourbar/detail/formulation_support.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::ClosedInstant;
using detail::Complex;
using detail::complex_mass_constants;
using detail::ComplexMassConstants;
using detail::CrankInput;
using detail::evaluated;
using detail::Failure;
using detail::to_complex;
using detail::to_vec;
using detail::Xy;
using detail::xy;

namespace {

constexpr Complex kI{0.0, 1.0};

// ⟨x̄, ȳ⟩ = Re(x̄* ȳ), the paper's inner product
double inner(const Complex& x, const Complex& y) { return std::real(std::conj(x) * y); }

// applied force on link k plus its weight, F̄_k + m_k ḡ [N]
Vec2 applied_force(const FourBar& model, int k) {
  return link_load(model, k).force + link(model, k).mass * model.loads.gravity;
}

// s̄ = e + i f of a link [m]
Complex com_offset(const Link& l) { return {l.e, l.f}; }

// eqs. 37-39 at the link vectors l (complex_mass_equations() without the trigonometry). With
// the coupler's complex masses per unit mass on their lever arms, p = m̄2p l̄1/m2 =
// (1 - s̄2/l2) l̄1 at A1 and q = m̄2q l̄3/m2 = (s̄2/l2) l̄3 at A2 (c.w2 = s̄2/l2), eqs. 37-39 print
// |m̄2p|²/m2, <m̄2p l̄1, m̄2q l̄3>/m2, ...; written with these unit-mass weights they are the same
// numbers without the division, which loses accuracy when m2 is subnormal
// (docs/failure-domains.md). The pose enters only through ζ13 = conj(l̄1) l̄3 = (l̄1·l̄3, l̄1 × l̄3):
// m2 conj(p) q = kappa ζ13 with the constant kappa = m2 conj(1 - s̄2/l2) s̄2/l2.
ComplexMassEquations equations(const FourBar& model, const ComplexMassConstants& c, const Xy& l1,
                               const Xy& l3) {
  ComplexMassEquations eq;
  // eq. 37, last lines: I1 + m1 s1² + l1² |m̄2p|²/m2 and I3 + m3 s3'² + l3² |m̄2q|²/m2 with
  // s3' = |l3 - s̄3| the distance of S3 from A3, constant (the first, principal-vector lines
  // divide by m1 and m3; principal_vector_forms() keeps them for the tests)
  eq.M.setZero();
  eq.M(0, 0) = c.M11;
  eq.M(1, 1) = model.coupler.inertia;
  eq.M(2, 2) = c.M33;
  // M13 = -<m̄2p l̄1, m̄2q l̄3>/m2 = -m2 Re(conj(p) q) (the cos/sin line of eq. 37 is the same);
  // eq. 38: C13 = <i m̄2p l̄1, m̄2q l̄3>/m2 = m2 Im(conj(p) q)
  const Xy kz = cmul(c.kappa, cmul_conj(l1, l3));
  eq.M(0, 2) = eq.M(2, 0) = -kz.x;
  eq.C13 = kz.y;

  // eq. 39. Q1: the moment about A0 of F̄1 at S1 = s̄1 l̄1/l1 (the simplified line; the
  // principal-vector line divides by m1) and of the coupler's share m̄2p/m2 of F̄2 at A1.
  // Q3 likewise about A3, with S3 - A3 = -(l3 - s̄3) l̄3/l3 and the share m̄2q/m2 of F̄2 at A2.
  // Each is the moment of one constant force about its link (a × F = l̄ × conj(w) F for
  // a = w l̄): Q1 = M1 + l̄1 × G1, Q3 = M3 + l̄3 × G3.
  eq.Q(0) = model.loads.crank.moment + cross(l1, c.G1);
  eq.Q(1) = model.loads.coupler.moment;
  eq.Q(2) = model.loads.rocker.moment + cross(l3, c.G3);
  return eq;
}

// the convective terms Σ_k C_jk θ̇_k² of eq. 36 (only C13 = -C31 is nonzero) [N m]
Eigen::Vector3d convective_terms(const ComplexMassEquations& eq, const FourBarState& s) {
  return {eq.C13 * s.omega3 * s.omega3, 0.0, -eq.C13 * s.omega1 * s.omega1};
}

// residuals of eq. 36, Σ_k (M_jk θ̈_k + C_jk θ̇_k²) - Q_j - δ_j1 τ, at a full state
Eigen::Vector3d constraint_forces(const ComplexMassEquations& eq, const FourBarState& s,
                                  double tau) {
  const Eigen::Vector3d alpha(s.alpha1, s.alpha2, s.alpha3);
  Eigen::Vector3d Qc = eq.M * alpha + convective_terms(eq, s) - eq.Q;
  Qc(0) -= tau;
  return Qc;
}

Expected<DynamicsSample, DynamicsError> one_instant(const FourBar& model, double theta1,
                                                    double omega1, CrankInput input) {
  const ComplexMassConstants c = complex_mass_constants(model);
  return evaluated(model, theta1, omega1, [&](const ClosedInstant& instant, DynamicsSample& out) {
    return complex_masses_at(model, c, instant, input, out);
  });
}

}  // namespace

namespace detail {

ComplexMassConstants complex_mass_constants(const FourBar& model) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m2 = L2.mass;
  const EquivalentMasses e1 = equivalent_masses(L1), e2 = equivalent_masses(L2),
                         e3 = equivalent_masses(L3);
  const FrameFactors f = frame_factors(model);
  const Xy one{1.0, 0.0};
  ComplexMassConstants c;
  c.w1 = xy(com_offset(L1) / L1.length);
  c.w2 = xy(com_offset(L2) / L2.length);
  c.w3 = xy(com_offset(L3) / L3.length);
  c.mq1 = xy(e1.mq);
  c.mp2 = xy(e2.mp);
  c.mq2 = xy(e2.mq);
  c.mp3 = xy(e3.mp);
  c.F1 = xy(applied_force(model, 1));
  c.F2 = xy(applied_force(model, 2));
  c.F3 = xy(applied_force(model, 3));
  c.F_sum = c.F1 + c.F2 + c.F3;
  c.M11 = L1.inertia + L1.mass * std::norm(com_offset(L1)) +
          m2 * squared_norm(one - c.w2) * (L1.length * L1.length);
  c.M33 = L3.inertia + L3.mass * std::norm(L3.length - com_offset(L3)) +
          m2 * squared_norm(c.w2) * (L3.length * L3.length);
  c.kappa = m2 * cmul_conj(one - c.w2, c.w2);
  c.G1 = cmul_conj(c.w1, c.F1) + cmul_conj(one - c.w2, c.F2);
  c.G3 = -(cmul_conj(one - c.w3, c.F3) + cmul_conj(c.w2, c.F2));
  c.a14 = xy(f.a14);
  c.a34 = xy(f.a34);
  c.a41 = xy(f.a41 * Complex(-model.frame_length, 0.0));  // ā41 = a41 l̄4, l̄4 = -l4
  c.total_mass = total_mass(model);
  return c;
}

}  // namespace detail

namespace detail {

std::optional<Failure> complex_masses_at(const FourBar& model, const ComplexMassConstants& c,
                                         const ClosedInstant& instant, CrankInput input,
                                         DynamicsSample& out) {
  // the instant gives the rates and the dependent accelerations θ̈_k = Θ_k θ̈1 + γ_k
  const ComplexMassEquations eq = equations(model, c, instant.l1, instant.l3);
  const double dtheta2_dtheta1 = instant.tf.dtheta2_dtheta1,
               dtheta3_dtheta1 = instant.tf.dtheta3_dtheta1;
  const double gamma2 = instant.bias.gamma2, gamma3 = instant.bias.gamma3;
  const double omega1_sq = instant.state.omega1 * instant.state.omega1,
               omega3_sq = instant.state.omega3 * instant.state.omega3;
  const double M13 = eq.M(0, 2), I2 = eq.M(1, 1);

  // reduced equation: δθ = Θ δθ1 keeps the loop closed, so Σ_j Θ_j Q^c_j = 0 and
  // (Θᵀ M Θ) θ̈1 = Θᵀ (Q - M γ - C θ̇²) + τ   (τ enters Q1, Θ1 = 1), with M12 = M23 = 0
  const double inertia = c.M11 + 2.0 * M13 * dtheta3_dtheta1 +
                         I2 * dtheta2_dtheta1 * dtheta2_dtheta1 +
                         c.M33 * dtheta3_dtheta1 * dtheta3_dtheta1;
  const double rhs = (eq.Q(0) - M13 * gamma3 - eq.C13 * omega3_sq) +
                     dtheta2_dtheta1 * (eq.Q(1) - I2 * gamma2) +
                     dtheta3_dtheta1 * (eq.Q(2) - c.M33 * gamma3 + eq.C13 * omega1_sq);
  double alpha1 = 0.0, tau = 0.0;
  if (!input.torque_unknown) {
    alpha1 = rhs / inertia;
  } else {
    alpha1 = input.alpha1;
    tau = inertia * alpha1 - rhs;
  }

  set_state(instant, alpha1, out.state);
  const FourBarState& s = out.state;

  // mass centre accelerations times masses (eq. 35 in the complex masses; the principal-vector
  // brackets of m1 r̈1 and m3 r̈3 equal m̄1q l̄1 and -m̄3p l̄3 and divide by no mass either),
  // with l̄1'' = l̄1 (iθ̈1 - θ̇1²) and l̄3'' likewise
  const Xy l1_acc = s.alpha1 * perp(instant.l1) - omega1_sq * instant.l1;
  const Xy l3_acc = s.alpha3 * perp(instant.l3) - omega3_sq * instant.l3;
  const Xy m1a1 = cmul(c.mq1, l1_acc);
  const Xy m2a2 = cmul(c.mp2, l1_acc) - cmul(c.mq2, l3_acc);
  const Xy m3a3 = -cmul(c.mp3, l3_acc);

  // (a) translation of S: the resultant of the reactions; S = -ā14 - ā41 - ā34 (eq. 32) with
  // ā14 = a14 l̄1, ā34 = a34 l̄3 turning with the crank and the rocker
  const Xy a_S = -(cmul(c.a14, l1_acc) + cmul(c.a34, l3_acc));
  const Xy Fsh = c.F_sum - c.total_mass * a_S;

  // (b) rotation about S: eq. 40 gives each centre of mass's lever c̄_k about S times m_k; the
  // virtual work uses c̄_k/m_k = r̄_k - r̄_S (the rigid-rotation identity the corrected eq. 40
  // satisfies, tested). Taken directly, it divides by no mass; c̄_k/m_k would lose
  // ~eps·m_tot/m_k at a small m_k (docs/failure-domains.md). It gives R_A3y.
  const Xy rS = -(cmul(c.a14, instant.l1) + c.a41 + cmul(c.a34, instant.l3));
  double W_S = tau + model.loads.crank.moment - model.crank.inertia * s.alpha1 +
               model.loads.coupler.moment - I2 * s.alpha2 + model.loads.rocker.moment -
               model.rocker.inertia * s.alpha3;
  // centres of mass along the chain from A0: r̄1 = (s̄1/l1) l̄1, r̄2 = l̄1 + (s̄2/l2) l̄2,
  // r̄3 = l̄1 + l̄2 + (s̄3/l3) l̄3; ⟨i x̄, ȳ⟩ = x̄ × ȳ
  const Xy r1 = cmul(c.w1, instant.l1);
  const Xy r2 = instant.l1 + cmul(c.w2, instant.l2);
  const Xy r3 = instant.l1 + instant.l2 + cmul(c.w3, instant.l3);
  W_S += cross(r1 - rS, c.F1 - m1a1) + cross(r2 - rS, c.F2 - m2a2) + cross(r3 - rS, c.F3 - m3a3);
  // r̄_A0 - r̄_S = -r̄_S
  const double RA3y = (W_S + cross(rS, Fsh)) / model.frame_length;

  // (c) the loop-closure force μ̄ from rows 2 and 3 of eq. 36, then the rocker side's
  // translation along the frame gives R_A3x
  const double Qc2 = I2 * s.alpha2 - eq.Q(1);
  const double Qc3 = M13 * s.alpha1 + c.M33 * s.alpha3 - eq.C13 * omega1_sq - eq.Q(2);
  const Xy mu = (Qc2 * instant.l3 - Qc3 * instant.l2) * instant.inv_l2_x_l3;
  const Xy RA3_rocker_side = c.F3 - m3a3 + cmul_conj(c.w2, c.F2 - m2a2) - mu;

  const Xy RA3{RA3_rocker_side.x, RA3y};
  return complete_sample(model, Fsh - RA3, RA3, tau, out);
}

}  // namespace detail

ComplexMassEquations complex_mass_equations(const FourBar& model, const Pose& pose) {
  const LinkVectors l = link_vectors(model, pose);
  return equations(model, complex_mass_constants(model), xy(l.l1), xy(l.l3));
}

PrincipalVectorForms principal_vector_forms(const FourBar& model, const Pose& pose) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m1 = L1.mass, m2 = L2.mass, m3 = L3.mass;
  const LinkVectors l = link_vectors(model, pose);
  const Complex l1 = to_complex(l.l1), l3 = to_complex(l.l3);
  const EquivalentMasses e2 = equivalent_masses(L2);
  const FrameVectors v = frame_vectors(model, pose);
  const Complex a14 = to_complex(v.a14), a34 = to_complex(v.a34), a12p = to_complex(v.a12p),
                a32p = to_complex(v.a32p);
  // the complex masses that eq. 33 puts on the principal vectors
  const Complex k14 = m1 + e2.mq + m3;  // m1 + m2b + i m2c + m3, on ā14
  const Complex k34 = m1 + e2.mp + m3;  // m1 + m2a - i m2c + m3, on ā34
  const Complex F1 = to_complex(applied_force(model, 1)), F2 = to_complex(applied_force(model, 2)),
                F3 = to_complex(applied_force(model, 3));
  const double sq_mp = std::norm(e2.mp), sq_mq = std::norm(e2.mq);  // (m2a)²+(m2c)², (m2b)²+..

  PrincipalVectorForms f;
  f.M11 = L1.inertia + std::norm(a14) / m1 * std::norm(k14) +
          (std::norm(a12p) / m1 + std::norm(l1) / m2) * sq_mp +
          2.0 * inner(k14 * a14, e2.mp * a12p) / m1;
  f.M33 = L3.inertia + std::norm(a34) / m3 * std::norm(k34) +
          (std::norm(a32p) / m3 + std::norm(l3) / m2) * sq_mq +
          2.0 * inner(k34 * a34, e2.mq * a32p) / m3;
  f.Q1 = model.loads.crank.moment - inner(kI * (k14 * a14 + e2.mp * a12p), F1 / m1) +
         inner(kI * e2.mp * l1, F2 / m2);
  f.Q3 = model.loads.rocker.moment + inner(-kI * l3 * e2.mq, F2 / m2) -
         inner(kI * (k34 * a34 + e2.mq * a32p), F3 / m3);
  return f;
}

RotationAboutCentreOfMass rotation_about_centre_of_mass(const FourBar& model, const Pose& pose) {
  const double m1 = model.crank.mass, m3 = model.rocker.mass;
  const EquivalentMasses e2 = equivalent_masses(model.coupler);
  const FrameVectors v = frame_vectors(model, pose);
  const Complex a14 = to_complex(v.a14), a41 = to_complex(v.a41), a43 = to_complex(v.a43),
                a34 = to_complex(v.a34), a12p = to_complex(v.a12p), a32p = to_complex(v.a32p);
  // eq. 40 = eq. 33 minus m_k r̄_S = -m_k (ā14 + ā41 + ā34) (eq. 32); for link 3 with
  // ā41 - l̄4 = ā43. The coupler mass at A1 is m̄2p = m2a - i m2c in all three lines.
  RotationAboutCentreOfMass c;
  c.c1 = to_vec(m1 * (a34 + a41) - (e2.mq + m3) * a14 - e2.mp * a12p);
  c.c2 = to_vec((a34 + a41 + a12p) * e2.mp + (a14 + a43 + a32p) * e2.mq);
  c.c3 = to_vec(m3 * (a14 + a43) - (m1 + e2.mp) * a34 - e2.mq * a32p);
  return c;
}

Eigen::Vector3d generalised_constraint_forces(const FourBar& model, const FourBarState& state,
                                              double tau) {
  return constraint_forces(complex_mass_equations(model, pose_of(state)), state, tau);
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1) {
  return one_instant(model, theta1, omega1, CrankInput::forward());
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1,
                                                                        double alpha1) {
  return one_instant(model, theta1, omega1, CrankInput::inverse(alpha1));
}

}  // namespace bd::core
