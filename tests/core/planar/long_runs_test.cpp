// Cranks that turn many times: the link angles are continuous (absolute), so after tens of turns
// they are hundreds of radians, and every angle input row must still close to round-off.
// (Regression: the input row was written l (continued angle - target), which carries the
// round-off of target's whole turns, ~1.4e-14 rad at 80 rad; Newton's stopping test, steps
// below 1e-14 of the length scale, then never passed: a driven slider-crank failed to assemble
// after ~20 turns, and the reduced free route reported a limit position that is not there.)
#include <gtest/gtest.h>

#include <cstdio>

#include "core/planar/simulate.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

TEST(LongRuns, DrivenSliderCranksAssembleOverFortyTurns) {
  Rng rng(1);  // before the fix, #4 failed to assemble at 235.7 rad
  for (int i = 0; i < 20; ++i) {
    const cp::Model model(slider_crank(rng, coin(rng)));
    cp::DrivenScene scene;
    scene.speeds = {10.0};
    scene.samples = 90;
    scene.revolutions = 40;
    const cp::Trajectory tr = cp::simulate_driven(model, scene);
    ASSERT_TRUE(tr.ok()) << "slider-crank #" << i << ": " << tr.message;
    // the last sample against the referee: 40 turns on, the same as at the start
    const Glue g = glue_of(model.linkage());
    const double t = tr.table.column_values("t").back();
    const std::vector<rf::Sample> ref = rf::driven(g.mechanism, {10.0}, 0.0, {t});
    core::Series last;
    last.columns = tr.table.columns;
    const auto row = tr.table.row(tr.table.rows() - 1);
    last.values.assign(row.begin(), row.end());
    expect_agreement(compare_tables(model, last, reference_table(model, g, ref), "#" + std::to_string(i)),
                     1e-10, "slider-crank #" + std::to_string(i) + " after 40 turns");
  }
}

TEST(LongRuns, FreeReducedRouteFindsNoLimitPositionInACrankThatTurns) {
  // fast cranks, 80 to 200 rad in 2 s: no limit position exists (every crank angle assembles
  // with transmission angles away from 0 and π), so both routes must complete
  Rng rng(2);  // before the fix, #4 stopped at a "limit position" at -265.7 rad
  for (int i = 0; i < 6; ++i) {
    const cp::Model model(slider_crank(rng, coin(rng)));
    const double rate = uniform(rng, 40, 100);
    for (cp::Route route : {cp::Route::kReduced, cp::Route::kDae}) {
      cp::SimulateOptions o;
      o.route = route;
      const cp::Trajectory tr = cp::simulate_free(model, cp::FreeScene{{}, {rate}, 2.0, 2001}, o);
      EXPECT_TRUE(tr.ok()) << "slider-crank #" << i << " (" << cp::to_string(route) << "): " << tr.message;
      EXPECT_GT(std::abs(tr.table.column_values("theta_crank").back()), 40.0);
    }
  }
}

}  // namespace
}  // namespace bd::testing::planar
