// The free scene's program (optimize/free_nlp.cpp): gradients by forward sensitivities,
// checked against central differences of full simulations, and gradient methods against
// cobyla on the same problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// no drive in a free scene: its torque is no metric there (DesignProblem::validate())
bool is_torque(Metric m) { return m == Metric::kTauRms || m == Metric::kTauMax; }

std::size_t metric_index_of(Metric m) { return static_cast<std::size_t>(m); }

// a loaded four-bar under gravity swinging freely from a push, counterweights on crank and
// rocker and the coupler's mass and centre of mass as variables
DesignProblem free_problem(Metric metric) {
  DesignProblem p;
  p.original =
      core::samples::with_paper_loads(core::samples::paper_fourbar_unloaded(), Vec2(0, -9.81));
  p.scene = core::FreeScene{.theta1 = 1.0, .omega1 = 3.0, .duration = 1.0, .samples = 41};
  p.formulation = core::Formulation::kComplexMasses;
  p.tolerance = 1e-10;
  p.counterweights = {CounterweightVariables{.link = 1, .mass_max = 4.0, .distance_max = 0.8},
                      CounterweightVariables{.link = 3, .mass_max = 4.0, .distance_max = 0.8}};
  p.link_parameters = {LinkParameterVariable{.link = 2,
                                             .parameter = LinkParameterVariable::Parameter::kMass,
                                             .lower = 1.0,
                                             .upper = 5.0},
                       LinkParameterVariable{.link = 2,
                                             .parameter = LinkParameterVariable::Parameter::kE,
                                             .lower = 0.5,
                                             .upper = 2.0}};
  p.objective = {Term{metric, 1.0}};
  return p;
}

// an interior design: every counterweight carrying mass, off the link lines
VectorXd design_point(const Nlp& nlp) {
  VectorXd x = nlp.start();
  x.head(6) << 1.3, -0.31, 0.17, 0.9, 0.22, -0.26;
  x(6) = 3.4;
  x(7) = 1.2;
  return x;
}

// The referee: central differences of the same program at a tighter integration tolerance
// (1e-12), each variable moved by h = 1e-4 max(1, |x_j|). Truncation ~h² ~ 1e-8; the runs' global
// error (~1e-11 of the values) over 2h ~ 1e-7. The program's gradient comes from sensitivities at
// 1e-10 (error ~1e-9 of its size). Each entry is held to 1e-5 of the gradient's largest entry.
constexpr double kStep = 1e-4;
constexpr double kTolerance = 1e-5;

TEST(FreeNlp, GradientOfEveryMetricMatchesCentralDifferences) {
  for (Metric m : kMetrics) {
    if (is_torque(m)) continue;
    SCOPED_TRACE(to_string(m));
    DesignProblem p = free_problem(m);
    // the forms alternate over the metrics (each form's derivative is the same for every
    // metric; the metrics' gradients are what differ)
    const ObjectiveForm form =
        metric_index_of(m) % 2 == 0 ? ObjectiveForm::kLinear : ObjectiveForm::kSquared;
    {
      p.objective_form = form;
      const Nlp nlp(p);
      ASSERT_TRUE(nlp.has_gradients());
      DesignProblem tight = p;
      tight.tolerance = 1e-12;
      const Nlp referee(tight);
      const VectorXd x = design_point(nlp);
      VectorXd g(nlp.n());
      const double f = nlp.objective(x, &g);
      EXPECT_NEAR(f, referee.objective(x, nullptr), 1e-7 * std::max(1.0, std::abs(f)));
      VectorXd d(nlp.n());
      for (int j = 0; j < nlp.n(); ++j) {
        const double h = kStep * std::max(1.0, std::abs(x(j)));
        VectorXd xp = x, xm = x;
        xp(j) += h;
        xm(j) -= h;
        d(j) = (referee.objective(xp, nullptr) - referee.objective(xm, nullptr)) / (2 * h);
      }
      ASSERT_GT(d.cwiseAbs().maxCoeff(), 0.0);
      for (int j = 0; j < nlp.n(); ++j) {
        EXPECT_NEAR(g(j), d(j), kTolerance * d.cwiseAbs().maxCoeff())
            << nlp.variable_names()[static_cast<std::size_t>(j)] << " (" << to_string(form) << ")";
      }
    }
  }
}

TEST(FreeNlp, LimitJacobianMatchesCentralDifferences) {
  DesignProblem p = free_problem(Metric::kAddedMass);
  for (Metric m : kMetrics) {
    if (!is_torque(m)) p.limits.push_back(Limit{m, m == Metric::kAddedMass ? 2.0 : 0.9});
  }
  const Nlp nlp(p);
  DesignProblem tight = p;
  tight.tolerance = 1e-12;
  const Nlp referee(tight);
  const VectorXd x = design_point(nlp);
  VectorXd c;
  MatrixXd jac;
  nlp.inequalities(x, c, &jac);
  ASSERT_EQ(jac.rows(), nlp.n_ineq());
  for (int j = 0; j < nlp.n(); ++j) {
    const double h = kStep * std::max(1.0, std::abs(x(j)));
    VectorXd xp = x, xm = x, cp, cm;
    xp(j) += h;
    xm(j) -= h;
    referee.inequalities(xp, cp, nullptr);
    referee.inequalities(xm, cm, nullptr);
    const VectorXd d = (cp - cm) / (2 * h);
    for (int i = 0; i < nlp.n_ineq(); ++i) {
      EXPECT_NEAR(jac(i, j), d(i), kTolerance * std::max(1.0, jac.row(i).cwiseAbs().maxCoeff()))
          << nlp.constraint_names()[static_cast<std::size_t>(i)] << " by "
          << nlp.variable_names()[static_cast<std::size_t>(j)];
    }
  }
}

// The problem of docs/performance.md ("Free scenes"): the least RMS shaking force with
// counterweights on crank and rocker and at most 2 kg added.
DesignProblem budget_problem() {
  DesignProblem p = free_problem(Metric::kFshRms);
  p.link_parameters.clear();
  p.limits = {Limit{Metric::kAddedMass, 2.0}};
  return p;
}

TEST(FreeNlp, GradientMethodsReachCobylasOptimumInFewerSimulations) {
  const DesignProblem p = budget_problem();
  OptimizeOptions o;  // the defaults: relative tolerance 1e-8, 2000 evaluations
  o.algorithm = Algorithm::kCobyla;
  const OptimizeResult cobyla = optimize(p, o);
  SCOPED_TRACE("cobyla: " + cobyla.brief_report() + " | " + cobyla.message);
  ASSERT_EQ(cobyla.termination, Termination::kConverged);
  for (Algorithm a : {Algorithm::kSlsqp, Algorithm::kMma, Algorithm::kIpopt}) {
    o.algorithm = a;
    const OptimizeResult r = optimize(p, o);
    SCOPED_TRACE(r.brief_report() + " | " + r.message);
    EXPECT_EQ(r.termination, Termination::kConverged);
    // the same optimum: both objectives are simulations at tolerance 1e-10, and each solver
    // stops within 1e-8 of it (measured: equal to 9 digits)
    EXPECT_NEAR(r.objective, cobyla.objective, 1e-6 * cobyla.objective);
    // each evaluation one simulation (with its sensitivities for the gradient methods):
    // measured 39 (slsqp), 229 (mma), ~50 (ipopt) against cobyla's ~1200
    EXPECT_LT(r.evaluations, cobyla.evaluations);
  }
}

}  // namespace
}  // namespace bd::optimize

namespace bd::optimize {
namespace {

// The optimum of a peak in a free scene no longer depends on the sample count: the program
// resolves the peak between each run's samples (core::metrics(model, trajectory, options, mask))
// and takes its gradient at the peak's instant. The referee is core's own resolved peak of the
// optimum's simulation at 2001 samples, independent of the program's samples. With
// `peaks: sampled` the optimum of 21 samples is another design whose true peak lies higher.
TEST(FreeNlp, APeakOptimumDoesNotDependOnTheSampleCount) {
  DesignProblem p = free_problem(Metric::kRA0Max);
  p.link_parameters.clear();
  p.limits = {Limit{Metric::kAddedMass, 2.0}};
  OptimizeOptions o;
  o.algorithm = Algorithm::kSlsqp;
  auto true_peak = [&](const core::FourBar& design) {
    core::FreeScene dense = std::get<core::FreeScene>(p.scene);
    dense.samples = 2001;
    core::SimulateOptions options;
    options.formulation = p.formulation;
    options.tolerance = p.tolerance;
    const core::Trajectory t = core::simulate_free(design, dense, options);
    return core::metrics(design, t, options).RA0_max;
  };
  std::vector<double> peaks;
  for (int samples : {21, 61}) {
    DesignProblem q = p;
    std::get<core::FreeScene>(q.scene).samples = samples;
    const OptimizeResult r = optimize(q, o);
    SCOPED_TRACE(std::to_string(samples) + " samples: " + r.brief_report() + " | " + r.message);
    ASSERT_EQ(r.termination, Termination::kConverged);
    const double peak = true_peak(r.design);
    // the program's value is the motion's peak (to the integration tolerance), and the
    // verification's run resolves it alike
    EXPECT_NEAR(r.metrics.RA0_max, peak, 1e-8 * peak);
    EXPECT_LT(r.verification_error, 1e-7);
    peaks.push_back(peak);
  }
  // both optima are the motion's: equal within the solver's tolerance (1e-8 relative on the
  // objective; measured: to 12 digits, 167.836994429 N)
  EXPECT_NEAR(peaks[0], peaks[1], 1e-7 * peaks[1]);
  // the samples' optimum (measured: SLSQP stops short on the kinks of the largest sample, at
  // 166.83 N, whose motion peaks at 168.92 N): its value below its design's peak, the design
  // worse than the motion's optimum
  DesignProblem sampled = p;
  sampled.resolve_peaks = false;
  std::get<core::FreeScene>(sampled.scene).samples = 21;
  const OptimizeResult s = optimize(sampled, o);
  ASSERT_TRUE(s.ok()) << s.message;
  const double sampled_peak = true_peak(s.design);
  EXPECT_LT(s.metrics.RA0_max, sampled_peak * (1 - 1e-3));
  EXPECT_GT(sampled_peak, peaks[1] * (1 + 1e-3));
}

}  // namespace
}  // namespace bd::optimize
