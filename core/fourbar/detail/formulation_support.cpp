#include "core/fourbar/detail/formulation_support.hpp"

#include <fmt/printf.h>

#include <cstdio>

namespace bd::core::detail {

DynamicsError Failure::error() const {
  std::string buf;
  switch (reason) {
    case Reason::kAssembly:
      return {DynamicsError::Kind::kAssembly, theta1, AssemblyError{theta1, value}.what()};
    case Reason::kDeadCentre:
      buf = fmt::sprintf(
          "sin(theta3 - theta2) = %.3g: coupler and rocker are aligned (dead centre)", value);
      return {DynamicsError::Kind::kSingular, theta1, buf};
    case Reason::kAllParallel:
      buf = fmt::sprintf(
          "all three moving links are parallel (largest |sin| of their relative angles "
          "%.3g): the opened-loop 5x5 system is singular",
          value);
      return {DynamicsError::Kind::kSingular, theta1, buf};
    case Reason::kNonFinite:
      break;
  }
  return {DynamicsError::Kind::kNonFinite, theta1, "non-finite acceleration, reaction or torque"};
}

Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1) {
  ClosedInstant instant;
  if (const auto failure =
          close_instant(model, theta1, crank_vector(model, theta1), 0.0, instant)) {
    return Unexpected(failure->error());
  }
  return pose_of(instant.state);
}

}  // namespace bd::core::detail
