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
  // the link vectors from the angles: three sincos (the sweeps, which hold them from the
  // position solve, call derived_outputs_at() with theirs)
  const LinkVectors v = link_vectors(model, pose_of(s.state));
  detail::derived_outputs_at(detail::derived_constants(model), detail::xy(v.l1),
                             detail::xy(v.l2), detail::xy(v.l3), s);
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

DerivedConstants derived_constants(const FourBar& model) {
  DerivedConstants c;
  const Xy g = xy(model.loads.gravity);
  const auto per_link = [&](const Link& l, const LinkLoad& load, Xy& s, double& m, double& I,
                            Xy& F, double& M) {
    s = Xy{l.e / l.length, l.f / l.length};
    m = l.mass;
    I = l.inertia;
    F = xy(load.force) + l.mass * g;
    M = load.moment;
  };
  per_link(model.crank, model.loads.crank, c.s1, c.m1, c.I1, c.F1, c.M1);
  per_link(model.coupler, model.loads.coupler, c.s2, c.m2, c.I2, c.F2, c.M2);
  per_link(model.rocker, model.loads.rocker, c.s3, c.m3, c.I3, c.F3, c.M3);
  c.J1 = model.counter_rotations.crank.inertia;
  c.J3 = model.counter_rotations.rocker.inertia;
  c.l4 = model.frame_length;
  return c;
}

DynamicsConstants dynamics_constants(const FourBar& model) {
  return {mass_matrix_constants(model), opened_loop_constants(model), complex_mass_constants(model),
          derived_constants(model), has_counter_rotations(model)};
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
