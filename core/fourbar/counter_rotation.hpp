#pragma once
/// Counter-rotating inertias in the dynamics (core/fourbar/model.hpp CounterRotation): a disc on a
/// frame shaft, geared to the crank or the rocker with ratio -1.
///
/// The disc turns at minus its link's rate, so its kinetic energy ½ J θ̇_k² is that of extra
/// rotary inertia J on link k: the equations of motion of every formulation hold with I_k + J.
/// The reactions differ: the disc acts on link k through the gear mesh, a tangential force f_k at
/// the mesh point M = (pivot + at)/2, and its shaft carries -f_k to the frame. With
/// û = (at - pivot)/|at - pivot| and ρ = |at - pivot|/2 the disc's moment balance gives
/// f_k = -(J θ̈_k / ρ) i û, whose virtual work on the link is -J θ̈_k δθ_k. The support reactions
/// are those of the bare linkage loaded by f_k at M; the shafts add RC_k = -f_k on the ground.
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"

namespace bd::core {

/// The model with each disc's inertia added to its link (I_k + J_k) and no counter-rotations:
/// the same equations of motion, for computing accelerations.
FourBar with_disc_inertia(const FourBar& model);

/// The gear-mesh forces of the discs on the crank and the rocker [N] for the state's
/// accelerations (zero where a link has no disc).
struct MeshForces {
  Vec2 crank{0, 0}, rocker{0, 0};
};
MeshForces mesh_forces(const FourBar& model, const FourBarState& state);

/// The model without counter-rotations whose crank and rocker carry the mesh forces as applied
/// loads (force at the centre of mass plus its moment about it) at the state's pose.
FourBar with_mesh_loads(const FourBar& model, const FourBarState& state, const MeshForces& f);

/// Completes a sample of the bare linkage loaded by the mesh forces with the shafts' reactions:
/// RC1 = -f_crank, RC3 = -f_rocker, and Fsh, Msh including them.
DynamicsSample with_shaft_reactions(const FourBar& model, DynamicsSample sample,
                                    const MeshForces& f);

/// Forward (tau = 0) and inverse dynamics of a model with counter-rotations by formulation `f`.
Expected<DynamicsSample, DynamicsError> forward_dynamics_with_discs(const FourBar& model,
                                                                    double theta1, double omega1,
                                                                    Formulation f);
Expected<DynamicsSample, DynamicsError> inverse_dynamics_with_discs(const FourBar& model,
                                                                    double theta1, double omega1,
                                                                    double alpha1, Formulation f);

}  // namespace bd::core
