#pragma once
/// Forward and inverse dynamics of the four-bar at one instant: all dependent angles, rates and
/// accelerations, the support reactions, the shaking force and moment, and the drive torque.
#include <string>

#include "core/expected.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// Everything the dynamics gives at one instant, in the paper's conventions: SI units, angles in
/// radians from the frame line A0→A3, and every reaction the force of the mechanism ON the
/// ground.
struct DynamicsSample {
  FourBarState state;  // angles [rad], rates [rad/s], accelerations [rad/s^2]
  Vec2 RA0{0, 0};      // force of the mechanism ON the ground at A0 [N]
  Vec2 RA3{0, 0};      // force of the mechanism ON the ground at A3 [N]
  Vec2 RC1{0, 0};      // force ON the ground at the crank's counter-rotation shaft [N]
  Vec2 RC3{0, 0};      // force ON the ground at the rocker's counter-rotation shaft [N]
  Vec2 Fsh{0, 0};      // shaking force RA0 + RA3 + RC1 + RC3 [N]
  /// shaking moment on the frame about A0: l4·RA3y - tau + at1 × RC1 + at3 × RC3 [N m]
  double Msh{};
  double tau{};  // drive torque on the crank from the frame [N m] (0 in free motion)
  /// The joint forces between moving links (set_derived_outputs()), each named after its joint:
  /// the force of the first link on the second.
  Vec2 FA1{0, 0};  // on the coupler at A1 from the crank [N]
  Vec2 FA2{0, 0};  // on the rocker at A2 from the coupler [N]
  /// The shaking force and moment split by their cause (set_derived_outputs(); Fsh = Fsh_inertial +
  /// Fsh_static and Msh = Msh_inertial + Msh_static to round-off, by Newton's law on the moving
  /// parts). The inertial part is what balancing acts on; the static part does not change with
  /// the motion's speed.
  Vec2 Fsh_inertial{0, 0};  // -Σ m a over the links' centres of mass [N]
  double Msh_inertial{};    // -dH/dt about A0, counter-rotating discs included [N m]
  Vec2 Fsh_static{0, 0};    // the weights and the applied forces [N]
  double Msh_static{};      // their moment about A0 and the applied moments [N m]
};

/// Sets the outputs of s derived from its state (angles, rates, accelerations), its reactions
/// and the model's masses and loads: the inertial and static parts of the shaking force and
/// moment, and the joint forces FA1, FA2 (Newton's law on the crank and on the rocker).
/// forward_dynamics(), inverse_dynamics() and the simulations call it on every sample they
/// return.
void set_derived_outputs(const FourBar& model, DynamicsSample& s);

/// |sin(theta3 - theta2)| below this counts as a singular (dead-centre) position, and the dynamics
/// returns kSingular instead of a number. Near a dead centre theta1 is an ill-conditioned input:
/// the closed loop's angles move like sqrt(theta1 - limit), and every formulation's relative
/// error grows like eps/sin² (docs/failure-domains.md measures the factor and derives this
/// threshold from it), so every value returned is good to better than 2e-9; within 0.06° of a
/// dead centre the tool says "singular" rather than return a number it cannot vouch for.
inline constexpr double kSingularSin = 1e-3;

/// Why the dynamics could not be evaluated at an instant.
struct DynamicsError {
  enum class Kind {
    kAssembly,   // the loop cannot close at theta1
    kSingular,   // a singular (dead-centre) position: the reduced inertia or a solve is singular
    kNonFinite,  // a non-finite value appeared
  };
  Kind kind{Kind::kAssembly};
  double theta1{};     // crank angle where it happened [rad]
  std::string detail;  // the condition, in words, with numbers
  /// One line, e.g. "singular position at theta1 = 1.234 rad: sin(theta3 - theta2) = 1e-17".
  std::string what() const;
};

/// The formulations of the equations of motion: three exact routes to the same dynamics, which
/// agree to round-off with each other and with the Newton–Euler referee of the tests.
enum class Formulation {
  kMassMatrix,     // constant equivalent mass matrix / truss element (paper §4.2)
  kOpenedLoop,     // opened kinematic loop with principal vectors, 5x5 solve (paper §3)
  kComplexMasses,  // closed loop with complex equivalent masses (paper §4.1)
};
/// "mass-matrix", "opened-loop", "complex-masses" (the study file's method names).
const char* to_string(Formulation f);
/// Every formulation, in the order the docs list them.
inline constexpr Formulation kFormulations[] = {Formulation::kMassMatrix, Formulation::kOpenedLoop,
                                                Formulation::kComplexMasses};

/// Forward dynamics (free motion, tau = 0): the crank acceleration and everything else for crank
/// angle theta1 [rad] and rate omega1 [rad/s] under the model's loads, with the model's
/// counter-rotations (core/fourbar/counter_rotation.hpp). The formulations' own entry points
/// (forward_dynamics_mass_matrix, ...) model the bare linkage and ignore counter-rotations.
Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model, double theta1,
                                                         double omega1,
                                                         Formulation f = Formulation::kMassMatrix);

/// Inverse dynamics: the drive torque tau that gives crank acceleration alpha1 [rad/s^2] at
/// theta1 [rad], omega1 [rad/s], with everything else.
Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model, double theta1,
                                                         double omega1, double alpha1,
                                                         Formulation f = Formulation::kMassMatrix);

}  // namespace bd::core
