#pragma once
/// Steps every formulation of the dynamics shares: closing the loop with the singularity check,
/// and completing a sample (shaking force and moment, the non-finite check). Internal to core.
#include "core/dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/model.hpp"

namespace bd::core {

/// |sin(theta3 - theta2)| below this is a singular (dead-centre) position: the transfer functions
/// Θ2, Θ3 grow like 1/sin and carry a relative error ~eps/sin there.
inline constexpr double kSingularSin = 1e-10;

/// The pose at theta1 on the model's branch, or kAssembly / kSingular.
Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1);

/// Fills Fsh = RA0 + RA3 and Msh = l4·RA3y - tau from the sample's reactions and torque, and
/// returns it, or kNonFinite if any rate, acceleration, reaction or the torque is not finite.
Expected<DynamicsSample, DynamicsError> completed_sample(const FourBar& model, DynamicsSample s);

}  // namespace bd::core
