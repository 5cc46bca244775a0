// pareto_front (optimize/optimize.hpp): the ε-constraint trade-off between the RMS shaking force
// and the RMS shaking moment of the paper's four-bar with counterweights on crank and rocker.
//
// What must hold, whatever the front's shape:
// - ε decreases from the second metric's value at the first metric's optimum to (just above) its
//   own minimum, and every point meets its bound: Msh_rms <= ε · original, to the constraint
//   tolerance (1e-9 scaled; 1e-8 allows the scaling of the constraint, (Msh/limit)² - 1);
// - the first metric does not decrease as the bound tightens (a tighter bound shrinks the
//   feasible set). The local optimiser could in principle stop at different local optima, so
//   monotonicity is asked to 1e-6 of the first point's objective (far above the solver's
//   tolerance of 1e-10, far below the steps between points);
// - every point is a verified design: re-simulated by another formulation to 1e-9.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize {
namespace {

DesignProblem problem() {
  DesignProblem p;
  p.original = core::samples::paper_fourbar_unloaded();
  p.scene = core::DrivenScene{
      .theta1 = 0.0, .omega1 = 2.0 * std::numbers::pi, .revolutions = 1, .samples = 72};
  p.counterweights = {CounterweightVariables{.link = 1, .mass_max = 10.0, .distance_max = 1.0},
                      CounterweightVariables{.link = 3, .mass_max = 10.0, .distance_max = 1.0}};
  p.objective = {Term{Metric::kFshRms, 1.0}};
  return p;
}

OptimizeOptions options(Algorithm a) {
  OptimizeOptions o;
  o.algorithm = a;
  o.relative_tolerance = 1e-10;
  return o;
}

class ParetoFront : public ::testing::TestWithParam<Algorithm> {};

TEST_P(ParetoFront, IsMonotoneFeasibleAndVerified) {
  const std::vector<ParetoPoint> front =
      pareto_front(problem(), Metric::kFshRms, Metric::kMshRms, 5, options(GetParam()));
  ASSERT_EQ(front.size(), 5u);
  const double Msh0 = core::metrics(core::simulate_driven(problem().original,
                                                         std::get<core::DrivenScene>(problem().scene)))
                          .Msh_rms;  // the original's
  for (size_t i = 0; i < front.size(); ++i) {
    const OptimizeResult& r = front[i].result;
    SCOPED_TRACE("point " + std::to_string(i) + ", epsilon " + std::to_string(front[i].epsilon) +
                 ": " + r.brief_report() + " | " + r.message);
    EXPECT_TRUE(r.ok());
    EXPECT_LE(r.constraint_violation, 1e-9);
    EXPECT_LT(r.verification_error, 1e-9);
    EXPECT_LE(r.metrics.Msh_rms, front[i].epsilon * Msh0 * (1 + 1e-8));
    if (i == 0) continue;
    EXPECT_LT(front[i].epsilon, front[i - 1].epsilon);
    EXPECT_GE(r.metrics.Fsh_rms, front[i - 1].result.metrics.Fsh_rms -
                                     1e-6 * front.back().result.metrics.Fsh_rms);
  }
  // the first point is (nearly) the force-balanced design, the first metric's own minimum
  // Fsh = 0: the loose end is lexicographic, the second metric minimised with the first held
  // within 1e-3 of its range above its minimum (pareto.cpp), so the first point may sit up to
  // that far from Fsh = 0; the range's top is at most the last point's Fsh
  EXPECT_LT(front.front().result.metrics.Fsh_rms, 2e-3 * front.back().result.metrics.Fsh_rms);
  // a real trade-off: the last point's shaking force is well above zero, its moment well below
  // the first point's
  EXPECT_GT(front.back().result.metrics.Fsh_rms, 0.0);
  EXPECT_LT(front.back().epsilon, 0.9 * front.front().epsilon);
}

INSTANTIATE_TEST_SUITE_P(Solvers, ParetoFront,
                         ::testing::Values(Algorithm::kSlsqp, Algorithm::kIpopt),
                         [](const auto& p) { return std::string(to_string(p.param)); });

TEST(ParetoFront, BadArgumentsThrow) {
  try {
    (void)pareto_front(problem(), Metric::kFshRms, Metric::kMshRms, 1, options(Algorithm::kSlsqp));
    FAIL() << "one point accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "pareto_front: points must be >= 2, got 1");
  }
  try {
    (void)pareto_front(problem(), Metric::kFshRms, Metric::kFshRms, 3, options(Algorithm::kSlsqp));
    FAIL() << "the same metric twice accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "pareto_front: the two metrics must differ, got Fsh_rms twice");
  }
}

}  // namespace
}  // namespace bd::optimize
