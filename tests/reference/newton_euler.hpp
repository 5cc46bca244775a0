#pragma once
/// The independent Newton–Euler referee of the dynamics formulations: the four-bar solved link by
/// link from first principles, with the pin forces as unknowns. It shares no code with core's
/// dynamics formulations; from core it takes only the model types and the closed-form kinematics
/// (position, transfer functions, acceleration bias), which core's kinematics tests check against
/// finite differences. Counter-rotating discs (FourBar::counter_rotations with J > 0) are extra
/// rigid bodies with their shaft bearing force and tangential mesh force as unknowns.
#include <array>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::reference {

/// Position [m], velocity [m/s] and acceleration [m/s^2] of a point, ground axes.
struct PointMotion {
  Vec2 p{0, 0}, v{0, 0}, a{0, 0};
};

/// Motion of the joints and centres of mass for a full kinematic state, computed here from the
/// link angles, rates and accelerations alone (no use of core's centre-of-mass functions).
struct LinkageMotion {
  PointMotion A1, A2;
  /// A3 reached through the chain A0 -> A1 -> A2 -> A3. For a consistent state it is
  /// (l4, 0) at rest; anything else means the state does not close the loop.
  PointMotion A3;
  std::array<PointMotion, 3> com;  // centres of mass of links 1, 2, 3
};
/// Joint and centre-of-mass motion of a state whose position, velocity and acceleration stages
/// are all filled.
LinkageMotion linkage_motion(const core::FourBar& model, const core::FourBarState& state);

/// Forward dynamics (free motion, tau = 0) under the model's loads: the returned sample has the
/// full state (angles, rates, accelerations), RA0, RA3, RC1, RC3 (zero without discs), Fsh, Msh
/// and tau = 0.
/// @throws std::domain_error if the loop cannot close at theta1, a disc's shaft sits on its
///         link's pivot, or the linear system (9x9, plus 3 rows and columns per disc) is
///         singular (a test referee; callers choose assemblable, non-singular states).
core::DynamicsSample newton_euler_forward(const core::FourBar& model, double theta1, double omega1);

/// Inverse dynamics: the drive torque tau that gives crank acceleration alpha1 [rad/s^2], with
/// the full state and all reactions.
/// @throws std::domain_error as newton_euler_forward.
core::DynamicsSample newton_euler_inverse(const core::FourBar& model, double theta1, double omega1,
                                          double alpha1);

}  // namespace bd::reference
