// The closed loop with complex equivalent masses (paper §4.1).
//
// Notation. Planar vectors are complex numbers; ⟨x̄, ȳ⟩ = Re(x̄* ȳ) (§2.1), so ⟨i x̄, ȳ⟩ = x̄ × ȳ.
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
#include "core/complex_masses.hpp"

#include <cmath>

#include "core/formulation_support.hpp"

namespace bd::core {

namespace {

constexpr Complex kI{0.0, 1.0};

// ⟨x̄, ȳ⟩ = Re(x̄* ȳ), the paper's inner product
double inner(const Complex& x, const Complex& y) { return std::real(std::conj(x) * y); }

// applied force on link k plus its weight, F̄_k + m_k ḡ [N]
Complex applied_force(const FourBar& model, int k) {
  return to_complex(link_load(model, k).force + link(model, k).mass * model.loads.gravity);
}

// s̄ = e + i f of a link [m]
Complex com_offset(const Link& l) { return {l.e, l.f}; }

// the link vectors l̄1, l̄2, l̄3 as complex numbers [m]
struct ComplexLinks {
  Complex l1, l2, l3;
};
ComplexLinks complex_links(const LinkVectors& l) {
  return {to_complex(l.l1), to_complex(l.l2), to_complex(l.l3)};
}

// eqs. 37-39 from the link vectors (complex_mass_equations() without the trigonometry)
ComplexMassEquations equations(const FourBar& model, const ComplexLinks& l);

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

// Solves the complex-mass formulation at one instant. Forward when `alpha1_given` is null
// (tau = 0), inverse otherwise.
Expected<DynamicsSample, DynamicsError> solve(const FourBar& model, double theta1, double omega1,
                                              const double* alpha1_given) {
  // position and velocity stages and the velocity-product accelerations θ̈_k = Θ_k θ̈1 + γ_k,
  // once for the whole instant
  const auto instant = nonsingular_instant(model, theta1, omega1);
  if (!instant) return Unexpected(instant.error());
  const ComplexLinks l = complex_links(instant->l);
  const ComplexMassEquations eq = equations(model, l);
  const TransferFunctions& tf = instant->tf;
  const AccelerationBias& bias = instant->bias;
  const Eigen::Vector3d convective = convective_terms(eq, instant->state);
  const Eigen::Vector3d Theta(1.0, tf.Theta2, tf.Theta3);
  const Eigen::Vector3d gamma(0.0, bias.gamma2, bias.gamma3);

  // reduced equation: δθ = Θ δθ1 keeps the loop closed, so Σ_j Θ_j Q^c_j = 0 and
  // (Θᵀ M Θ) θ̈1 = Θᵀ (Q - M γ - C θ̇²) + τ   (τ enters Q1, Θ1 = 1)
  const double inertia = Theta.dot(eq.M * Theta);
  const double rhs = Theta.dot(eq.Q - eq.M * gamma - convective);
  double alpha1 = 0.0, tau = 0.0;
  if (alpha1_given == nullptr) {
    alpha1 = rhs / inertia;
  } else {
    alpha1 = *alpha1_given;
    tau = inertia * alpha1 - rhs;
  }
  const FourBarState s = instant->accelerated(alpha1);

  // mass centre accelerations times masses (eq. 35 in the complex masses; the principal-vector
  // brackets of m1 r̈1 and m3 r̈3 equal m̄1q l̄1 and -m̄3p l̄3 and divide by no mass either)
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const EquivalentMasses e1 = equivalent_masses(L1), e2 = equivalent_masses(L2),
                         e3 = equivalent_masses(L3);
  const Complex turn1 = kI * s.alpha1 - s.omega1 * s.omega1;  // l̄1'' = l̄1 (iθ̈1 - θ̇1²)
  const Complex turn3 = kI * s.alpha3 - s.omega3 * s.omega3;
  const Complex m1a1 = e1.mq * l.l1 * turn1;
  const Complex m2a2 = e2.mp * l.l1 * turn1 - e2.mq * l.l3 * turn3;
  const Complex m3a3 = -e3.mp * l.l3 * turn3;
  const Complex F1 = applied_force(model, 1), F2 = applied_force(model, 2),
                F3 = applied_force(model, 3);

  // (a) translation of S: the resultant of the reactions
  const FrameVectors a = frame_vectors(model, instant->l);
  const PointKinematics S = centre_of_mass_frame(a, s);
  const Complex Fsh = F1 + F2 + F3 - total_mass(model) * to_complex(S.a);

  // (b) rotation about S: eq. 40 gives each centre of mass's lever c̄_k about S times m_k; the
  // virtual work uses c̄_k/m_k = r̄_k - r̄_S (the rigid-rotation identity the corrected eq. 40
  // satisfies, tested). Taken directly, it divides by no mass; c̄_k/m_k would lose
  // ~eps·m_tot/m_k at a small m_k (measured: 56 % at m1 = 1e-16 kg). It gives R_A3y.
  const Complex rS = to_complex(S.r);
  double W_S = tau + model.loads.crank.moment - L1.inertia * s.alpha1 +
               model.loads.coupler.moment - L2.inertia * s.alpha2 + model.loads.rocker.moment -
               L3.inertia * s.alpha3;
  // centres of mass along the chain from A0: r̄1 = (s̄1/l1) l̄1, r̄2 = l̄1 + (s̄2/l2) l̄2,
  // r̄3 = l̄1 + l̄2 + (s̄3/l3) l̄3
  const Complex r1 = com_offset(L1) / L1.length * l.l1;
  const Complex r2 = l.l1 + com_offset(L2) / L2.length * l.l2;
  const Complex r3 = l.l1 + l.l2 + com_offset(L3) / L3.length * l.l3;
  W_S += inner(kI * (r1 - rS), F1 - m1a1) + inner(kI * (r2 - rS), F2 - m2a2) +
         inner(kI * (r3 - rS), F3 - m3a3);
  const Complex p_SA0 = to_complex(a.a14 + a.a41 + a.a34);  // r̄_A0 - r̄_S
  const double RA3y = (W_S - inner(kI * p_SA0, Fsh)) / model.frame_length;

  // (c) the loop-closure force μ̄ from rows 2 and 3 of eq. 36, then the rocker side's
  // translation along the frame gives R_A3x
  const Eigen::Vector3d Qc = constraint_forces(eq, s, tau);
  const Complex mu = (Qc(1) * l.l3 - Qc(2) * l.l2) / inner(kI * l.l2, l.l3);
  const Complex RA3_rocker_side =
      F3 - m3a3 + std::conj(com_offset(L2) / L2.length) * (F2 - m2a2) - mu;

  DynamicsSample out;
  out.state = s;
  out.tau = tau;
  out.RA3 = Vec2(RA3_rocker_side.real(), RA3y);
  out.RA0 = to_vec(Fsh) - out.RA3;
  return completed_sample(model, out);
}

}  // namespace

ComplexMassEquations complex_mass_equations(const FourBar& model, const Pose& pose) {
  return equations(model, complex_links(link_vectors(model, pose)));
}

namespace {

ComplexMassEquations equations(const FourBar& model, const ComplexLinks& l) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m2 = L2.mass;
  // the coupler's complex masses per unit mass on their lever arms: m̄2p l̄1/m2 at A1 and
  // m̄2q l̄3/m2 at A2. Eqs. 37-39 print |m̄2p|²/m2, <m̄2p l̄1, m̄2q l̄3>/m2, ...; written with the
  // unit-mass weights (1 - s̄2/l2) and s̄2/l2 they are the same numbers without the division,
  // which loses accuracy when m2 is subnormal (measured: 25 % at m2 = 4.9e-324 kg).
  const Complex w2 = com_offset(L2) / L2.length;
  const Complex p = (1.0 - w2) * l.l1, q = w2 * l.l3;

  ComplexMassEquations eq;
  // eq. 37, last lines: I1 + m1 s1² + l1² |m̄2p|²/m2 and I3 + m3 s3'² + l3² |m̄2q|²/m2 with
  // s3' = |l3 - s̄3| the distance of S3 from A3 (the first, principal-vector lines divide by m1
  // and m3; principal_vector_forms() keeps them for the tests)
  eq.M.setZero();
  eq.M(0, 0) = L1.inertia + L1.mass * std::norm(com_offset(L1)) + m2 * std::norm(p);
  eq.M(1, 1) = L2.inertia;
  eq.M(2, 2) = L3.inertia + L3.mass * std::norm(L3.length - com_offset(L3)) + m2 * std::norm(q);
  // M13 = -<m̄2p l̄1, m̄2q l̄3>/m2 (the cos/sin line of eq. 37 is the same)
  eq.M(0, 2) = eq.M(2, 0) = -m2 * inner(p, q);
  // eq. 38: C13 = <i m̄2p l̄1, m̄2q l̄3>/m2
  eq.C13 = m2 * inner(kI * p, q);

  // eq. 39. Q1: the moment about A0 of F̄1 at S1 = s̄1 l̄1/l1 (the simplified line; the
  // principal-vector line divides by m1) and of the coupler's share m̄2p/m2 of F̄2 at A1.
  // Q3 likewise about A3, with S3 - A3 = -(l3 - s̄3) l̄3/l3 and the share m̄2q/m2 of F̄2 at A2.
  const Complex F1 = applied_force(model, 1), F2 = applied_force(model, 2),
                F3 = applied_force(model, 3);
  const Complex p_A0S1 = com_offset(L1) / L1.length * l.l1;
  const Complex p_A3S3 = -(L3.length - com_offset(L3)) / L3.length * l.l3;
  eq.Q(0) = model.loads.crank.moment + inner(kI * p_A0S1, F1) + inner(kI * p, F2);
  eq.Q(1) = model.loads.coupler.moment;
  eq.Q(2) = model.loads.rocker.moment + inner(kI * p_A3S3, F3) + inner(-kI * q, F2);
  return eq;
}

}  // namespace

PrincipalVectorForms principal_vector_forms(const FourBar& model, const Pose& pose) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const double m1 = L1.mass, m2 = L2.mass, m3 = L3.mass;
  const ComplexLinks l = complex_links(link_vectors(model, pose));
  const EquivalentMasses e2 = equivalent_masses(L2);
  const FrameVectors v = frame_vectors(model, pose);
  const Complex a14 = to_complex(v.a14), a34 = to_complex(v.a34), a12p = to_complex(v.a12p),
                a32p = to_complex(v.a32p);
  // the complex masses that eq. 33 puts on the principal vectors
  const Complex k14 = m1 + e2.mq + m3;  // m1 + m2b + i m2c + m3, on ā14
  const Complex k34 = m1 + e2.mp + m3;  // m1 + m2a - i m2c + m3, on ā34
  const Complex F1 = applied_force(model, 1), F2 = applied_force(model, 2),
                F3 = applied_force(model, 3);
  const double sq_mp = std::norm(e2.mp), sq_mq = std::norm(e2.mq);  // (m2a)²+(m2c)², (m2b)²+..

  PrincipalVectorForms f;
  f.M11 = L1.inertia + std::norm(a14) / m1 * std::norm(k14) +
          (std::norm(a12p) / m1 + std::norm(l.l1) / m2) * sq_mp +
          2.0 * inner(k14 * a14, e2.mp * a12p) / m1;
  f.M33 = L3.inertia + std::norm(a34) / m3 * std::norm(k34) +
          (std::norm(a32p) / m3 + std::norm(l.l3) / m2) * sq_mq +
          2.0 * inner(k34 * a34, e2.mq * a32p) / m3;
  f.Q1 = model.loads.crank.moment - inner(kI * (k14 * a14 + e2.mp * a12p), F1 / m1) +
         inner(kI * e2.mp * l.l1, F2 / m2);
  f.Q3 = model.loads.rocker.moment + inner(-kI * l.l3 * e2.mq, F2 / m2) -
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
  c.c1 = m1 * (a34 + a41) - (e2.mq + m3) * a14 - e2.mp * a12p;
  c.c2 = (a34 + a41 + a12p) * e2.mp + (a14 + a43 + a32p) * e2.mq;
  c.c3 = m3 * (a14 + a43) - (m1 + e2.mp) * a34 - e2.mq * a32p;
  return c;
}

Eigen::Vector3d generalised_constraint_forces(const FourBar& model, const FourBarState& state,
                                              double tau) {
  return constraint_forces(complex_mass_equations(model, pose_of(state)), state, tau);
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1) {
  return solve(model, theta1, omega1, nullptr);
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1,
                                                                        double alpha1) {
  return solve(model, theta1, omega1, &alpha1);
}

}  // namespace bd::core
