#pragma once
/// The dynamics at one closed instant with the model's constants, inline, for the loops over
/// instants (the overloads with DynamicsConstants, the driven sweep): the default formulation,
/// the mass matrix (core/fourbar/mass_matrix.hpp, paper §4.2), is compiled into each of them; the
/// others are calls (core/fourbar/detail/formulation_support.hpp says why). Internal to core, not
/// part of its API (core/detail/xy.hpp says what the detail folders hold).
#include <optional>

#include "core/detail/xy.hpp"
#include "core/fourbar/detail/dynamics_constants.hpp"
#include "core/fourbar/detail/formulation_support.hpp"

namespace bd::core::detail {

namespace mass_matrix_blocks {

// M·v for the moving joints' accelerations v = [v_A1; v_A2] (eq. 48 in the constants' block form)
struct JointPair {
  Xy A1, A2;
};
inline JointPair times_M(const MassMatrixConstants& c, const JointPair& v) {
  return {c.d1 * v.A1 + cmul(c.w2, v.A2), cmul_conj(c.w2, v.A1) + c.d2 * v.A2};
}
inline double dot(const JointPair& a, const JointPair& b) {
  return dot(a.A1, b.A1) + dot(a.A2, b.A2);
}

}  // namespace mass_matrix_blocks

/// The mass-matrix formulation at a closed instant of `model`, whose constants are `c` (model
/// without counter-rotations): fills `out` and returns std::nullopt, or returns why not.
inline std::optional<Failure> mass_matrix_at(const FourBar& model, const MassMatrixConstants& c,
                                             const ClosedInstant& instant, CrankInput input,
                                             DynamicsSample& out) {
  const Xy il1 = perp(instant.l1), il2 = perp(instant.l2), il3 = perp(instant.l3);  // i l̄k
  const double omega1 = instant.state.omega1, omega3 = instant.state.omega3;

  // accelerations of the moving joints [A1, A2]: r̈ = J·alpha1 + c (eqs. 50-51), with
  // A1 = l̄1 and A2 = A3 - l̄3; A0 and A3 do not move
  const mass_matrix_blocks::JointPair J{il1, -instant.tf.dtheta3_dtheta1 * il3};
  const mass_matrix_blocks::JointPair bias{
      -(omega1 * omega1) * instant.l1, (omega3 * omega3) * instant.l3 - instant.bias.gamma3 * il3};

  // nodal forces (eq. 46): the constant shares of the forces, and each link's moment as the
  // couple ±(M_k/l_k²)·i l̄k at its second and first joint
  const Xy couple1 = c.couple1 * il1, couple2 = c.couple2 * il2, couple3 = c.couple3 * il3;
  const mass_matrix_blocks::JointPair F{c.F_A1 + couple1 - couple2, c.F_A2 + couple2 - couple3};
  const Xy F_A0 = c.F_A0 - couple1, F_A3 = c.F_A3 + couple3;

  // reduced equation (eq. 47 with the virtual displacements of eq. 50): Jᵀ(M r̈ - F) = tau.
  // Forward: alpha1 from it, then M r̈ = alpha1 M J + M c; inverse: M r̈ at once.
  double alpha1 = input.alpha1, tau = 0;
  mass_matrix_blocks::JointPair Ma;  // M r̈
  if (!input.torque_unknown) {
    const mass_matrix_blocks::JointPair MJ = mass_matrix_blocks::times_M(c, J),
                                        Mc = mass_matrix_blocks::times_M(c, bias);
    alpha1 = (dot(J, F) - dot(J, Mc)) / dot(J, MJ);
    Ma = {alpha1 * MJ.A1 + Mc.A1, alpha1 * MJ.A2 + Mc.A2};
  } else {
    Ma = mass_matrix_blocks::times_M(c, {alpha1 * J.A1 + bias.A1, alpha1 * J.A2 + bias.A2});
    tau = dot(J, Ma) - dot(J, F);
  }

  // residual of every joint: r = M r̈ - F - tau n, with n the nodal forces of a unit drive
  // moment on the crank, ∓ i l̄1/l1² at A0 and A1. At the moving joints it is carried by the
  // axial forces λ of the three links (the truss elements' length constraints g_k = |l̄k|):
  // r_free = G_freeᵀ λ. At the supports r = (Gᵀλ) - R̄ (R̄ acts ON the ground).
  const Xy n1 = c.inv_l1_sq * il1;
  const Xy a_A1 = alpha1 * J.A1 + bias.A1, a_A2 = alpha1 * J.A2 + bias.A2;
  const Xy r_A1 = Ma.A1 - F.A1 - tau * n1;
  const Xy r_A2 = Ma.A2 - F.A2;
  // the supports couple to the moving joints through the crank (A0-A1) and the rocker (A3-A2)
  const Xy r_A0 = cmul(c.w1, a_A1) - F_A0 + tau * n1;
  const Xy r_A3 = cmul_conj(c.w3, a_A2) - F_A3;
  // G_freeᵀ = [e1 -e2 0; 0 e2 -e3] (∂g1/∂A1 = e1, ∂g2/∂A1 = -e2, ∂g2/∂A2 = e2, ∂g3/∂A2 = -e3,
  // e_k = l̄k/l_k) has full column rank, and r_free lies in its range (Jᵀ r_free = 0 is the
  // reduced equation), so the four equations are solved exactly by elimination, here for the
  // axial forces per unit length μ_k = λ_k/l_k: the A2 rows, μ2 l̄2 - μ3 l̄3 = r_A2, give μ2 and
  // μ3 by Cramer's rule with l̄2 × l̄3 = l2 l3 sin(theta3 - theta2), away from zero wherever the
  // dynamics is evaluated (nonsingular_instant); then the A1 rows, μ1 l̄1 = r_A1 + μ2 l̄2,
  // projected on l̄1 give μ1.
  const double mu2 = cross(r_A2, instant.l3) * instant.inv_l2_x_l3;
  const double mu3 = cross(r_A2, instant.l2) * instant.inv_l2_x_l3;
  const double mu1 = dot(instant.l1, r_A1 + mu2 * instant.l2) * c.inv_l1_sq;

  set_state(instant, alpha1, out.state);
  return complete_sample(model, -mu1 * instant.l1 - r_A0,  // R̄A0: ∂g1/∂A0 = -e1
                         mu3 * instant.l3 - r_A3,          // R̄A3: ∂g3/∂A3 = +e3
                         tau, out);
}

/// Formulation f at a closed instant, likewise (model without counter-rotations).
inline std::optional<Failure> dynamics_at(const FourBar& model, const DynamicsConstants& c,
                                          const ClosedInstant& instant, CrankInput input,
                                          Formulation f, DynamicsSample& out) {
  switch (f) {
    case Formulation::kOpenedLoop:
      return opened_loop_at(model, c.opened_loop, instant, input, out);
    case Formulation::kComplexMasses:
      return complex_masses_at(model, c.complex_masses, instant, input, out);
    case Formulation::kMassMatrix:
      break;
  }
  return mass_matrix_at(model, c.mass_matrix, instant, input, out);
}

/// A driven instant (constant crank speed omega1 [rad/s]) at crank angle theta1 [rad] with
/// crank vector l̄1 = l1·(cos theta1, sin theta1) [m]: the loop closed into `instant` (which
/// close_instant() fills whole, so one may serve many instants), formulation f's inverse
/// dynamics and the derived outputs from the instant's link vectors into `out`. The outputs a
/// model without counter-rotations does not have (their shafts' forces) are left as they are in
/// `out`: zero in a new sample. Model without counter-rotations.
inline std::optional<Failure> driven_instant_at(const FourBar& model, const DynamicsConstants& c,
                                                double theta1, const Xy& l1, double omega1,
                                                Formulation f, ClosedInstant& instant,
                                                DynamicsSample& out) {
  std::optional<Failure> failure = close_instant(model, theta1, l1, omega1, instant);
  if (!failure) failure = dynamics_at(model, c, instant, CrankInput::inverse(0.0), f, out);
  if (!failure) derived_outputs_at(c.derived, instant.l1, instant.l2, instant.l3, out);
  return failure;
}

}  // namespace bd::core::detail
