// The optimize section's helpers: what an optimum added (mass, inertia about the pivots), metric
// look-up by name, the problem and the study of an optimum built from a study.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "balance/counterweight.hpp"
#include "core/fourbar/samples.hpp"
#include "optimize/optimize.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/method.hpp"
#include "studies/study/optimize_request.hpp"
#include "studies/study/study.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

TEST(OptimizeStudy, AddedMassAndInertiaOfCounterweightsAreABalanceStudysOwn) {
  // the textbook force balance: what force_balance reports is what the helpers find
  const core::FourBar model = core::samples::paper_fourbar_unloaded();
  const balance::ForceBalancedDesign fb =
      balance::force_balance(model, balance::CounterweightSpec{}, balance::CounterweightSpec{});
  EXPECT_NEAR(added_mass(model, fb.model), fb.added_mass, 1e-13 * fb.added_mass);
  // inertias about A0 and A3: the parallel-axis sums agree to round-off of the merge
  EXPECT_NEAR(added_inertia(model, fb.model), fb.added_inertia, 1e-12 * fb.added_inertia);
  EXPECT_EQ(added_mass(model, model), 0.0);
  EXPECT_EQ(added_inertia(model, model), 0.0);
}

TEST(OptimizeStudy, TakingMassAwayIsNegativeAndCounterRotationsCount) {
  const core::FourBar model = core::samples::paper_fourbar_unloaded();
  core::FourBar lighter = model;
  lighter.coupler.mass -= 1.0;
  lighter.coupler.inertia -= 0.5;
  EXPECT_DOUBLE_EQ(added_mass(model, lighter), -1.0);
  // the coupler about A1: I + m |s|^2 changes by -0.5 - 1 |s2|^2
  const double s2 = model.coupler.s();
  EXPECT_NEAR(added_inertia(model, lighter), -0.5 - s2 * s2, 1e-13);
  core::FourBar discs = model;
  discs.counter_rotations.crank = {2.0, Vec2(0, -1)};
  EXPECT_DOUBLE_EQ(added_inertia(model, discs), 2.0);
}

TEST(OptimizeStudy, MetricValuesByName) {
  core::Metrics m;
  m.Fsh_rms = 1;
  m.Fsh_max = 2;
  m.Msh_rms = 3;
  m.Msh_max = 4;
  m.tau_rms = 5;
  m.tau_max = 6;
  m.RA0_rms = 7;
  m.RA0_max = 8;
  m.RA3_rms = 9;
  m.RA3_max = 10;
  double expected = 1;
  for (optimize::Metric metric : optimize::kMetrics) {
    if (metric == optimize::Metric::kAddedMass) continue;
    EXPECT_EQ(metric_value(m, metric, 0.0), expected) << optimize::to_string(metric);
    expected += 1;
  }
  EXPECT_EQ(metric_value(m, optimize::Metric::kAddedMass, 12.5), 12.5);
}

TEST(OptimizeStudy, TextsSayWhatIsMinimisedUnderWhichConstraints) {
  OptimizeRequest r;
  r.objective = {{optimize::Metric::kMshRms, 1.0}, {optimize::Metric::kTauRms, 0.5}};
  EXPECT_EQ(objective_text(r), "1 x Msh_rms + 0.5 x tau_rms (each / original)");
  EXPECT_EQ(constraints_text(r), "none");
  r.force_balance = true;
  r.limits = {{optimize::Metric::kFshRms, 0.2}, {optimize::Metric::kAddedMass, 6.0}};
  EXPECT_EQ(constraints_text(r),
            "full force balance (eq. 57); Fsh_rms <= 0.2 x original; added_mass <= 6 kg");
  EXPECT_STREQ(to_string(optimize::LinkParameterVariable::Parameter::kInertia), "inertia");
}

TEST(OptimizeStudy, DesignProblemAndOptimizedStudyComeFromTheStudy) {
  Study s;
  s.name = "t";
  s.fourbar() = core::samples::paper_fourbar_unloaded();
  s.scene = core::DrivenScene{0.0, 6.28, 1, 90};
  s.tolerance = 1e-9;
  OptimizeRequest r;
  r.objective = {{optimize::Metric::kMshRms, 1.0}};
  r.counterweights = {optimize::CounterweightVariables{}};
  r.force_balance = true;
  s.optimize = r;
  const optimize::DesignProblem p = design_problem(s);
  EXPECT_EQ(p.original.crank.mass, s.fourbar().crank.mass);
  EXPECT_EQ(std::get<core::DrivenScene>(p.scene).samples, 90);
  EXPECT_EQ(p.formulation, choose_method(s).formulation);
  EXPECT_EQ(p.tolerance, 1e-9);
  EXPECT_TRUE(p.force_balance);
  EXPECT_EQ(p.counterweights.size(), 1u);
  s.method = Method::kOpenedLoop;  // a requested method is used as asked
  EXPECT_EQ(design_problem(s).formulation, core::Formulation::kOpenedLoop);

  core::FourBar design = s.fourbar();
  design.crank.mass = 5.0;
  const Study o = optimized_study(s, design);
  EXPECT_EQ(o.name, "t-optimized");
  EXPECT_EQ(o.fourbar().crank.mass, 5.0);
  EXPECT_EQ(o.method, s.method);
  EXPECT_EQ(o.tolerance, 1e-9);
  EXPECT_FALSE(o.optimize.has_value());
  EXPECT_FALSE(o.balance.has_value());
  EXPECT_TRUE(o.source.empty());
}

// A Pareto front's loosest point is the first metric's least value under the loose end's bound.
// Found by a user: the weighted example (rocker disc counterweight) with Msh_rms against
// tau_max; the front started from the design that minimises tau_max alone (no rocker
// counterweight), where SLSQP stays at the original's Msh_rms, and gave 84.84 N m at every
// point while minimising Msh_rms alone reaches 40.84 N m there. Its inner points then started
// from the same design (their neighbour missed their tighter bound), until each started from its
// neighbour brought within its bound (detail::feasible_towards()).
TEST(OptimizeStudy, AParetoFrontsPointsAreEachBoundsOptimum) {
  const Study study = parse_study(
      bd::testing::edited_example("weighted-counterweights.yaml",
                                  {{"  samples: 360", "  samples: 36"},
                                   {"  max_evaluations: 2000",
                                    "  max_evaluations: 2000\n  pareto: {first: Msh_rms, "
                                    "second: tau_max, points: 4}"}}),
      "weighted.yaml");
  const optimize::DesignProblem problem = design_problem(study);
  optimize::DesignProblem alone = problem;
  alone.objective = {optimize::Term{optimize::Metric::kMshRms, 1.0}};
  const optimize::OptimizeResult least = optimize::optimize(alone, study.optimize->options);
  ASSERT_TRUE(least.ok()) << least.message;
  const std::vector<optimize::ParetoPoint> front = optimize::pareto_front(
      problem, optimize::Metric::kMshRms, optimize::Metric::kTauMax, 4, study.optimize->options);
  ASSERT_EQ(front.size(), 4u);
  ASSERT_TRUE(front[0].result.ok()) << front[0].result.message;
  // the loosest bound is the tau_max of a design within 1e-3 of Msh_rms's range above its least
  // value (optimize/epsilon_front.hpp; the range here is about the least value, 40.8 to 84.8)
  EXPECT_LE(front[0].result.metrics.Msh_rms, least.metrics.Msh_rms * (1 + 2e-3));
  // Each inner point is its ε-constraint problem's global optimum: the same problem solved alone
  // by mlsl, which its convex relaxation's bound certifies global (the user's front gave the
  // tau_max minimiser's 84.84 N m at every inner point: it started there, where SLSQP stays).
  optimize::OptimizeOptions global = study.optimize->options;
  global.algorithm = optimize::Algorithm::kMlsl;
  for (std::size_t i = 1; i + 1 < front.size(); ++i) {
    SCOPED_TRACE("point " + std::to_string(i));
    ASSERT_TRUE(front[i].result.ok()) << front[i].result.message;
    optimize::DesignProblem alone_at = alone;
    alone_at.limits.push_back(optimize::Limit{optimize::Metric::kTauMax, front[i].epsilon});
    const optimize::OptimizeResult reference = optimize::optimize(alone_at, global);
    ASSERT_TRUE(reference.ok() && reference.global) << reference.message;
    // both converge to 1e-10 relative in x and f (the example's tolerance); the certificate
    // holds to ~1e-9 of the objective
    EXPECT_NEAR(front[i].result.metrics.Msh_rms, reference.metrics.Msh_rms,
                1e-7 * reference.metrics.Msh_rms);
    EXPECT_LT(front[i].result.metrics.Msh_rms, 0.9 * front.back().result.metrics.Msh_rms);
  }
}

// A counterweight a solver leaves at round-off of nothing is none, exactly. Found by a user: the
// weighted example under RA0_max <= 0.6 x original, where SLSQP ends with the rocker's disc at
// its mass's lower bound, and the console printed "9.66396e-36 kg ... radius 1.4e-19 m".
TEST(OptimizeStudy, ACounterweightLeftAtNothingIsExactlyNone) {
  const Study study = parse_study(
      bd::testing::edited_example(
          "weighted-counterweights.yaml",
          {{"  samples: 360", "  samples: 36"},
           {"    tau_rms: 1.0\n", "    tau_rms: 1.0\n  constraints: {RA0_max: 0.6}\n"}}),
      "weighted.yaml");
  const optimize::OptimizeResult r =
      optimize::optimize(design_problem(study), study.optimize->options);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.counterweights.size(), 2u);
  EXPECT_GT(r.counterweights[0].counterweight.mass, 1.0);  // the crank's: 7.25 kg
  EXPECT_EQ(r.counterweights[1].link, 3);
  EXPECT_EQ(r.counterweights[1].counterweight.mass, 0.0);
  EXPECT_EQ(r.counterweights[1].counterweight.radius, 0.0);
  // the design is the one evaluated: its rocker is the original's
  EXPECT_EQ(r.design.rocker.mass, study.fourbar().rocker.mass);
  EXPECT_EQ(r.design.rocker.inertia, study.fourbar().rocker.inertia);
}

// peaks: resolved in a four-bar study: the objective (a peak over the original's, the added mass
// too small for force balance) is the ratio the tables show, both resolved between the samples, and
// summary.json says how the peaks were bounded and at which added crank angles.
TEST(OptimizeStudy, ResolvedPeaksAreWhatTheTablesShow) {
  const Study study = parse_study(
      bd::testing::edited_example(
          "weighted-counterweights.yaml",
          {{"  samples: 360", "  samples: 24"},
           {"    Fsh_rms: 1.0\n    Msh_rms: 1.0\n    tau_rms: 1.0\n",
            "    Fsh_max: 1.0\n  constraints: {added_mass: 2.0}\n  peaks: resolved\n"}}),
      "weighted.yaml");
  ASSERT_TRUE(study.optimize->resolve_peaks);
  namespace fs = std::filesystem;
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "optimize-study" / "resolved";
  fs::remove_all(out);
  RunResult r = compute_study(study);
  write_run(study, r, out);
  ASSERT_TRUE(r.ok() && r.optimized && r.optimized->found()) << r.optimized->message();
  const optimize::OptimizeResult& o = r.optimized->result;
  ASSERT_FALSE(o.peak_angles.empty());
  const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
  EXPECT_EQ(j["optimize"]["peaks"], "resolved");
  ASSERT_EQ(j["optimize"]["peak_angles"].size(), o.peak_angles.size());
  EXPECT_EQ(j["optimize"]["peak_angles"][0].get<double>(), o.peak_angles[0]);
  const double ratio =
      j["optimized_metrics"]["Fsh_max"].get<double>() / j["metrics"]["Fsh_max"].get<double>();
  EXPECT_NEAR(o.objective, ratio, 1e-9);  // the smoothed peak: sqrt(r² + ε²), ε = 1e-6
}

}  // namespace
}  // namespace bd::studies
