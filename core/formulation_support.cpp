#include "core/formulation_support.hpp"

#include <cmath>
#include <cstdio>

namespace bd::core {

namespace {

// the closed loop at theta1, or kAssembly / kSingular
Expected<ClosedLoop, DynamicsError> nonsingular_loop(const FourBar& model, double theta1) {
  const auto loop = solve_loop(model, theta1, model.branch);
  if (!loop) {
    return Unexpected(DynamicsError{DynamicsError::Kind::kAssembly, theta1, loop.error().what()});
  }
  // sin(theta3 - theta2) = l̄2 × l̄3 / (l2 l3)
  const double sin_mu =
      cross(loop->l.l2, loop->l.l3) / (model.coupler.length * model.rocker.length);
  if (!(std::abs(sin_mu) >= kSingularSin)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "sin(theta3 - theta2) = %.3g: coupler and rocker are aligned (dead centre)",
                  sin_mu);
    return Unexpected(DynamicsError{DynamicsError::Kind::kSingular, theta1, buf});
  }
  return *loop;
}

}  // namespace

Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1) {
  const auto loop = nonsingular_loop(model, theta1);
  if (!loop) return Unexpected(loop.error());
  return loop->pose;
}

FourBarState ClosedInstant::accelerated(double alpha1) const {
  FourBarState s = state;
  s.alpha1 = alpha1;
  s.alpha2 = tf.Theta2 * alpha1 + bias.gamma2;
  s.alpha3 = tf.Theta3 * alpha1 + bias.gamma3;
  return s;
}

Expected<ClosedInstant, DynamicsError> nonsingular_instant(const FourBar& model, double theta1,
                                                           double omega1) {
  const auto loop = nonsingular_loop(model, theta1);
  if (!loop) return Unexpected(loop.error());
  ClosedInstant c;
  c.l = loop->l;
  c.tf = transfer_functions(c.l);
  c.state.theta1 = theta1;
  c.state.theta2 = loop->pose.theta2;
  c.state.theta3 = loop->pose.theta3;
  c.state.omega1 = omega1;
  c.state.omega2 = c.tf.Theta2 * omega1;
  c.state.omega3 = c.tf.Theta3 * omega1;
  c.bias = acceleration_bias(c.l, c.state);
  return c;
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
