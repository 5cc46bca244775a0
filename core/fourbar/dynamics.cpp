#include "core/fourbar/dynamics.hpp"

#include <fmt/printf.h>

#include <cstdio>

#include "core/fourbar/complex_masses.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/counter_rotation.hpp"
#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/detail/instant_dynamics.hpp"
#include "core/fourbar/mass_matrix.hpp"
#include "core/fourbar/opened_loop.hpp"

namespace bd::core {

std::string DynamicsError::what() const {
  if (kind == Kind::kAssembly) return detail;  // AssemblyError::what() names theta1 already
  const char* kind_text = kind == Kind::kAssembly   ? "assembly failure"
                          : kind == Kind::kSingular ? "singular position"
                                                    : "non-finite result";
  const std::string buf = fmt::sprintf("%s at theta1 = %.6g rad: ", kind_text, theta1);
  return buf + detail;
}

const char* to_string(Formulation f) {
  switch (f) {
    case Formulation::kMassMatrix:
      return "mass-matrix";
    case Formulation::kOpenedLoop:
      return "opened-loop";
    case Formulation::kComplexMasses:
      return "complex-masses";
  }
  return "?";
}

void set_derived_outputs(const FourBar& model, DynamicsSample& s) {
  const Pose pose = pose_of(s.state);
  s.Fsh_inertial = Vec2(0, 0);
  s.Msh_inertial = 0.0;
  s.Fsh_static = Vec2(0, 0);
  s.Msh_static = 0.0;
  const double alpha[] = {s.state.alpha1, s.state.alpha2, s.state.alpha3};
  Vec2 net[3];  // per link: m a - (F + m g), what the joints, supports and gears must supply
  for (int k = 1; k <= 3; ++k) {
    const Link& l = link(model, k);
    const LinkLoad& load = link_load(model, k);
    const Vec2 c = centre_of_mass(model, k, pose);
    const Vec2 ma = l.mass * centre_of_mass_acceleration(model, k, s.state);
    // H about A0 = Σ (c × m v + I ω), so dH/dt = Σ (c × m a + I α)
    s.Fsh_inertial -= ma;
    s.Msh_inertial -= cross(c, ma) + l.inertia * alpha[k - 1];
    const Vec2 f = load.force + l.mass * model.loads.gravity;
    s.Fsh_static += f;
    s.Msh_static += cross(c, f) + load.moment;
    net[k - 1] = ma - f;
  }
  // the crank: net = -RA0 - RC1 - FA1 (its support, its gear, the coupler); the rocker:
  // net = -RA3 - RC3 + FA2
  s.FA1 = -net[0] - s.RA0 - s.RC1;
  s.FA2 = net[2] + s.RA3 + s.RC3;
  // a disc turns at minus its link's rate about a shaft fixed in the frame: -dH/dt = +J α_link
  s.Msh_inertial += model.counter_rotations.crank.inertia * s.state.alpha1 +
                    model.counter_rotations.rocker.inertia * s.state.alpha3;
}

namespace {

Expected<DynamicsSample, DynamicsError> with_parts(const FourBar& model,
                                                   Expected<DynamicsSample, DynamicsError> s) {
  if (s) set_derived_outputs(model, *s);
  return s;
}

Expected<DynamicsSample, DynamicsError> forward_of(const FourBar& model, double theta1,
                                                   double omega1, Formulation f) {
  if (has_counter_rotations(model)) return forward_dynamics_with_discs(model, theta1, omega1, f);
  switch (f) {
    case Formulation::kOpenedLoop:
      return forward_dynamics_opened_loop(model, theta1, omega1);
    case Formulation::kComplexMasses:
      return forward_dynamics_complex_masses(model, theta1, omega1);
    case Formulation::kMassMatrix:
      break;
  }
  return forward_dynamics_mass_matrix(model, theta1, omega1);
}

Expected<DynamicsSample, DynamicsError> inverse_of(const FourBar& model, double theta1,
                                                   double omega1, double alpha1, Formulation f) {
  if (has_counter_rotations(model)) {
    return inverse_dynamics_with_discs(model, theta1, omega1, alpha1, f);
  }
  switch (f) {
    case Formulation::kOpenedLoop:
      return inverse_dynamics_opened_loop(model, theta1, omega1, alpha1);
    case Formulation::kComplexMasses:
      return inverse_dynamics_complex_masses(model, theta1, omega1, alpha1);
    case Formulation::kMassMatrix:
      break;
  }
  return inverse_dynamics_mass_matrix(model, theta1, omega1, alpha1);
}

}  // namespace

Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model, double theta1,
                                                         double omega1, Formulation f) {
  return with_parts(model, forward_of(model, theta1, omega1, f));
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model, double theta1,
                                                         double omega1, double alpha1,
                                                         Formulation f) {
  return with_parts(model, inverse_of(model, theta1, omega1, alpha1, f));
}

namespace detail {

DynamicsConstants dynamics_constants(const FourBar& model) {
  return {mass_matrix_constants(model), opened_loop_constants(model), complex_mass_constants(model),
          has_counter_rotations(model)};
}

Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model,
                                                         const DynamicsConstants& constants,
                                                         double theta1, double omega1,
                                                         Formulation f) {
  if (constants.counter_rotations) return forward_dynamics_with_discs(model, theta1, omega1, f);
  return evaluated(model, theta1, omega1, [&](const ClosedInstant& instant, DynamicsSample& out) {
    return dynamics_at(model, constants, instant, CrankInput::forward(), f, out);
  });
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model,
                                                         const DynamicsConstants& constants,
                                                         double theta1, double omega1,
                                                         double alpha1, Formulation f) {
  if (constants.counter_rotations) {
    return inverse_dynamics_with_discs(model, theta1, omega1, alpha1, f);
  }
  return evaluated(model, theta1, omega1, [&](const ClosedInstant& instant, DynamicsSample& out) {
    return dynamics_at(model, constants, instant, CrankInput::inverse(alpha1), f, out);
  });
}

}  // namespace detail

}  // namespace bd::core
