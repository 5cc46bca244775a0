// Cranks that turn many times: the link angles are continuous (absolute), so after tens of turns
// they are hundreds of radians, and every angle input row must still close to round-off.
// (Regression: the input row was written l (continued angle - target), which carries the
// round-off of target's whole turns, ~1.4e-14 rad at 80 rad; Newton's stopping test, steps
// below 1e-14 of the length scale, then never passed: a driven slider-crank failed to assemble
// after ~20 turns, a free scene could not even start there, and the reduced free route reported
// a limit position that is not there. And the dae route, which integrates node coordinates,
// continued the link angles from one sample to the next only, losing whole turns when a link
// turned more than half a turn between samples.)
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

TEST(LongRuns, FreeCranksStartedFortyTurnsOnRunOnBothRoutes) {
  // free cranks started 40 to 60 turns on from the drawn angle (250 to 380 rad): no limit
  // position exists (every crank angle assembles with transmission angles away from 0 and π),
  // so both routes must complete
  Rng rng(2);
  for (int i = 0; i < 6; ++i) {
    const cp::Model model(slider_crank(rng, coin(rng)));
    const double start = cp::drawn_inputs(model)[0] + 2 * kPi * std::round(uniform(rng, 40, 60));
    const double rate = uniform(rng, 20, 40);
    for (cp::Route route : {cp::Route::kReduced, cp::Route::kDae}) {
      const cp::Trajectory tr =
          cp::simulate_free(model, cp::FreeScene{{start}, {rate}, 1.0, 101}, cp::SimulateOptions{.route = route});
      EXPECT_TRUE(tr.ok()) << "slider-crank #" << i << " (" << cp::to_string(route) << "): " << tr.message;
    }
  }
}

}  // namespace
}  // namespace bd::testing::planar

namespace bd::testing::planar {
namespace {

TEST(LongRuns, DaeRouteKeepsLinkAnglesContinuousBetweenSparseSamples) {
  // cranks at 60 to 100 rad/s sampled every 0.05 s: 3 to 5 rad, more than half a turn, between
  // samples. The link angles are continuous in time, not in the sample index: both routes must
  // give the referee's angles (the dae route continued them from one sample to the next only,
  // and lost whole turns).
  Rng rng(3);
  for (int i = 0; i < 6; ++i) {
    const cp::Linkage l = slider_crank(rng, coin(rng));
    const cp::Model model(l);
    const double rate = uniform(rng, 60, 100);
    const Glue g = glue_of(l);
    std::vector<double> times;
    for (int k = 0; k <= 20; ++k) times.push_back(k == 20 ? 1.0 : k / 20.0);
    const core::Series ref = reference_table(model, g, rf::free_run(g.mechanism, {rate}, 1.0, times));
    for (cp::Route route : {cp::Route::kReduced, cp::Route::kDae}) {
      cp::SimulateOptions o;
      o.route = route;
      o.tolerance = 1e-12;
      o.absolute_tolerance = 1e-14;
      const cp::Trajectory tr = cp::simulate_free(model, cp::FreeScene{{}, {rate}, 1.0, 21}, o);
      ASSERT_TRUE(tr.ok()) << tr.message;
      const std::string what = "slider-crank #" + std::to_string(i) + " (" + cp::to_string(route) + ")";
      const Agreement a = compare_tables(model, tr.table, ref, what);
      EXPECT_LT(a.worst.at(Family::kAngle), 1e-6) << what << ": " << a.where.at(Family::kAngle);
    }
  }
}

}  // namespace
}  // namespace bd::testing::planar
