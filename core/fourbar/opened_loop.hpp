#pragma once
/// The opened kinematic loop with principal vectors (paper §3, eqs. 12-28): the mechanism freed
/// at A3, link angles theta1..theta3 as coordinates, R̄A3 as a multiplier. One 5x5 linear system
/// per instant (eqs. 22 and 27), solved exactly by eliminating its two constraint rows, gives the
/// three angular accelerations and R̄A3; R̄A0 follows from the motion of the centre of mass
/// (eq. 28).
///
/// Signs: R̄A3 is the force of the mechanism ON the ground (as every reaction of DynamicsSample),
/// so the ground pushes the mechanism with -R̄A3 and the virtual work of eq. 21 carries -<δr̄A3,
/// R̄A3>; D_j = ∂r̄A3/∂θ_j. The drive torque tau acts on the crank from the frame and enters Q1.
#include <Eigen/Core>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// The coefficients of the three equations of motion of the opened loop (eq. 22),
///   Σ_k (M_jk θ̈_k + C_jk θ̇_k²) + D_jx RA3x + D_jy RA3y = Q_j + δ_j1·tau   (j = 1, 2, 3),
/// at link angles that are taken as independent: they need not close the loop.
struct OpenedLoopTerms {
  Eigen::Matrix3d M;              // symmetric positive definite mass matrix M_jk [kg m^2]
  Eigen::Matrix3d C;              // skew-symmetric convective coefficients C_jk (eq. 23) [kg m^2]
  Eigen::Matrix<double, 3, 2> D;  // D_jx, D_jy = ∂r̄A3/∂θ_j = i l̄_j (eq. 24) [m]
  Eigen::Vector3d Q;  // generalised applied forces incl. gravity, tau = 0 (eq. 25) [N m]
};
/// The terms of eq. 22 at the angles of `pose` (closed or not) under the model's loads.
OpenedLoopTerms opened_loop_terms(const FourBar& model, const Pose& pose);

/// Forward dynamics (tau = 0) by the opened loop.
Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1);
/// Inverse dynamics by the opened loop.
Expected<DynamicsSample, DynamicsError> inverse_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1);

/// Forward dynamics (tau = 0) of the opened loop at independent link angles and rates: the
/// position and velocity stages of `state` (theta1..3, omega1..3) are taken as given, whether or
/// not they satisfy the loop closure (eq. 26) and its rate form. The 5x5 system of eqs. 22 and 27
/// is solved with `closure_bias` [m/s^2] added to the right-hand side of eq. 27,
///   Σ_k i l̄_k θ̈_k = Σ_k l̄_k θ̇_k² + closure_bias,
/// (zero for the plain DAE; -2α ċ - β² c for Baumgarte stabilisation). The returned sample has
/// the state with all three accelerations, RA3 from the solve and RA0 from eq. 28.
/// The 5x5 matrix is regular unless the three moving links are all parallel, so dead-centre
/// (limit) positions of the crank, where coupler and rocker align, are regular here; the
/// returned error is kSingular only when every pair of links is parallel to within kSingularSin.
Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(
    const FourBar& model, const FourBarState& state, const Vec2& closure_bias = Vec2::Zero());

}  // namespace bd::core
