// Link angles in a free run's samples are continuous whatever the integrator's steps: each
// sample continues the last sample's angles, and an angle input's is the integrated value. At
// loose tolerance an explicit pair's step can carry the crank more than half a turn past the
// sample being written; continuing from that last evaluation put 2π jumps into the samples.
// And a step of such a pair beyond a limit position (it cannot retry a shorter one) ends the
// run as a limit position reached, as on the four-bar.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/fourbar/samples.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"

namespace bd::core::planar {
namespace {

// a single-cylinder engine with a flywheel, coasting from 3000 rpm (5 turns in 0.1 s)
Linkage coasting_engine() {
  Linkage l;
  l.nodes = {{"O", {0, 0}, true}, {"A", {0.04, 0}, false}, {"B", {0.18, 0}, false}};
  l.links = {{"crank", {0, 1}, 1.2, 0.012, 0, 0.05}, {"rod", {1, 2}, 0.45, 0.035, 0, 0.0012}};
  l.point_masses = {{2, 0.35}};
  Slider piston;
  piston.name = "piston";
  piston.node = 2;
  piston.from = {0, 0};
  piston.to = {1, 0};
  l.sliders = {piston};
  Input crank;
  crank.name = "crank";
  crank.link = 0;
  l.inputs = {crank};
  return make_linkage(l);
}

TEST(PlanarAngles, FreeRunSamplesKeepLinkAnglesContinuousAtLooseTolerance) {
  const Model model(coasting_engine());
  const FreeScene scene{{}, {100 * std::numbers::pi}, 0.1, 1001};
  for (Integrator integrator : {Integrator::kErk3, Integrator::kErk5, Integrator::kCvodeAdams}) {
    for (Route route : {Route::kReduced, Route::kDae}) {
      SimulateOptions o;
      o.route = route;
      o.integrator = integrator;
      o.tolerance = 1e-3;
      o.absolute_tolerance = 1e-5;
      const Trajectory tr = simulate_free(model, scene, o);
      ASSERT_TRUE(tr.ok()) << to_string(route) << ": " << tr.message;
      for (const char* column : {"theta_crank", "theta_rod"}) {
        const std::vector<double> th = tr.table.column_values(column);
        double worst = 0;
        for (std::size_t i = 1; i < th.size(); ++i)
          worst = std::max(worst, std::abs(th[i] - th[i - 1]));
        // 31 rad in 1000 sample intervals: 0.03 rad each; a jump of 2π shows at once
        EXPECT_LT(worst, 0.2) << column << ", " << to_string(integrator) << ", "
                              << to_string(route);
      }
      // the crank turns one way, by about five turns (it slows and speeds up with the piston)
      const std::vector<double> crank = tr.table.column_values("theta_crank");
      EXPECT_NEAR(crank.back() - crank.front(), 10 * std::numbers::pi, 2.0)
          << to_string(integrator) << ", " << to_string(route);
    }
  }
}

// A triple rocker swings from its crank at 1 rad/s into its limit position at t = 1.30 s (crank
// 1.553 rad). On the reduced route every integrator stops there as "limit position reached":
// CVODE by its root function, an explicit pair also when a stage lands beyond the limit (it
// cannot retry a shorter step), every sample before the limit kept. (Tolerance 1e-3 for the
// pairs only: CVODE BDF there errs enough in energy that the crank turns back 2e-4 rad short of
// the limit, and the run completes.)
TEST(PlanarAngles, ReducedRouteStopsAtALimitPositionWithEveryIntegrator) {
  const Model model(linkage_of(samples::triple_rocker(), 0.0));
  const FreeScene scene{{}, {1.0}, 4.0, 201};
  for (Integrator integrator : {Integrator::kCvodeAdams, Integrator::kCvodeBdf, Integrator::kErk2,
                                Integrator::kErk3, Integrator::kErk4, Integrator::kErk5,
                                Integrator::kErk6, Integrator::kErk8}) {
    for (double tolerance : {1e-3, 1e-6, 1e-10}) {
      const bool cvode = integrator == Integrator::kCvodeAdams || integrator == Integrator::kCvodeBdf;
      if (cvode && tolerance > 1e-6) continue;
      SimulateOptions o;
      o.integrator = integrator;
      o.tolerance = tolerance;
      o.absolute_tolerance = 1e-2 * tolerance;
      const Trajectory tr = simulate_free(model, scene, o);
      const std::string what = std::string(to_string(integrator)) + " at " + std::to_string(tolerance);
      EXPECT_EQ(tr.status, SimulationStatus::kSingular) << what << ": " << tr.message;
      EXPECT_NE(tr.message.find("limit position reached"), std::string::npos) << what;
      // samples every 0.02 s up to the limit at 1.30 s: 66 (t = 0 ... 1.30), fewer by the step
      // that reached it
      EXPECT_GE(tr.table.rows(), 60u) << what;
      EXPECT_LE(tr.table.rows(), 66u) << what;
    }
  }
}

}  // namespace
}  // namespace bd::core::planar
