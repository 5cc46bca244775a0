#pragma once
/// The constant equivalent mass matrix of a binary link (paper eq. 45, García de Jalón's natural
/// coordinates / Spacar's planar truss element) and the four-bar formulation built on it
/// (paper §4.2, eqs. 47-54).
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// Equivalent mass matrix Me [kg] of a link in its joint coordinates [rpx, rpy, rqx, rqy]
/// (eq. 45): kinetic energy T = ½ ṙᵀ Me ṙ for every motion of the pseudo-rigid link.
Mat4 link_mass_matrix(const Link& link);

/// Nodal forces [Fpx, Fpy, Fqx, Fqy] [N] equivalent to a force at the centre of mass and a
/// moment on a rigid link with joints at p and q (eq. 46): same virtual work in rigid motion.
Vec4 link_nodal_forces(const Link& link, const Vec2& force, double moment, const Vec2& p,
                       const Vec2& q);

/// Constant system matrices of the four-bar: M couples the moving joints [A1x, A1y, A2x, A2y]
/// among themselves (eq. 48); Mr couples the fixed joints [A0x, A0y, A3x, A3y] to them (eq. 53).
struct SystemMassMatrices {
  Mat4 M;   // [kg]
  Mat4 Mr;  // [kg]
};
SystemMassMatrices system_mass_matrices(const FourBar& model);

/// Forward dynamics by the mass matrix (reduced equation Jᵀ(M r̈ - F) = tau).
Expected<DynamicsSample, DynamicsError> forward_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1, double omega1);
/// Inverse dynamics by the mass matrix.
Expected<DynamicsSample, DynamicsError> inverse_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1);

}  // namespace bd::core
