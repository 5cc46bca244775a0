#pragma once
/// The closed loop with complex equivalent masses (paper §4.1, eqs. 29-40): the coupler's mass
/// is carried by complex masses at A1 and A2, the link angles are coordinates, and the loop
/// constraint forces are eliminated by the transfer functions Θ2, Θ3 into one equation in theta1.
/// Reactions follow from virtual displacements of the centre of mass S and a rotation about S.
///
/// Masses in denominators: the mass matrix, convective term and generalised forces (eqs. 37-39)
/// divide by the coupler mass m2; the rotation about S (eq. 40) divides by m1, m2 and m3. No
/// other step divides by a link mass (the total mass only, through the principal vectors).
#include <Eigen/Core>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"

namespace bd::core {

/// Forward dynamics (tau = 0) by the complex equivalent masses.
Expected<DynamicsSample, DynamicsError> forward_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1);
/// Inverse dynamics by the complex equivalent masses.
Expected<DynamicsSample, DynamicsError> inverse_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1,
                                                                        double alpha1);

/// The coefficients of the equations of motion in the link angles (eq. 36),
///   Σ_k (M_jk θ̈_k + C_jk θ̇_k²) = Q_j + Q^c_j   (j = 1, 2, 3),
/// at one pose, with the paper's simplified forms (the last lines of eqs. 37-39).
struct ComplexMassEquations {
  Eigen::Matrix3d M;  // mass matrix, eq. 37 (M12 = M23 = 0, M22 = I2) [kg m^2]
  double C13{};       // convective coefficient, eq. 38; C31 = -C13, all others zero [kg m^2]
  Eigen::Vector3d Q;  // generalised applied forces, eq. 39, with the weights m_k ḡ added to the
                      // forces and without the drive torque (which adds to Q1) [N m]
};
ComplexMassEquations complex_mass_equations(const FourBar& model, const Pose& pose);

/// The principal-vector forms (first lines) of M11, M33 (eq. 37) and Q1, Q3 (eq. 39), which
/// divide by m1 (M11, Q1), m3 (M33, Q3) and m2. Equal to the simplified forms; kept for the
/// tests. Q3 is the corrected form: i multiplies the whole bracket
/// [(m1 + m2a - i m2c + m3) ā34 + (m2b + i m2c) ā32'], as in Q1 (printed: only its first term).
struct PrincipalVectorForms {
  double M11{}, M33{};  // [kg m^2]
  double Q1{}, Q3{};    // [N m]
};
PrincipalVectorForms principal_vector_forms(const FourBar& model, const Pose& pose);

/// Eq. 40 (corrected): in a rigid rotation δθ_S of the whole mechanism about S,
/// m_k δr̄_k = c̄_k i δθ_S with c̄_k = m_k (r̄_k - r̄_S) [kg m], written with the frame set of
/// principal vectors and the coupler's complex masses. In c̄3 the coupler mass at A1 enters as
/// m1 + m2a - i m2c (as in eqs. 30-31, 33); the paper prints m1 + m2a + i m2c.
struct RotationAboutCentreOfMass {
  Vec2 c1, c2, c3;  // [kg m]
};
RotationAboutCentreOfMass rotation_about_centre_of_mass(const FourBar& model, const Pose& pose);

/// The generalised constraint forces Q^c_j of eq. 36 [N m] at a state whose acceleration stage
/// is filled, with drive torque tau [N m] on the crank. For a consistent state they satisfy
/// Σ_j Θ_j Q^c_j = 0 and Q^c_j = l̄_j × μ̄ with one force μ̄, the multiplier of the loop closure
/// (eq. 1) in this formulation.
Eigen::Vector3d generalised_constraint_forces(const FourBar& model, const FourBarState& state,
                                              double tau);

}  // namespace bd::core
