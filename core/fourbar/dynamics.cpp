#include "core/fourbar/dynamics.hpp"

#include <fmt/printf.h>

#include <cstdio>

#include "core/fourbar/complex_masses.hpp"
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

Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model, double theta1,
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

Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model, double theta1,
                                                         double omega1, double alpha1,
                                                         Formulation f) {
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
