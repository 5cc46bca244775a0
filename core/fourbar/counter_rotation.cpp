#include "core/fourbar/counter_rotation.hpp"

#include "core/fourbar/complex_masses.hpp"
#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/mass_matrix.hpp"
#include "core/fourbar/opened_loop.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::nonsingular_pose;

namespace {

// the formulations' own entry points (they know nothing of discs)
Expected<DynamicsSample, DynamicsError> bare_forward(const FourBar& m, double theta1, double omega1,
                                                     Formulation f) {
  switch (f) {
    case Formulation::kOpenedLoop:
      return forward_dynamics_opened_loop(m, theta1, omega1);
    case Formulation::kComplexMasses:
      return forward_dynamics_complex_masses(m, theta1, omega1);
    case Formulation::kMassMatrix:
      break;
  }
  return forward_dynamics_mass_matrix(m, theta1, omega1);
}

Expected<DynamicsSample, DynamicsError> bare_inverse(const FourBar& m, double theta1, double omega1,
                                                     double alpha1, Formulation f) {
  switch (f) {
    case Formulation::kOpenedLoop:
      return inverse_dynamics_opened_loop(m, theta1, omega1, alpha1);
    case Formulation::kComplexMasses:
      return inverse_dynamics_complex_masses(m, theta1, omega1, alpha1);
    case Formulation::kMassMatrix:
      break;
  }
  return inverse_dynamics_mass_matrix(m, theta1, omega1, alpha1);
}

// mesh force on the link of a disc at `at` geared to `pivot`, for link acceleration alpha
Vec2 mesh_force(const CounterRotation& c, const Vec2& pivot, double alpha) {
  if (!(c.inertia > 0)) return Vec2(0, 0);
  const Vec2 d = c.at - pivot;
  const double rho = d.norm() / 2;
  return -(c.inertia * alpha / rho) * perp(d / d.norm());
}

// a force f at point M on a link whose centre of mass is at c: force at c plus its moment
void add_load(LinkLoad& load, const Vec2& f, const Vec2& M, const Vec2& c) {
  load.force += f;
  load.moment += cross(M - c, f);
}

}  // namespace

FourBar with_disc_inertia(const FourBar& model) {
  FourBar m = model;
  m.crank.inertia += model.counter_rotations.crank.inertia;
  m.rocker.inertia += model.counter_rotations.rocker.inertia;
  m.counter_rotations = {};
  return m;
}

MeshForces mesh_forces(const FourBar& model, const FourBarState& s) {
  const Vec2 A0(0, 0), A3(model.frame_length, 0);
  return {mesh_force(model.counter_rotations.crank, A0, s.alpha1),
          mesh_force(model.counter_rotations.rocker, A3, s.alpha3)};
}

FourBar with_mesh_loads(const FourBar& model, const FourBarState& s, const MeshForces& f) {
  FourBar m = model;
  m.counter_rotations = {};
  const Pose pose = pose_of(s);
  const Vec2 A0(0, 0), A3(model.frame_length, 0);
  const CounterRotations& c = model.counter_rotations;
  // centres of mass along the open chain from A0 (the state's own angles)
  const Vec2 r1 = centre_of_mass(model, 1, pose);
  const Vec2 A2_from_A3 = A3 - model.rocker.length * unit(s.theta3);
  const Vec2 r3 =
      A2_from_A3 + model.rocker.e * unit(s.theta3) + model.rocker.f * perp(unit(s.theta3));
  if (c.crank.inertia > 0) add_load(m.loads.crank, f.crank, (A0 + c.crank.at) / 2, r1);
  if (c.rocker.inertia > 0) add_load(m.loads.rocker, f.rocker, (A3 + c.rocker.at) / 2, r3);
  return m;
}

DynamicsSample with_shaft_reactions(const FourBar& model, DynamicsSample s, const MeshForces& f) {
  s.RC1 = -f.crank;
  s.RC3 = -f.rocker;
  s.Fsh = s.RA0 + s.RA3 + s.RC1 + s.RC3;
  s.Msh = model.frame_length * s.RA3.y() - s.tau + cross(model.counter_rotations.crank.at, s.RC1) +
          cross(model.counter_rotations.rocker.at, s.RC3);
  return s;
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_with_discs(const FourBar& model,
                                                                    double theta1, double omega1,
                                                                    double alpha1, Formulation f) {
  // the link accelerations, then the bare linkage loaded by the mesh forces
  const auto pose = nonsingular_pose(model, theta1);
  if (!pose) return Unexpected(pose.error());
  const FourBarState s = solve_acceleration(model, solve_velocity(model, *pose, omega1), alpha1);
  const MeshForces forces = mesh_forces(model, s);
  const auto bare = bare_inverse(with_mesh_loads(model, s, forces), theta1, omega1, alpha1, f);
  if (!bare) return bare;
  return with_shaft_reactions(model, *bare, forces);
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_with_discs(const FourBar& model,
                                                                    double theta1, double omega1,
                                                                    Formulation f) {
  // accelerations from the equations of motion with I_k + J_k, reactions as in inverse dynamics
  const auto motion = bare_forward(with_disc_inertia(model), theta1, omega1, f);
  if (!motion) return motion;
  auto out = inverse_dynamics_with_discs(model, theta1, omega1, motion->state.alpha1, f);
  if (!out) return out;
  // free motion: the torque that reproduces it is zero up to round-off; make it exactly so
  out->Msh += out->tau;
  out->tau = 0;
  return out;
}

}  // namespace bd::core
