#pragma once
// Test support for the planar balance tests: the motion they balance over (a driven revolution
// of a linkage on the general engine, and the balance layer's kinematics of its samples) and
// random four-bars to balance.
#include <gtest/gtest.h>

#include <vector>

#include "balance/planar.hpp"
#include "core/fourbar/samples.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {

namespace bp = balance::planar;
namespace cp = core::planar;

// a driven revolution of the first input (and the others at their own speeds) on the engine
inline cp::Trajectory revolution(const cp::Linkage& l, const std::vector<double>& speeds,
                                 int samples) {
  cp::DrivenScene scene;
  scene.speeds = speeds;
  scene.samples = samples;
  return cp::simulate_driven(cp::Model(l), scene);
}

inline bp::Kinematics kinematics_of(const cp::Linkage& l, const cp::Trajectory& tr) {
  const cp::Model model(l);
  const bp::InputSeries in = bp::input_series(model, tr.table);
  auto k = bp::kinematics(model, in.values, in.rates, in.accelerations);
  EXPECT_TRUE(k) << (k ? "" : k.error().detail);
  return k ? *k : bp::Kinematics{};
}

// random mass data on the paper's four-bar geometry; a Berkof coupler (dynamically two point
// masses at its joints: f2 = 0, I2 = m2 e2 (l2 - e2)) when asked
inline core::FourBar random_fourbar(Rng& rng, bool berkof = false) {
  core::FourBar fb = core::samples::paper_fourbar_unloaded();
  for (core::Link* link : {&fb.crank, &fb.coupler, &fb.rocker}) {
    link->mass = uniform(rng, 0.5, 5);
    link->e = uniform(rng, -0.3, 1.3) * link->length;
    link->f = uniform(rng, -0.4, 0.4) * link->length;
    link->inertia = uniform(rng, 0.1, 3);
  }
  if (berkof) {
    core::Link& c = fb.coupler;
    c.e = uniform(rng, 0.2, 0.8) * c.length;
    c.f = 0;
    c.inertia = c.mass * c.e * (c.length - c.e);
  }
  return fb;
}

}  // namespace bd::testing::planar
