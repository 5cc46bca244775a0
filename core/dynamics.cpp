#include "core/dynamics.hpp"

#include <cstdio>

#include "core/mass_matrix.hpp"

namespace bd::core {

std::string DynamicsError::what() const {
  if (kind == Kind::kAssembly) return detail;  // AssemblyError::what() names theta1 already
  const char* kind_text = kind == Kind::kAssembly   ? "assembly failure"
                          : kind == Kind::kSingular ? "singular position"
                                                    : "non-finite result";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s at theta1 = %.6g rad: ", kind_text, theta1);
  return buf + detail;
}

const char* to_string(Formulation f) {
  switch (f) {
    case Formulation::kMassMatrix: return "mass-matrix";
  }
  return "?";
}

Expected<DynamicsSample, DynamicsError> forward_dynamics(const FourBar& model, double theta1,
                                                         double omega1, Formulation f) {
  switch (f) {
    case Formulation::kMassMatrix: break;
  }
  return forward_dynamics_mass_matrix(model, theta1, omega1);
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics(const FourBar& model, double theta1,
                                                         double omega1, double alpha1,
                                                         Formulation f) {
  switch (f) {
    case Formulation::kMassMatrix: break;
  }
  return inverse_dynamics_mass_matrix(model, theta1, omega1, alpha1);
}

}  // namespace bd::core
