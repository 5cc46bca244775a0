#pragma once
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// The constants of a model that the dynamics of every instant needs: each formulation's
/// coefficients that depend on the masses, inertias, lengths and loads but not on the state
/// (link mass matrices, nodal-force shares, equivalent masses, principal-vector factors, weights
/// m_k ḡ). A loop over many instants (a simulation, a driven sweep, an optimiser's evaluation)
/// computes them once with dynamics_constants(model), as Pinocchio builds `Data data(model)`
/// once, instead of at every instant; the one-instant entry points compute what their
/// formulation needs per call.
///
/// Planar vectors are Xy (core/detail/xy.hpp), the type of the per-instant kernels; they stand
/// for complex numbers where the paper writes them: w = (u, v) multiplies as u + i v (cmul).
#include "core/detail/xy.hpp"
#include "core/expected.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core::detail {

/// Mass-matrix formulation (core/fourbar/mass_matrix.hpp). The 2x2 blocks of a link's mass matrix
/// (eq. 45) are a scalar on the diagonal and a complex multiplication off it: with joints p, q,
/// M_e = [I_q/l² 1, B; Bᵀ, I_p/l² 1] and B·v = w ⊗ v, w = (-I_red/l², m f/l), Bᵀ·v = conj(w) ⊗ v.
struct MassMatrixConstants {
  double d1{}, d2{};  // diagonal of M at A1 (I_p1/l1² + I_q2/l2²) and A2 (I_p2/l2² + I_q3/l3²) [kg]
  Xy w1, w2, w3;      // off-diagonal blocks of the crank, coupler, rocker [kg]
  /// nodal forces of the applied forces and weights F̄_k + m_k ḡ at A0..A3 (eq. 46, force part;
  /// it does not depend on the pose) [N]
  Xy F_A0, F_A1, F_A2, F_A3;
  double couple1{}, couple2{}, couple3{};  // M_k / l_k²: link k's moment as the couple
                                           // ±(M_k/l_k²)·i l̄_k at its joints (eq. 46) [N/m]
  double inv_l1_sq{};                      // 1/l1²: a unit drive moment's couple [1/m²]
};
MassMatrixConstants mass_matrix_constants(const FourBar& model);

/// Complex-masses formulation (core/fourbar/complex_masses.hpp), in the notation of eqs. 29-40.
struct ComplexMassConstants {
  Xy w1, w2, w3;        // s̄_k / l_k [-]
  Xy mq1, mp2, mq2;     // complex masses m̄1q, m̄2p, m̄2q (eq. 29) [kg]
  Xy mp3;               // m̄3p [kg]
  Xy F1, F2, F3;        // F̄_k + m_k ḡ [N]
  Xy F_sum;             // F̄1 + F̄2 + F̄3 [N]
  double M11{}, M33{};  // eq. 37, the simplified forms (constant) [kg m^2]
  /// M13 = -Re(kappa ζ13) and C13 = Im(kappa ζ13) with ζ13 = conj(l̄1) l̄3 and
  /// kappa = m2 conj(1 - s̄2/l2) s̄2/l2 [kg]
  Xy kappa;
  Xy G1, G3;            // Q1 = M1 + l̄1 × G1, Q3 = M3 + l̄3 × G3 (eq. 39) [N]
  Xy a14, a34;          // frame factors of ā14, ā34 (eq. 30) [-]
  Xy a41;               // ā41 (constant, eq. 30) [m]
  double total_mass{};  // [kg]
};
ComplexMassConstants complex_mass_constants(const FourBar& model);

/// Opened-loop formulation (core/fourbar/opened_loop.hpp), eqs. 12-25.
struct OpenedLoopConstants {
  double M11{}, M22{}, M33{};  // the diagonal of the mass matrix (constant) [kg m^2]
  /// M_jk = -Re(kappa_jk ζ_jk), C_jk = Im(kappa_jk ζ_jk) with ζ_jk = conj(l̄_j) l̄_k:
  /// kappa12 = m_tot ā21/l̄2, kappa13 = kappa23 = m_tot ā32/l̄3 [kg]
  Xy kappa12, kappa13;
  Xy H1, H2, H3;                              // Q_j = M_j + l̄_j × H_j (eq. 25) [N]
  Xy a14p, a21, a32;                          // factors of ā14', ā21, ā32 (eqs. 12-13) [-]
  Xy F_sum;                                   // Σ F̄_k + m_k ḡ [N]
  double total_mass{};                        // [kg]
  double inv_l1l2{}, inv_l1l3{}, inv_l2l3{};  // 1/(l_j l_k) [1/m²]
};
OpenedLoopConstants opened_loop_constants(const FourBar& model);

/// What the outputs derived from a sample need of the model (derived_outputs_at(),
/// core/fourbar/detail/formulation_support.hpp): per link k its centre-of-mass offset as a factor
/// of the link vector, s̄_k/l_k, so that s̄_k in ground axes is s̄_k/l_k ⊗ l̄_k (no angle, no
/// sincos), its mass, inertia and the constant force F̄_k + m_k ḡ with the applied moment.
struct DerivedConstants {
  Xy s1, s2, s3;                // s̄_k / l_k = (e_k + i f_k) / l_k [-]
  double m1{}, m2{}, m3{};      // [kg]
  double I1{}, I2{}, I3{};      // about the centres of mass [kg m^2]
  Xy F1, F2, F3;                // F̄_k + m_k ḡ [N]
  double M1{}, M2{}, M3{};      // applied moments [N m]
  double J1{}, J3{};            // counter-rotating discs on crank and rocker [kg m^2]
  double l4{};                  // frame length [m]
};
DerivedConstants derived_constants(const FourBar& model);

/// All three, and whether the model has counter-rotations (whose reactions need loads that
/// change with the state, so they take the one-instant route).
struct DynamicsConstants {
  MassMatrixConstants mass_matrix;
  OpenedLoopConstants opened_loop;
  ComplexMassConstants complex_masses;
  DerivedConstants derived;
  bool counter_rotations{};
};
/// The constants of `model` for all formulations; valid for that model only.
DynamicsConstants dynamics_constants(const FourBar& model);

/// forward_dynamics() and inverse_dynamics() (core/fourbar/dynamics.hpp) with the model's
/// constants computed once by dynamics_constants(model): what a loop over many instants of one
/// model calls (a simulation's right-hand side, a sweep). The results are those of the public
/// calls bit for bit, at less cost (docs/performance.md), but for the shaking force's and
/// moment's inertial and static parts, which they leave zero (set_derived_outputs() adds them).
/// `constants` must come from this `model`. Models with counter-rotations take the one-instant
/// route.
Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model,
                                                         const DynamicsConstants& constants,
                                                         double theta1, double omega1,
                                                         Formulation f = Formulation::kMassMatrix);
Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model,
                                                         const DynamicsConstants& constants,
                                                         double theta1, double omega1,
                                                         double alpha1,
                                                         Formulation f = Formulation::kMassMatrix);

}  // namespace bd::core::detail
