#pragma once
// Test support: the scales that relative tolerances of dynamics comparisons refer to.
#include <algorithm>
#include <cmath>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"

namespace bd::testing {

/// The other assembly branch.
inline core::Branch other(core::Branch b) {
  return b == core::Branch::kPlus ? core::Branch::kMinus : core::Branch::kPlus;
}
/// The longest link [m].
inline double longest_link(const core::FourBar& m) {
  return std::max({m.crank.length, m.coupler.length, m.rocker.length, m.frame_length});
}
/// The forces of a sample [N], at least 1.
inline double force_scale(const core::DynamicsSample& s) {
  return std::max({1.0, s.RA0.norm(), s.RA3.norm(), s.Fsh.norm()});
}
/// The moments of a sample: its forces times the longest link [N m].
inline double moment_scale(const core::FourBar& m, const core::DynamicsSample& s) {
  return force_scale(s) * std::max(1.0, longest_link(m));
}
/// The angular accelerations of a sample [rad/s^2], at least 1.
inline double acceleration_scale(const core::DynamicsSample& s) {
  return std::max(
      {1.0, std::abs(s.state.alpha1), std::abs(s.state.alpha2), std::abs(s.state.alpha3)});
}
/// The angular rates of a sample [rad/s], at least 1.
inline double rate_scale(const core::DynamicsSample& s) {
  return std::max(
      {1.0, std::abs(s.state.omega1), std::abs(s.state.omega2), std::abs(s.state.omega3)});
}

}  // namespace bd::testing
