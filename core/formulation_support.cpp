#include "core/formulation_support.hpp"

#include <cmath>
#include <cstdio>

namespace bd::core {

Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1) {
  const auto pose = solve_position(model, theta1);
  if (!pose) {
    return Unexpected(DynamicsError{DynamicsError::Kind::kAssembly, theta1, pose.error().what()});
  }
  const double sin_mu = std::sin(pose->theta3 - pose->theta2);
  if (!(std::abs(sin_mu) >= kSingularSin)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "sin(theta3 - theta2) = %.3g: coupler and rocker are aligned (dead centre)",
                  sin_mu);
    return Unexpected(DynamicsError{DynamicsError::Kind::kSingular, theta1, buf});
  }
  return *pose;
}

Expected<DynamicsSample, DynamicsError> completed_sample(const FourBar& model, DynamicsSample s) {
  s.Fsh = s.RA0 + s.RA3;
  s.Msh = model.frame_length * s.RA3.y() - s.tau;
  const FourBarState& x = s.state;
  const bool finite = std::isfinite(x.omega2) && std::isfinite(x.omega3) &&
                      std::isfinite(x.alpha1) && std::isfinite(x.alpha2) &&
                      std::isfinite(x.alpha3) && s.RA0.allFinite() && s.RA3.allFinite() &&
                      std::isfinite(s.tau);
  if (!finite) {
    return Unexpected(DynamicsError{DynamicsError::Kind::kNonFinite, x.theta1,
                                    "non-finite acceleration, reaction or torque"});
  }
  return s;
}

}  // namespace bd::core
