#pragma once
/// Steps every formulation of the dynamics shares: closing the loop with the singularity check,
/// and completing a sample (shaking force and moment, the non-finite check). Internal to core.
#include "core/dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/model.hpp"

namespace bd::core {

/// |sin(theta3 - theta2)| below this counts as a singular (dead-centre) position, and the dynamics
/// returns kSingular instead of a number. Near a dead centre theta1 is an ill-conditioned input:
/// the closed loop's angles move like sqrt(theta1 - limit), and every formulation's relative
/// error is measured to grow like 7.8·eps/sin² (docs/failure-domains.md). At this threshold that
/// bound is 1.7e-9, so every value returned is good to better than 2e-9; within 0.06° of a dead
/// centre the tool says "singular" rather than return a number it cannot vouch for.
inline constexpr double kSingularSin = 1e-3;

/// The pose at theta1 on the model's branch, or kAssembly / kSingular.
Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1);

/// One closed instant's kinematics, computed once and shared by all steps of a formulation (the
/// public kinematics functions would each redo the trigonometry of the pose): the position and
/// velocity stages, the link vectors straight from the position solve, and the coefficients of
/// the dependent accelerations alpha_k = Θk·alpha1 + gamma_k.
struct ClosedInstant {
  FourBarState state;     // position and velocity stages; acceleration stage zero
  LinkVectors l;          // l̄1, l̄2, l̄3 [m]
  TransferFunctions tf;   // Θ2, Θ3 [-]
  AccelerationBias bias;  // gamma2, gamma3 [rad/s^2]

  /// The state with the acceleration stage for crank acceleration alpha1 [rad/s^2] (eqs. 9-10).
  FourBarState accelerated(double alpha1) const;
};

/// The closed instant at theta1 [rad], omega1 [rad/s] on the model's branch, or kAssembly /
/// kSingular as nonsingular_pose() reports them.
Expected<ClosedInstant, DynamicsError> nonsingular_instant(const FourBar& model, double theta1,
                                                           double omega1);

/// Fills Fsh = RA0 + RA3 and Msh = l4·RA3y - tau from the sample's reactions and torque, and
/// returns it, or kNonFinite if any rate, acceleration, reaction or the torque is not finite.
Expected<DynamicsSample, DynamicsError> completed_sample(const FourBar& model, DynamicsSample s);

}  // namespace bd::core
