#pragma once
/// A self-contained high-precision four-bar solver, the yardstick of the failure-domain study
/// (docs/failure-domains.md). Written on its own: closed-form positions (paper eqs. 2-4), the
/// transfer functions Θ2, Θ3 and the velocity products γ2, γ3 (eqs. 7, 9-10) from cross products,
/// and a Newton-Euler 9x9 solve for the pin forces and the crank acceleration or the drive torque.
/// It takes only the model types from core, never core's kinematics or dynamics.
///
/// Templated on the scalar: `long double` (x87 80-bit, eps = 1.1e-19) is the reference;
/// `double` is the same algorithm at working precision, which estimates the reference's own
/// error (it is ~2048 times smaller than the double instance's error, eps ratio).
#include <optional>

#include "core/fourbar/model.hpp"

namespace bd::reference {

/// Link angles [rad] of a closed (or given) pose, and sin(theta3 - theta2) computed from the
/// triangle construction (not from the angles, so it keeps its relative accuracy near 0).
template <class T>
struct RefPose {
  T theta1{}, theta2{}, theta3{};
  T sin_mu{};  // sin(theta3 - theta2) [-]
};

/// Everything at one instant (core::DynamicsSample's conventions: reactions are forces ON the
/// ground).
template <class T>
struct RefSample {
  RefPose<T> pose;
  T dtheta2_dtheta1{}, dtheta3_dtheta1{};  // transfer functions dθ2/dθ1, dθ3/dθ1 [-]
  T gamma2{}, gamma3{};                    // velocity-product accelerations [rad/s^2]
  T omega1{}, omega2{}, omega3{};          // [rad/s]
  T alpha1{}, alpha2{}, alpha3{};          // [rad/s^2]
  T RA0x{}, RA0y{}, RA3x{}, RA3y{};        // [N]
  T tau{};                                 // drive torque [N m]
  T lu_rcond{};                            // 1/condition estimate of the 9x9 (|pivot| ratio) [-]
};

/// Closes the loop at theta1 [rad] on the model's branch; empty when |A1A3| lies outside
/// [|l2 - l3|, l2 + l3] (no tolerance: the reference is strict).
template <class T>
std::optional<RefPose<T>> ref_position(const core::FourBar& model, T theta1);

/// A pose from given angles (e.g. a pose computed by core in double, to separate the error of a
/// formulation's dynamics stage from that of the shared position stage).
template <class T>
RefPose<T> ref_pose_from_angles(T theta1, T theta2, T theta3);

/// Forward dynamics (tau = 0) under the model's loads at a pose and crank rate omega1 [rad/s].
template <class T>
RefSample<T> ref_forward(const core::FourBar& model, const RefPose<T>& pose, T omega1);

/// Inverse dynamics: the drive torque for crank acceleration alpha1 [rad/s^2].
template <class T>
RefSample<T> ref_inverse(const core::FourBar& model, const RefPose<T>& pose, T omega1, T alpha1);

/// The crank angle in [0, pi] [rad] at which |A1A3| = l23_target (a limit position when the
/// target is l2 + l3 or |l2 - l3|), in long double; the mirror image is -theta.
long double limit_angle(const core::FourBar& model, long double l23_target);

}  // namespace bd::reference
