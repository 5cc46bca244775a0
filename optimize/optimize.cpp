#include "optimize/optimize.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
#include "optimize/check_inputs.hpp"
#include "optimize/convex_solve.hpp"
#include "optimize/detail/peak_exchange.hpp"
#include "optimize/first_order.hpp"
#include "optimize/fixed_variables.hpp"
#include "optimize/ipopt_driver.hpp"
#include "optimize/nlopt_driver.hpp"
#include "optimize/nlp.hpp"

namespace bd::optimize {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr Algorithm kAlgorithms[] = {Algorithm::kSlsqp, Algorithm::kMma,   Algorithm::kIpopt,
                                     Algorithm::kMlsl,  Algorithm::kIsres, Algorithm::kCobyla};

// ---------------------------------------------------------------------------------------------
// gradient check: analytic derivatives against central differences at x.
// Step h = 1e-6 max(1, |x_i|) (the variables are O(1) in SI units): truncation ~h² |f'''|,
// round-off ~eps |f| / h ~ 1e-10; an entry fails when |analytic - difference| exceeds
// 1e-5 max(1, |analytic|, |difference|) (the scaled functions are O(1)). Where x ± h leaves the
// bounds, the one-sided second-order formula (-3 f0 + 4 f1 - f2) / 2h is used instead.

struct Worst {
  double error = -1.0;
  std::string what;
  double analytic{}, difference{};
};

// the differences of every output of `fun` (objective or constraints) with respect to x_j
template <class Fun>
VectorXd difference(const Program& nlp, const VectorXd& x, int j, Fun&& fun) {
  const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
  VectorXd xp = x;
  auto at = [&](double step) {
    xp[j] = x[j] + step;
    return fun(xp);
  };
  if (x[j] - h >= nlp.lower()[j] && x[j] + h <= nlp.upper()[j]) {
    return (at(h) - at(-h)) / (2 * h);
  }
  const double s = x[j] + 2 * h <= nlp.upper()[j] ? h : -h;  // into the box
  return (-3.0 * at(0.0) + 4.0 * at(s) - at(2 * s)) / (2 * s);
}

void compare(const MatrixXd& analytic, const MatrixXd& numeric,
             const std::vector<std::string>& rows, int row_offset, const Program& nlp,
             Worst& worst) {
  for (int i = 0; i < analytic.rows(); ++i) {
    for (int j = 0; j < analytic.cols(); ++j) {
      const double a = analytic(i, j), d = numeric(i, j);
      const double error = std::abs(a - d) / std::max({1.0, std::abs(a), std::abs(d)});
      if (!(error <= worst.error) || !std::isfinite(error)) {
        worst.error = std::isfinite(error) ? error : std::numeric_limits<double>::infinity();
        worst.what = "d(" + rows[static_cast<size_t>(row_offset + i)] + ")/d(" +
                     nlp.variable_names()[static_cast<size_t>(j)] + ")";
        worst.analytic = a;
        worst.difference = d;
      }
    }
  }
}

// "" when every entry agrees, else the worst entry in words
std::string check_gradients(const Program& nlp, const VectorXd& x) {
  const int n = nlp.n();
  Worst worst;
  // objective
  {
    VectorXd g(n);
    nlp.objective(x, &g);
    MatrixXd numeric(1, n);
    for (int j = 0; j < n; ++j) {
      numeric(0, j) = difference(nlp, x, j, [&](const VectorXd& y) {
        return VectorXd::Constant(1, nlp.objective(y, nullptr));
      })[0];
    }
    compare(g.transpose(), numeric, {"objective"}, 0, nlp, worst);
  }
  // equalities, then inequalities (named as in constraint_names(): equalities first)
  auto constraints = [&](int m, int offset, auto&& eval) {
    if (m == 0) return;
    VectorXd c;
    MatrixXd jac;
    eval(x, c, &jac);
    MatrixXd numeric(m, n);
    for (int j = 0; j < n; ++j) {
      numeric.col(j) = difference(nlp, x, j, [&](const VectorXd& y) {
        VectorXd cy;
        eval(y, cy, nullptr);
        return cy;
      });
    }
    compare(jac, numeric, nlp.constraint_names(), offset, nlp, worst);
  };
  constraints(nlp.n_eq(), 0,
              [&](const VectorXd& y, VectorXd& c, MatrixXd* j) { nlp.equalities(y, c, j); });
  constraints(nlp.n_ineq(), nlp.n_eq(),
              [&](const VectorXd& y, VectorXd& c, MatrixXd* j) { nlp.inequalities(y, c, j); });
  if (worst.error <= 1e-5) return "";
  return "gradient check failed: " + worst.what + " is " + text::digits(worst.analytic, 9) +
         " analytically but " + text::digits(worst.difference, 9) +
         " by central differences (relative error " + text::digits(worst.error, 2) + ")";
}

// ---------------------------------------------------------------------------------------------
// verification: the optimum re-simulated with a formulation other than the optimiser's

core::Formulation other_than(core::Formulation f) {
  return f == core::Formulation::kMassMatrix ? core::Formulation::kComplexMasses
                                             : core::Formulation::kMassMatrix;
}

// The largest relative difference between two evaluations of a design's metrics. A metric that
// vanishes by cancellation (Fsh of a force-balanced design is RA0 + RA3 with |RA0| ~ |RA3|) is
// only known to the round-off of the terms it is made of (~1e-14 of them), so each metric is
// measured against max(|a|, |b|, 1e-4 · scale), the scale being the largest reaction for the
// forces [N] and the largest of the moments and l4 times the largest reaction for the moments
// [N m]: round-off then shows as ~1e-10, while a wrong formula still shows at the order of the
// metric over that floor.
double verification_error(const core::Metrics& a, const core::Metrics& b, double frame_length) {
  const double force = std::max({a.RA0_max, a.RA3_max, b.RA0_max, b.RA3_max});
  const double moment =
      std::max({a.tau_max, a.Msh_max, b.tau_max, b.Msh_max, frame_length * force});
  double worst = 0.0;
  for (Metric m : kMetrics) {
    if (m == Metric::kAddedMass) continue;
    const double va = value(a, m), vb = value(b, m);
    const double scale =
        std::max({std::abs(va), std::abs(vb), 1e-4 * (is_moment(m) ? moment : force)});
    if (scale == 0.0) continue;  // zero in both, and nothing to be zero against
    const double error = std::abs(va - vb) / scale;
    if (!std::isfinite(error)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, error);
  }
  return worst;
}

}  // namespace

const char* to_string(Algorithm a) {
  switch (a) {
    case Algorithm::kSlsqp:
      return "slsqp";
    case Algorithm::kMma:
      return "mma";
    case Algorithm::kIpopt:
      return "ipopt";
    case Algorithm::kMlsl:
      return "mlsl";
    case Algorithm::kIsres:
      return "isres";
    case Algorithm::kCobyla:
      return "cobyla";
  }
  return "unknown";
}

std::optional<Algorithm> algorithm_named(const std::string& name) {
  for (Algorithm a : kAlgorithms) {
    if (name == to_string(a)) return a;
  }
  return std::nullopt;
}

bool uses_gradients(Algorithm a) {
  return a == Algorithm::kSlsqp || a == Algorithm::kMma || a == Algorithm::kIpopt ||
         a == Algorithm::kMlsl;
}

Problem OptimizeOptions::validate() const {
  if (std::find(std::begin(kAlgorithms), std::end(kAlgorithms), algorithm) ==
      std::end(kAlgorithms)) {
    return FieldError{"algorithm", -1, "must be one of slsqp, mma, ipopt, mlsl, isres, cobyla"};
  }
  if (max_evaluations < 1) {
    return FieldError{"max_evaluations", -1,
                      "must be >= 1, got " + std::to_string(max_evaluations)};
  }
  // only mlsl makes starts: another algorithm runs once, whatever starts holds (its default)
  if (algorithm == Algorithm::kMlsl && (starts < 1 || starts > max_evaluations)) {
    return FieldError{"starts", -1,
                      "must be >= 1 and <= max_evaluations (" + std::to_string(max_evaluations) +
                          ": each start needs an evaluation), got " + std::to_string(starts)};
  }
  if (!(std::isfinite(relative_tolerance) && relative_tolerance > 0 && relative_tolerance < 1)) {
    return FieldError{"relative_tolerance", -1,
                      "must be in (0, 1), got " + text::exact(relative_tolerance)};
  }
  if (!(std::isfinite(constraint_tolerance) && constraint_tolerance > 0)) {
    return FieldError{"constraint_tolerance", -1,
                      "must be > 0, got " + text::exact(constraint_tolerance)};
  }
  return std::nullopt;
}

Problem check_algorithm(const OptimizeOptions& options, const std::string& without_gradients,
                        const std::string& instead, bool force_balance) {
  const std::string name = std::string("'") + to_string(options.algorithm) + "'";
  if (uses_gradients(options.algorithm) && !without_gradients.empty()) {
    return FieldError{"algorithm", -1,
                      name + " needs gradients, which " + without_gradients +
                          " does not provide; use cobyla or isres" +
                          (instead.empty() ? "" : ", or " + instead)};
  }
  if (options.algorithm == Algorithm::kMma && force_balance) {
    return FieldError{"algorithm", -1,
                      name +
                          " takes inequality constraints only, and force_balance adds "
                          "equalities; use slsqp, ipopt, mlsl or cobyla"};
  }
  return std::nullopt;
}

Problem check_algorithm(const DesignProblem& problem, const OptimizeOptions& options) {
  // a four-bar's free scene has gradients by forward sensitivities of its reduced equation
  // (optimize/free_nlp.cpp), but not on the opened loop's DAE
  const bool opened = std::holds_alternative<core::FreeScene>(problem.scene) &&
                      problem.formulation == core::Formulation::kOpenedLoop;
  return check_algorithm(options,
                         opened ? "a free scene on the opened loop (method opened-loop)" : "",
                         "the method mass-matrix or complex-masses", problem.force_balance);
}

void detail::check_inputs(const DesignProblem& problem, const OptimizeOptions& options) {
  if (const Problem e = options.validate()) throw InputError("optimize options: " + e->text());
  if (const Problem e = problem.validate()) throw InputError("design problem: " + e->text());
}

std::string other_algorithms(Algorithm used, bool free_scene) {
  const std::vector<Algorithm> driven = {Algorithm::kIpopt, Algorithm::kMlsl, Algorithm::kSlsqp,
                                         Algorithm::kCobyla};
  const std::vector<Algorithm> free = {Algorithm::kCobyla, Algorithm::kIsres};
  std::string out;
  for (Algorithm a : free_scene ? free : driven) {
    if (a == used) continue;
    out += (out.empty() ? "" : ", ") + std::string(to_string(a));
  }
  return out;
}

const char* to_string(Termination t) {
  switch (t) {
    case Termination::kNotRun:
      return "not run";
    case Termination::kConverged:
      return "converged";
    case Termination::kMaxEvaluations:
      return "max evaluations";
    case Termination::kStoppedShort:
      return "stopped short";
    case Termination::kInfeasible:
      return "infeasible";
    case Termination::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string OptimizeResult::verified_by() const {
  return verified_on_general_engine ? "truss-dae" : core::to_string(verified_with);
}

std::string OptimizeResult::brief_report() const {
  std::string s = solver_report(*this);
  if (!peak_angles.empty()) {
    s += ", peaks bounded at " + std::to_string(peak_angles.size()) +
         " crank angles besides the samples";
  }
  if (termination == Termination::kNotRun || std::isnan(verification_error)) {
    s += ", not verified";
  } else {
    s += ", verified by " + verified_by() + " to " + text::digits(verification_error, 2);
  }
  return s;
}

void detail::check_feasibility(const Program& nlp, const OptimizeOptions& options,
                               const std::string& solver, detail::Solved& r) {
  int worst = -1;
  double worst_value = 0.0;
  r.constraint_violation = detail::constraint_violation(nlp, r.x, &worst, &worst_value);
  if (r.constraint_violation > options.constraint_tolerance) {
    const std::string& name = nlp.constraint_names()[static_cast<size_t>(worst)];
    const bool equality = worst < nlp.n_eq();
    r.termination = Termination::kInfeasible;
    const std::string words = nlp.constraint_text(worst, r.x);
    r.message =
        "no feasible design found: the binding constraint is '" + name + "'" +
        (words.empty() ? " at " + text::digits(worst_value, 6) +
                             (equality ? " (must be 0" : " (must be <= 0") + ", tolerance " +
                             text::digits(options.constraint_tolerance, 2) + ")"
                       : ": " + words) +
        " [" + solver + "]";
  } else if (r.termination == Termination::kInfeasible) {
    // the solver gave up on feasibility yet stopped at a feasible point: say so plainly
    r.termination = Termination::kFailed;
    r.message += " (the point returned is feasible)";
  }
}

namespace {

// A free scene on the general planar engine's DAE route, which passes limit positions, as a
// four-bar trajectory.
core::Trajectory general_engine_run(const core::FourBar& design, const core::FreeScene& scene,
                                    double tolerance) {
  const core::planar::Model model(core::planar::linkage_of(design, scene.theta1));
  core::planar::SimulateOptions options;
  options.route = core::planar::Route::kDae;
  options.tolerance = tolerance;
  return core::planar::fourbar_trajectory(core::planar::simulate_free(
      model, core::planar::FreeScene{{scene.theta1}, {scene.omega1}, scene.duration, scene.samples},
      options));
}

// The optimum re-simulated with another formulation, compared metric by metric. A free scene
// that passes limit positions, which of the closed forms only the opened loop follows, is
// re-simulated on the general planar engine instead (its DAE route passes them too).
void verify(const DesignProblem& problem, OptimizeResult& r) {
  core::SimulateOptions simulate;
  simulate.formulation = other_than(problem.formulation);
  simulate.tolerance = problem.tolerance;
  r.verified_with = simulate.formulation;
  r.verified_on_general_engine = false;
  const auto* free_scene = std::get_if<core::FreeScene>(&problem.scene);
  core::Trajectory trajectory =
      free_scene
          ? core::simulate_free(r.design, *free_scene, simulate)
          : core::simulate_driven(r.design, std::get<core::DrivenScene>(problem.scene), simulate);
  if (free_scene && trajectory.status == core::SimulationStatus::kSingular &&
      problem.formulation == core::Formulation::kOpenedLoop) {
    // the peaks are still resolved by the optimiser's formulation, between the samples of the
    // general engine's run
    simulate.formulation = problem.formulation;
    r.verified_on_general_engine = true;
    trajectory = general_engine_run(r.design, *free_scene, problem.tolerance);
  }
  if (!trajectory.ok()) {
    r.verification_error = std::numeric_limits<double>::infinity();
    r.message += "; verification by " + r.verified_by() + " failed: " + trajectory.message;
    return;
  }
  // the peaks as the optimiser's: a free scene's program resolves those it reads, a driven
  // scene's bounds them at the samples and the peak angles
  const bool free = std::holds_alternative<core::FreeScene>(problem.scene);
  const core::MetricMask resolved = resolved_peak_rows(problem);
  r.verified = free && problem.resolve_peaks
                   ? core::metrics(r.design, trajectory, simulate, &resolved)
                   : core::metrics(trajectory);
  if (const auto* scene = std::get_if<core::DrivenScene>(&problem.scene)) {
    for (const double angle : problem.peak_angles) {
      const auto d = core::inverse_dynamics(r.design, angle, scene->omega1, 0.0,
                                            simulate.formulation);
      if (!d) {
        r.verification_error = std::numeric_limits<double>::infinity();
        r.message += "; verification by " + std::string(core::to_string(simulate.formulation)) +
                     " failed: " + d.error().what();
        return;
      }
      for (const core::MetricInfo& info : core::kMetricTable) {
        if (info.statistic != core::Statistic::kMax) continue;
        r.verified.*info.field =
            std::max(r.verified.*info.field, core::magnitude(*d, info.quantity));
      }
    }
  }
  r.verification_error = verification_error(r.metrics, r.verified, r.design.frame_length);
}

}  // namespace

namespace {

// One run of options.algorithm from x0, polished, its feasibility checked.
detail::Solved run_once(const Program& nlp, const VectorXd& x0, const OptimizeOptions& options) {
  detail::Solved r;
  const auto started = std::chrono::steady_clock::now();
  detail::DriverOutcome outcome = options.algorithm == Algorithm::kIpopt
                                      ? detail::solve_with_ipopt(nlp, x0, options)
                                      : detail::solve_with_nlopt(nlp, x0, options);
  const auto stopped = std::chrono::steady_clock::now();
  r.termination = outcome.termination;
  r.message = outcome.message;
  r.x = outcome.x;
  r.iterations = outcome.iterations;
  r.evaluations = outcome.evaluations;
  r.starts = outcome.starts;
  r.starts_at_best = outcome.starts_at_best;
  r.seconds = std::chrono::duration<double>(stopped - started).count();
  nlp.polish(r.x);
  r.objective = nlp.objective(r.x, nullptr);
  detail::check_feasibility(nlp, options, outcome.message, r);
  return r;
}

void add_costs(const detail::Solved& from, detail::Solved& to) {
  to.iterations += from.iterations;
  to.evaluations += from.evaluations;
  to.seconds += from.seconds;
}

// The methods that go on from a gradient method's end where the first-order conditions do not
// hold: the same once more (a restart renews SLSQP's Hessian and MMA's asymptotes), then
// another local method
std::vector<Algorithm> continuations(Algorithm a) {
  const Algorithm same = a == Algorithm::kMlsl ? Algorithm::kSlsqp : a;
  return {same, same == Algorithm::kIpopt ? Algorithm::kSlsqp : Algorithm::kIpopt};
}

// The evaluations a run that goes on from a converged end may take, of the `left` in the budget:
// SLSQP and Ipopt converge superlinearly near a regular end, so a polish by them is capped
// (refinement_evaluations()); MMA converges linearly, and MLSL searches again: they take what is
// left.
int continuation_budget(const Program& nlp, Algorithm a, int left) {
  const bool superlinear = a == Algorithm::kSlsqp || a == Algorithm::kIpopt;
  return superlinear ? detail::refinement_evaluations(nlp, left) : left;
}

// A converged end where counterweights vanish, put on their cones' apex and solved again in the
// other variables with those held there (FixedVariables: the rest of the problem is smooth, so a
// few steps settle it), then checked against the whole program's first-order conditions, which at
// the apex read the cone's subgradient and hold only if no counterweight there would help. True
// when that design meets them; then it replaces r's. Else r keeps its design (the costs counted).
bool settle_on_apex(const Program& nlp, const OptimizeOptions& options, double tolerance,
                    detail::Solved& r) {
  const std::vector<int> held_at_apex =
      nlp.vanishing_counterweight_variables(r.x, detail::kVanishingCounterweight);
  if (held_at_apex.empty()) return false;
  // on the apex, the variables that bound others set for it
  VectorXd x = nlp.within_envelopes(
      nlp.without_vanishing_counterweights(r.x, detail::kVanishingCounterweight));
  nlp.polish(x);
  double residual = detail::stationarity_residual(nlp, x);
  if (residual > tolerance && r.evaluations < options.max_evaluations) {
    const detail::FixedVariables held(nlp, held_at_apex, x);
    OptimizeOptions next = options;
    next.max_evaluations =
        continuation_budget(held, options.algorithm, options.max_evaluations - r.evaluations);
    const detail::Solved s = run_once(held, held.reduce(x), next);
    add_costs(s, r);
    if (s.termination == Termination::kConverged) {
      x = held.expand(s.x);
      nlp.polish(x);
      residual = detail::stationarity_residual(nlp, x);
    }
  }
  if (!(residual <= tolerance)) return false;
  const double f = nlp.objective(x, nullptr);
  const double violation = detail::constraint_violation(nlp, x);
  // against the solver's end within its envelopes and with its bound variables tightened too:
  // the solver may leave a vanishing counterweight a mass moment beyond its envelope and a
  // bound below its peak, each within the constraint tolerance, which its objective then
  // understates (a counterweight of 1e-13 kg on the apex carrying 6e-9 kg m lowered a peak by
  // 1.7e-9 of it)
  VectorXd end = nlp.within_envelopes(r.x);
  nlp.polish(end);
  const double f_end = std::max(r.objective, nlp.objective(end, nullptr));
  if (!(violation <= options.constraint_tolerance) ||
      f > f_end + options.relative_tolerance * std::max(std::abs(f_end), 1.0)) {
    return false;
  }
  const std::size_t count = held_at_apex.size() / 3;
  r.message += "; the first-order conditions held to " + text::digits(r.stationarity, 2) +
               " only where it stopped, where " + std::to_string(count) + " counterweight" +
               (count == 1 ? "" : "s") + " vanished; with " + (count == 1 ? "it" : "them") +
               " taken away and the rest solved again they hold to " + text::digits(residual, 2);
  r.x = x;
  r.objective = f;
  r.constraint_violation = violation;
  r.stationarity = residual;
  return true;
}

// A converged end of a gradient method checked against the first-order conditions, and
// continued where they do not hold (nlopt_driver.hpp, solve()). Where a degenerate optimum keeps
// the residual up (many constraints active together, as a peak's rows at a force-balanced
// design), runs that go on from the point, end converged themselves and change the objective by
// less than the tolerance (relative to the objective's size, 1 for the original design) settle
// it: converged. A continuation stopped by its evaluation budget (refinement_evaluations():
// a continuation polishes, it does not search again) settles nothing.
void ensure_first_order(const Program& nlp, const OptimizeOptions& options, detail::Solved& r) {
  if (!nlp.has_gradients() || r.termination != Termination::kConverged) return;
  const double tolerance = detail::stationarity_tolerance(options.relative_tolerance);
  r.stationarity = detail::stationarity_residual(nlp, r.x);
  if (!(r.stationarity > tolerance)) return;
  if (settle_on_apex(nlp, options, tolerance, r)) return;
  const double first = r.stationarity, f_first = r.objective;
  std::string continued;
  int runs = 0, settled = 0;
  for (Algorithm a : continuations(options.algorithm)) {
    if (r.evaluations >= options.max_evaluations) break;
    OptimizeOptions next = options;
    next.algorithm = a;
    next.max_evaluations = continuation_budget(nlp, a, options.max_evaluations - r.evaluations);
    detail::Solved s = run_once(nlp, r.x, next);
    add_costs(s, r);
    ++runs;
    if (s.termination == Termination::kConverged) ++settled;
    continued += std::string(continued.empty() ? "" : ", then ") + to_string(a);
    if (!found_design(s.termination) || s.objective > r.objective) continue;
    r.x = s.x;
    r.objective = s.objective;
    r.constraint_violation = s.constraint_violation;
    r.stationarity = detail::stationarity_residual(nlp, s.x);
    if (!(r.stationarity > tolerance)) break;
  }
  std::string said = "; the first-order conditions held to " + text::digits(first, 2) +
                     " only where it stopped (tolerance " + text::digits(tolerance, 2) + ")";
  if (!continued.empty()) said += "; continued by " + continued;
  if (!(r.stationarity > tolerance)) {
    r.message += said + " to " + text::digits(r.stationarity, 2);
    return;
  }
  const double gain = f_first - r.objective;
  if (settled > 0 && gain <= options.relative_tolerance * std::max(std::abs(f_first), 1.0)) {
    r.message += said + ", which changed the objective by " + text::digits(gain, 2) +
                 " only: a degenerate optimum, taken as converged";
    return;
  }
  r.termination = Termination::kStoppedShort;
  r.message += said + (runs > 0 ? ", to " + text::digits(r.stationarity, 2) : std::string()) +
               " at the design returned: it is feasible but may not be the optimum; another "
               "algorithm or a larger max_evaluations may find a better one";
}

}  // namespace

detail::Solved detail::solve(const Program& nlp, const VectorXd& x0, const OptimizeOptions& options,
                             bool to_first_order) {
  if (options.check_gradients && nlp.has_gradients()) {
    // a wrong derivative would mislead every gradient method: stop before solving (Ceres)
    if (std::string e = check_gradients(nlp, x0); !e.empty()) {
      Solved r;
      r.termination = Termination::kFailed;
      r.message = std::move(e);
      r.x = x0;
      r.objective = nlp.objective(x0, nullptr);
      r.constraint_violation = constraint_violation(nlp, x0);
      r.gradient_check_failed = true;
      return r;
    }
  }
  Solved r = run_once(nlp, x0, options);
  if (to_first_order) ensure_first_order(nlp, options, r);
  return r;
}

// within this fraction of its range from a bound a variable is on it (snapped_to_bounds())
constexpr double kOnTheBound = 1e-12;

VectorXd detail::snapped_to_bounds(const Program& nlp, const OptimizeOptions& options,
                                   const VectorXd& x, double objective, double violation) {
  VectorXd out = nlp.without_vanishing_counterweights(x, kOnTheBound);
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    const double lo = nlp.lower()(i), hi = nlp.upper()(i), near = kOnTheBound * (hi - lo);
    if (!std::isfinite(near)) continue;
    if (out(i) != lo && std::abs(out(i) - lo) <= near) out(i) = lo;
    if (out(i) != hi && std::abs(out(i) - hi) <= near) out(i) = hi;
  }
  if (out == x) return x;
  const double f = nlp.objective(out, nullptr);
  if (!(detail::constraint_violation(nlp, out) <=
        std::max(violation, options.constraint_tolerance)) ||
      !(std::abs(f - objective) <= 1e-12 * std::max(std::abs(objective), 1.0))) {
    return x;
  }
  return out;
}

VectorXd detail::without_needless_counterweights(const Program& program,
                                                 const OptimizeOptions& options, const VectorXd& x,
                                                 double objective, double violation,
                                                 std::string* said) {
  VectorXd out = x;
  std::vector<std::string> left_out, lighter;
  const double allowed_violation = std::max(violation, options.constraint_tolerance);
  // trial in place of out where it reads the same: the objective within 1e-12 of out's (or
  // lower), the constraints no more violated than allowed
  const auto same = [&](VectorXd& trial) {
    // a peak's bound variable tight at the trial design (else a peak it lowers would leave the
    // objective overstated, and one it raises show only as a violated row)
    program.polish(trial);
    const double f = program.objective(trial, nullptr);
    if (!(f <= objective + 1e-12 * std::max(std::abs(objective), 1.0)) ||
        !(constraint_violation(program, trial) <= allowed_violation)) {
      return false;
    }
    out = trial;
    objective = std::min(objective, f);
    return true;
  };
  const std::vector<int> first = program.counterweight_mass_variables();
  const std::vector<double> reach = program.counterweight_reach();
  for (std::size_t c = 0; c < first.size(); ++c) {
    const int j = first[c];
    if (!(out(j) > 0)) continue;
    std::string name = program.variable_names()[static_cast<std::size_t>(j)];
    if (const auto at = name.rfind(" mass"); at != std::string::npos) name.resize(at);
    VectorXd trial = out;
    trial.segment(j, 3).setZero();
    if (same(trial)) {
      left_out.push_back(name);
      continue;
    }
    // where the problem reads only its mass moment (its force, not its inertia: a shaking
    // force alone), the same moment with the least mass: at distance_max (position variables)
    if (reach.size() != first.size()) continue;
    const double mass = out(j), at = std::hypot(out(j + 1), out(j + 2)), d = reach[c];
    if (!(at > 0) || !(at < d * (1 - 1e-6))) continue;
    trial = out;
    trial(j) = mass * at / d;
    trial.segment(j + 1, 2) *= d / at;
    if (same(trial)) {
      lighter.push_back("the " + name + " is moved out to its distance_max, " +
                        text::digits(trial(j), 6) + " kg instead of " + text::digits(mass, 6) +
                        " kg at the same mass moment");
    }
  }
  if (said && !left_out.empty()) {
    std::string names;
    for (std::size_t i = 0; i < left_out.size(); ++i) {
      names += (i == 0 ? "" : i + 1 == left_out.size() ? " and " : ", ") + left_out[i];
    }
    *said = "; the " + names + " changed" +
            " nothing the problem reads (objective and constraints the same without " +
            (left_out.size() == 1 ? "it" : "them") + ") and " +
            (left_out.size() == 1 ? "is" : "are") + " left out";
  }
  if (said && !lighter.empty()) {
    *said += "; only the mass moment counts in the problem (objective and constraints the same)";
    for (const std::string& l : lighter) *said += "; " + l;
  }
  return out;
}

detail::Solved detail::solve_from(const Program& nlp, const std::vector<VectorXd>& starts,
                                  const OptimizeOptions& options) {
  // the first feasible start, else the least violated
  std::vector<std::size_t> order;
  std::size_t first = 0;
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const double v = constraint_violation(nlp, starts[i]);
    if (v <= options.constraint_tolerance) {
      first = i;
      break;
    }
    if (v < least) least = v, first = i;
  }
  order.push_back(first);
  for (std::size_t i = 0; i < starts.size(); ++i) {
    if (i != first) order.push_back(i);
  }
  Solved best, costs;
  bool have = false;
  for (std::size_t i : order) {
    Solved s = solve(nlp, starts[i], options);
    add_costs(s, costs);
    if (!have || found_design(s.termination) ||
        s.constraint_violation < best.constraint_violation) {
      best = std::move(s);
    }
    have = true;
    if (found_design(best.termination) || best.gradient_check_failed) break;
  }
  best.iterations = costs.iterations;
  best.evaluations = costs.evaluations;
  best.seconds = costs.seconds;
  return best;
}

namespace {

// The program's instants as crank angles: the scene's samples and the peak angles so far.
std::vector<double> instant_angles(const DesignProblem& problem, const core::DrivenScene& scene) {
  // the samples, then the motion's end (the first sample of the next revolution), which closes
  // the last interval
  const int samples = scene.samples * scene.revolutions;
  std::vector<double> angles;
  for (int i = 0; i <= samples; ++i) {
    angles.push_back(scene.theta1 + scene.omega1 * core::driven_sample_time(scene, i));
  }
  angles.insert(angles.end(), problem.peak_angles.begin(), problem.peak_angles.end());
  std::sort(angles.begin(), angles.end());
  return angles;
}

// The crank angles a next round bounds the peak at, for each peak metric of the objective
// (weight > 0) and of the limits whose resolved peak at the optimum (core::metrics(), searched
// between the samples) rises above the peak over the program's instants by more than
// kPeakExchangeTolerance: detail::add_peak_instants(). Empty in a free scene, for a design that
// is no result or cannot be run, when the instants hold the peaks, and without
// problem.resolve_peaks.
std::vector<double> short_peak_angles(const DesignProblem& problem, const Nlp& nlp,
                                      const detail::Solved& solved) {
  const auto* scene = std::get_if<core::DrivenScene>(&problem.scene);
  if (!problem.resolve_peaks || !scene || !found_design(solved.termination)) return {};
  std::vector<Metric> used;
  for (const Term& t : problem.objective) {
    if (t.weight > 0 && is_peak(t.metric)) used.push_back(t.metric);
  }
  for (const Limit& l : problem.limits) {
    if (is_peak(l.metric)) used.push_back(l.metric);
  }
  if (used.empty()) return {};
  const core::FourBar design = nlp.design(solved.x);
  core::SimulateOptions simulate;
  simulate.formulation = problem.formulation;
  const core::Trajectory run = core::simulate_driven(design, *scene, simulate);
  if (!run.ok()) return {};
  core::PeakList peaks;
  const core::Metrics resolved = core::metrics(design, *scene, run, problem.formulation, &peaks);
  const core::Metrics bounded = nlp.metrics(solved.x);
  const std::vector<double> instants = instant_angles(problem, *scene);
  std::vector<double> added;
  for (Metric m : used) {
    // of the original's peak, the objective's and the limits' unit (a peak of a balanced design
    // may vanish, and 1e-9 of nothing is round-off)
    const double excess = (value(resolved, m) - value(bounded, m)) / nlp.original(m);
    if (!(excess > detail::kPeakExchangeTolerance)) continue;
    // the interval of instants around it sorted by angle, whatever the sense of rotation
    detail::add_peak_instants(
        instants, scene->theta1 + scene->omega1 * peaks.table[static_cast<std::size_t>(m)].t,
        excess, added);
  }
  return added;
}

}  // namespace

OptimizeResult optimize(const DesignProblem& problem, const OptimizeOptions& options,
                        const std::vector<VectorXd>& designs) {
  detail::check_inputs(problem, options);
  // The exchange step: solve on the samples (and the peak angles found so far); where a peak of
  // the optimum resolved between the samples rises above what the program bounded, add crank
  // angles around it and solve again from that optimum, until the program bounds the motion's
  // peaks (detail::exchange_rounds()).
  return detail::exchange_rounds<Nlp>(
      problem, designs, options, &DesignProblem::peak_angles, "crank angles", short_peak_angles,
      [&](const Nlp&) { throw_if(check_algorithm(problem, options)); },
      [&](const Nlp& nlp, const DesignProblem& exchanged, const detail::ConvexAwareSolve& solve,
          const detail::ExchangeTotals& totals) {
        const detail::Solved& solved = solve.solved;
        OptimizeResult r;
        detail::set_solve_fields(r, nlp, solve, options, totals);
        r.message += totals.shortfall;
        r.peak_angles = exchanged.peak_angles;
        // the optimum as a design, as the optimiser evaluated it, then verified
        r.design = nlp.design(r.x);
        r.counterweights = nlp.counterweights(r.x);
        r.metrics = nlp.metrics(r.x);
        if (solved.gradient_check_failed) {
          r.verification_error = std::numeric_limits<double>::quiet_NaN();  // not verified
          return r;
        }
        verify(exchanged, r);
        return r;
      });
}

}  // namespace bd::optimize
