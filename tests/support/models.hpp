#pragma once
// Test support: two four-bar models are the same design, number for number.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "core/fourbar/model.hpp"

namespace bd::testing {

/// Every field bit for bit (%.17g round trips), except the centre of mass: a study file gives it
/// in the polar form s, sigma, so e = s cos(sigma), f = s sin(sigma) come back within a few ulps
/// of s.
inline void expect_same_link(const core::Link& a, const core::Link& b, const std::string& name) {
  EXPECT_EQ(a.length, b.length) << name;
  EXPECT_EQ(a.mass, b.mass) << name;
  const double ulps = 8 * std::numeric_limits<double>::epsilon() * a.s();
  EXPECT_NEAR(a.e, b.e, ulps) << name;
  EXPECT_NEAR(a.f, b.f, ulps) << name;
  EXPECT_EQ(a.inertia, b.inertia) << name;
}

/// The same links (as above), frame, branch, loads and counter-rotations.
inline void expect_same_model(const core::FourBar& a, const core::FourBar& b) {
  for (int k = 1; k <= 3; ++k) {
    expect_same_link(core::link(a, k), core::link(b, k), core::link_name(k));
    EXPECT_EQ(core::link_load(a, k).force, core::link_load(b, k).force) << k;
    EXPECT_EQ(core::link_load(a, k).moment, core::link_load(b, k).moment) << k;
  }
  EXPECT_EQ(a.frame_length, b.frame_length);
  EXPECT_EQ(a.branch, b.branch);
  EXPECT_EQ(a.loads.gravity, b.loads.gravity);
  EXPECT_EQ(a.counter_rotations.crank.inertia, b.counter_rotations.crank.inertia);
  EXPECT_EQ(a.counter_rotations.rocker.inertia, b.counter_rotations.rocker.inertia);
  if (a.counter_rotations.crank.inertia > 0) {
    EXPECT_EQ(a.counter_rotations.crank.at, b.counter_rotations.crank.at);
  }
  if (a.counter_rotations.rocker.inertia > 0) {
    EXPECT_EQ(a.counter_rotations.rocker.at, b.counter_rotations.rocker.at);
  }
}

}  // namespace bd::testing
