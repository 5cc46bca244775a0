#pragma once
/// Closed-form kinematics of the four-bar (paper eqs. 2-10): positions, rates, accelerations,
/// transfer functions, joint and centre-of-mass positions, transmission angle.
#include <string>

#include "core/expected.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// Link angles [rad] with the loop closed. theta2, theta3 lie in (-pi, pi].
struct Pose {
  double theta1{}, theta2{}, theta3{};
};

/// Why the loop cannot close at a crank angle.
struct AssemblyError {
  double theta1{};  // where it failed [rad]
  double gap{};     // how far |A1A3| lies outside [|l2 - l3|, l2 + l3]: > 0 above, < 0 below [m]
  /// "loop cannot close at theta1 = 2.094 rad: |A1A3| exceeds l2 + l3 by 0.1 m"
  std::string what() const;
};

/// Closes the loop A0-A1-A2-A3 for crank angle theta1 [rad] on the given branch (eqs. 2-4).
/// Fails, without throwing, where l23 = |A1A3| lies outside [|l2 - l3|, l2 + l3].
Expected<Pose, AssemblyError> solve_position(const FourBar& model, double theta1, Branch branch);
/// Same on the model's own branch.
Expected<Pose, AssemblyError> solve_position(const FourBar& model, double theta1);

/// Link vectors l̄1, l̄2, l̄3 in ground axes [m].
struct LinkVectors {
  Vec2 l1, l2, l3;
};
/// The link vectors at the angles of a pose (closed or not): three cos/sin pairs.
LinkVectors link_vectors(const FourBar& model, const Pose& pose);

/// A closed pose together with its link vectors as the position solve produces them (eq. 4).
/// The dynamics solves the loop once per instant and works with these vectors, so it spends no
/// atan2 → cos/sin round trips; they equal link_vectors(model, pose) to round-off.
struct ClosedLoop {
  Pose pose;
  LinkVectors l;  // [m]
};
/// solve_position() that also returns the link vectors; fails in the same way.
Expected<ClosedLoop, AssemblyError> solve_loop(const FourBar& model, double theta1, Branch branch);
/// The same with the crank vector l̄1 = l1·(cos theta1, sin theta1) [m] given, for a caller that
/// has it already (a driven sweep turns it from sample to sample); theta1 is only recorded.
Expected<ClosedLoop, AssemblyError> solve_loop(const FourBar& model, double theta1, const Vec2& l1,
                                               Branch branch);

/// First-order kinematic transfer functions Θ2 = dθ2/dθ1, Θ3 = dθ3/dθ1 (eq. 7) [-].
struct TransferFunctions {
  double dtheta2_dtheta1{}, dtheta3_dtheta1{};
};
TransferFunctions transfer_functions(const FourBar& model, const Pose& pose);
/// The same from the link vectors of a closed pose (no trigonometry).
TransferFunctions transfer_functions(const LinkVectors& l);
/// The same with 1/(l̄2 × l̄3) [1/m^2] given (the divisor of every dependent rate and acceleration).
inline TransferFunctions transfer_functions(const LinkVectors& l, double inv_l2_x_l3) {
  // eq. 7 via cross products: l̄1 + l̄2 Θ2 + l̄3 Θ3 = 0 (eq. 5) crossed with l̄3 and with l̄2
  return {cross(l.l3, l.l1) * inv_l2_x_l3, cross(l.l1, l.l2) * inv_l2_x_l3};
}

/// Full kinematic state: the crank input and the dependent angles, rates and accelerations.
struct FourBarState {
  double theta1{}, omega1{}, alpha1{};  // input [rad], [rad/s], [rad/s^2]
  double theta2{}, theta3{};            // position stage [rad]
  double omega2{}, omega3{};            // velocity stage [rad/s]
  double alpha2{}, alpha3{};            // acceleration stage [rad/s^2]
};

/// Coupler and rocker rates [rad/s] for crank rate omega1 (eq. 6); needs a closed pose.
/// Returned in a state whose acceleration stage is zero.
FourBarState solve_velocity(const FourBar& model, const Pose& pose, double omega1);
/// Dependent accelerations for crank acceleration alpha1 (eqs. 9-10), filling the state's
/// acceleration stage. `state` must have its position and velocity stages filled.
FourBarState solve_acceleration(const FourBar& model, FourBarState state, double alpha1);
/// The velocity-product part of the dependent accelerations: alpha_k = Θk·alpha1 + gamma_k.
struct AccelerationBias {
  double gamma2{}, gamma3{};  // [rad/s^2]
};
AccelerationBias acceleration_bias(const FourBar& model, const FourBarState& state);
/// The same from the link vectors of the state's pose (no trigonometry).
AccelerationBias acceleration_bias(const LinkVectors& l, const FourBarState& state);
/// The same with 1/(l̄2 × l̄3) [1/m^2] given.
inline AccelerationBias acceleration_bias(const LinkVectors& l, const FourBarState& state,
                                          double inv_l2_x_l3) {
  // eq. 8: Σ l̄k α_k = -i b with b = Σ l̄k ω_k²; crossed with l̄3 and l̄2 (eqs. 9-10)
  const Vec2 b = l.l1 * (state.omega1 * state.omega1) + l.l2 * (state.omega2 * state.omega2) +
                 l.l3 * (state.omega3 * state.omega3);
  return {l.l3.dot(b) * inv_l2_x_l3, -l.l2.dot(b) * inv_l2_x_l3};
}

/// Joint positions in ground axes [m] (A0 is the origin, A3 = (l4, 0)).
struct Joints {
  Vec2 A0, A1, A2, A3;
};
Joints joint_positions(const FourBar& model, double theta1, double theta3);
inline Joints joint_positions(const FourBar& model, const Pose& p) {
  return joint_positions(model, p.theta1, p.theta3);
}
/// Centre of mass of link k = 1, 2, 3 in ground axes [m] for the given link angles.
Vec2 centre_of_mass(const FourBar& model, int k, const Pose& pose);
/// Velocity [m/s] and acceleration [m/s^2] of the centre of mass of link k.
Vec2 centre_of_mass_velocity(const FourBar& model, int k, const FourBarState& s);
Vec2 centre_of_mass_acceleration(const FourBar& model, int k, const FourBarState& s);

/// Transmission angle mu [rad] in [0, pi]: the angle between coupler and rocker at A2.
/// Good transmission near pi/2; 0 or pi are toggle (dead-centre) positions of the rocker drive.
double transmission_angle(const Pose& pose);

/// Loop-closure residual |l̄1 + l̄2 + l̄3 + l̄4| [m] of a pose (zero to round-off when closed).
double closure_residual(const FourBar& model, const Pose& pose);

/// Pose of a full state.
inline Pose pose_of(const FourBarState& s) { return {s.theta1, s.theta2, s.theta3}; }

}  // namespace bd::core
