// The general planar linkage's free scenes (optimize/planar.cpp): every evaluation a simulation,
// its gradients from the same run's forward sensitivities (core/planar/simulate.hpp), checked
// against central differences of full simulations; gradient methods against cobyla on the same
// problem; and no lower bound (with the reason) where the motion depends on the design.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "optimize/planar.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

namespace op = optimize::planar;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using Par = op::LinkParameterVariable::Parameter;

// A slider-crank under gravity (no other loads, no spring), its crank pushed to 20 rad/s and
// left to turn for 0.3 s (31 samples): a counterweight on the crank, and the rod's mass, centre
// of mass and inertia as variables.
op::DesignProblem free_problem(const std::string& metric) {
  Rng rng(611);
  cp::Linkage l = slider_crank(rng, false);
  l.loads.link_loads.clear();
  l.loads.node_forces.clear();
  l.springs.clear();
  l.loads.gravity = Vec2(0, -9.81);
  op::DesignProblem p;
  p.original = cp::make_linkage(l);
  p.scene = cp::FreeScene{{}, {20.0}, 0.3, 31};
  p.simulate.tolerance = 1e-10;
  const double L = cp::element_length(p.original, 0);
  p.counterweights = {op::CounterweightVariables{.link = 0, .mass_max = 2 * cp::total_mass(l),
                                                 .distance_max = 1.5 * L}};
  const cp::Link& rod = p.original.links[1];
  const double R = cp::element_length(p.original, 1);
  p.link_parameters = {{1, Par::kMass, 0.5 * rod.mass, 2 * rod.mass},
                       {1, Par::kE, -R, 2 * R},
                       {1, Par::kF, -0.5 * R, 0.5 * R},
                       {1, Par::kInertia, 0.0, 4 * rod.inertia + rod.mass * R * R}};
  p.objective = {op::Term{metric, 1.0}};
  return p;
}

// an interior design: the counterweight off the crank's line, the rod's parameters moved
VectorXd design_point(const op::PlanarNlp& nlp) {
  VectorXd x = nlp.start();
  const VectorXd lo = nlp.lower(), hi = nlp.upper();
  const double at[] = {0.37, 0.61, 0.28, 0.55, 0.62, 0.41, 0.33};
  for (int j = 0; j < nlp.design_variables(); ++j) x(j) = lo(j) + at[j] * (hi(j) - lo(j));
  return x;
}

// The referee: the same program at the integration tolerance 1e-12, differenced with
// h = 1e-4 of each variable's range. Truncation ~h² ~ 1e-8; the runs' own error (~1e-9 of the
// values over 0.3 s at 1e-12, tests/core/planar/referee_free_test.cpp) over 2h ~ 1e-5 of the
// values per range. The gradient under test comes from sensitivities at 1e-7 (the state at 1e-10;
// measured within 1e-6 of its size, tests/core/planar/sensitivity_test.cpp). Each entry is held to
// 1e-4 of the gradient's largest entry scaled by its variable's range.
constexpr double kStep = 1e-4;
constexpr double kTolerance = 1e-4;

op::DesignProblem tightened(op::DesignProblem p) {
  p.simulate.tolerance = 1e-12;
  p.simulate.absolute_tolerance = 1e-14;
  return p;
}

TEST(PlanarFree, GradientOfEveryMetricMatchesCentralDifferences) {
  const op::PlanarNlp probe(free_problem("Fsh_rms"));
  ASSERT_TRUE(probe.has_gradients());
  for (const cp::ColumnMetric& m : probe.metric_table()) {
    if (m.name.rfind("tau", 0) == 0) continue;  // no drive: its torque is 0, no normaliser
    SCOPED_TRACE(m.name);
    const op::DesignProblem p = free_problem(m.name);
    const op::PlanarNlp nlp(p), referee(tightened(p));
    const VectorXd x = design_point(nlp);
    VectorXd g(nlp.n());
    const double f = nlp.objective(x, &g);
    EXPECT_NEAR(f, referee.objective(x, nullptr), 1e-7 * std::max(1.0, std::abs(f)));
    VectorXd d(nlp.n()), range = nlp.upper() - nlp.lower();
    for (int j = 0; j < nlp.n(); ++j) {
      const double h = kStep * range(j);
      VectorXd xp = x, xm = x;
      xp(j) += h;
      xm(j) -= h;
      d(j) = (referee.objective(xp, nullptr) - referee.objective(xm, nullptr)) / (2 * h);
    }
    const double scale = (d.cwiseProduct(range)).cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0.0);
    for (int j = 0; j < nlp.n(); ++j) {
      EXPECT_NEAR(g(j) * range(j), d(j) * range(j), kTolerance * scale)
          << nlp.variable_names()[static_cast<std::size_t>(j)];
    }
  }
}

TEST(PlanarFree, LimitJacobianMatchesCentralDifferences) {
  op::DesignProblem p = free_problem("Fsh_rms");
  const op::PlanarNlp probe(p);
  for (const cp::ColumnMetric& m : probe.metric_table())
    if (m.name.rfind("tau", 0) != 0) p.limits.push_back(op::Limit{m.name, 0.9});
  p.limits.push_back(op::Limit{"added_mass", 1.0});
  const op::PlanarNlp nlp(p), referee(tightened(p));
  const VectorXd x = design_point(nlp);
  VectorXd c;
  MatrixXd jac;
  nlp.inequalities(x, c, &jac);
  ASSERT_EQ(jac.rows(), nlp.n_ineq());
  const VectorXd range = nlp.upper() - nlp.lower();
  MatrixXd d(nlp.n_ineq(), nlp.n());
  for (int j = 0; j < nlp.n(); ++j) {
    const double h = kStep * range(j);
    VectorXd xp = x, xm = x, cp_, cm;
    xp(j) += h;
    xm(j) -= h;
    referee.inequalities(xp, cp_, nullptr);
    referee.inequalities(xm, cm, nullptr);
    d.col(j) = (cp_ - cm) / (2 * h);
  }
  for (int i = 0; i < nlp.n_ineq(); ++i) {
    const double scale = d.row(i).cwiseProduct(range.transpose()).cwiseAbs().maxCoeff();
    for (int j = 0; j < nlp.n(); ++j) {
      EXPECT_NEAR(jac(i, j) * range(j), d(i, j) * range(j), kTolerance * std::max(scale, 1e-12))
          << nlp.constraint_names()[static_cast<std::size_t>(i)] << " by "
          << nlp.variable_names()[static_cast<std::size_t>(j)];
    }
  }
}

// The least RMS shaking force with counterweights on the crank and the rod under a budget of half
// the linkage's mass: gradient methods reach cobyla's optimum (or better) in fewer simulations.
TEST(PlanarFree, GradientMethodsReachCobylasOptimumInFewerSimulations) {
  op::DesignProblem p = free_problem("Fsh_rms");
  p.link_parameters.clear();
  p.counterweights.push_back(op::CounterweightVariables{
      .link = 1, .mass_max = 2 * cp::total_mass(p.original),
      .distance_max = cp::element_length(p.original, 1)});
  p.limits = {op::Limit{"added_mass", 0.5 * cp::total_mass(p.original)}};
  optimize::OptimizeOptions o;  // the defaults: relative tolerance 1e-8, 2000 evaluations
  o.algorithm = optimize::Algorithm::kCobyla;
  const op::Result cobyla = op::optimize(p, o);
  SCOPED_TRACE("cobyla: " + cobyla.brief_report() + " | " + cobyla.message);
  ASSERT_EQ(cobyla.termination, optimize::Termination::kConverged);
  // the motion depends on the design: no convex relaxation is built, and the summary says why
  EXPECT_TRUE(std::isnan(cobyla.lower_bound));
  EXPECT_EQ(cobyla.lower_bound_source.rfind("no lower bound: in a free scene the motion", 0), 0u)
      << cobyla.lower_bound_source;
  EXPECT_FALSE(cobyla.global);
  for (optimize::Algorithm a :
       {optimize::Algorithm::kSlsqp, optimize::Algorithm::kMma, optimize::Algorithm::kIpopt}) {
    o.algorithm = a;
    const op::Result r = op::optimize(p, o);
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    EXPECT_EQ(r.termination, optimize::Termination::kConverged);
    // cobyla's optimum or better: both objectives are simulations at tolerance 1e-10, and each
    // solver stops within ~1e-8 of the optimum
    EXPECT_LE(r.objective, cobyla.objective * (1 + 1e-6));
    EXPECT_LT(r.evaluations, cobyla.evaluations);
    EXPECT_LT(r.verification_error, 1e-6);  // the optimum simulated by the dae route
    EXPECT_EQ(r.lower_bound_source, cobyla.lower_bound_source);
  }
}

// The optimum of a peak in a free scene does not depend on the sample count: the program
// resolves the peak between each run's samples and takes its gradient at the peak's instant
// (cp::free_derivatives_at()). The referee: the engine's resolved peak of the optimum's run at
// 1501 samples. With `peaks: sampled` the optimum of 16 samples is a design whose peak lies
// higher, and its value claims less than that peak.
TEST(PlanarFree, APeakOptimumDoesNotDependOnTheSampleCount) {
  const std::string metric = "Rpiston_max";  // the piston guide's reaction on the frame
  op::DesignProblem p = free_problem(metric);
  p.link_parameters.clear();
  p.counterweights.push_back(
      op::CounterweightVariables{.link = 1,
                                 .mass_max = 2 * cp::total_mass(p.original),
                                 .distance_max = cp::element_length(p.original, 1)});
  p.limits = {op::Limit{"added_mass", 0.5 * cp::total_mass(p.original)}};
  optimize::OptimizeOptions o;
  o.algorithm = optimize::Algorithm::kSlsqp;
  auto true_peak = [&](const cp::Linkage& design) {
    const cp::Model model(design);
    cp::FreeScene dense = std::get<cp::FreeScene>(p.scene);
    dense.samples = 1501;
    const cp::Trajectory t = cp::simulate_free(model, dense, p.simulate);
    const std::vector<cp::ColumnMetric> table = cp::metric_table(model);
    const auto k = static_cast<std::size_t>(
        std::find_if(table.begin(), table.end(),
                     [&](const cp::ColumnMetric& c) { return c.name == metric; }) -
        table.begin());
    return cp::metric_values(model, p.simulate, table, t)[k];
  };
  auto value_of = [&](const op::Result& r) {
    for (std::size_t k = 0; k < r.metric_table.size(); ++k)
      if (r.metric_table[k].name == metric) return r.metrics[k];
    return std::nan("");
  };
  std::vector<double> peaks;
  for (int samples : {16, 46}) {
    op::DesignProblem q = p;
    std::get<cp::FreeScene>(q.scene).samples = samples;
    const op::Result r = op::optimize(q, o);
    SCOPED_TRACE(std::to_string(samples) + " samples: " + r.brief_report() + " | " + r.message);
    ASSERT_EQ(r.termination, optimize::Termination::kConverged);
    const double peak = true_peak(r.design);
    EXPECT_NEAR(value_of(r), peak, 1e-8 * peak);
    EXPECT_LT(r.verification_error, 1e-6);  // the dae route's run, its peak resolved alike
    peaks.push_back(peak);
  }
  // both optima the motion's: equal within the solver's tolerance (1e-8 relative on the
  // objective; measured: to 12 digits, 23.2113704516 N, 25 evaluations each)
  EXPECT_NEAR(peaks[0], peaks[1], 1e-7 * peaks[1]);
  // the samples' optimum (measured: SLSQP stops short on the kinks of the largest sample after
  // 433 evaluations, at 23.31 N, whose motion peaks at 23.57 N; here within 100 of them)
  op::DesignProblem sampled = p;
  sampled.resolve_peaks = false;
  std::get<cp::FreeScene>(sampled.scene).samples = 16;
  o.max_evaluations = 100;
  const op::Result s = op::optimize(sampled, o);
  ASSERT_TRUE(s.ok()) << s.message;
  const double sampled_peak = true_peak(s.design);
  EXPECT_LT(value_of(s), sampled_peak * (1 - 1e-3));
  EXPECT_GT(sampled_peak, peaks[1] * (1 + 1e-3));
}

// Without sensitivities (the dae route, an explicit Runge-Kutta pair) a gradient method is
// refused, in words that say what would give it gradients.
TEST(PlanarFree, GradientMethodsNeedTheReducedRouteOnCvode) {
  op::DesignProblem p = free_problem("Fsh_rms");
  optimize::OptimizeOptions o;
  o.algorithm = optimize::Algorithm::kSlsqp;
  EXPECT_FALSE(op::check_algorithm(p, o));
  p.simulate.route = cp::Route::kDae;
  const bd::Problem dae = op::check_algorithm(p, o);
  ASSERT_TRUE(dae);
  EXPECT_EQ(dae->text(),
            "algorithm 'slsqp' needs gradients, which a free scene on the dae route does not "
            "provide; use cobyla or isres, or the reduced route integrated by cvode-adams or "
            "cvode-bdf");
  EXPECT_FALSE(op::PlanarNlp(p).has_gradients());
  p.simulate.route = cp::Route::kReduced;
  p.simulate.integrator = core::Integrator::kErk5;
  const bd::Problem erk = op::check_algorithm(p, o);
  ASSERT_TRUE(erk);
  EXPECT_NE(erk->text().find("a free scene integrated by erk5 does not provide"),
            std::string::npos);
  o.algorithm = optimize::Algorithm::kCobyla;
  EXPECT_FALSE(op::check_algorithm(p, o));
}

}  // namespace
}  // namespace bd::testing::planar
