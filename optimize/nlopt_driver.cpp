#include "optimize/nlopt_driver.hpp"

#include "optimize/first_order.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <random>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <nlopt.h>
#pragma GCC diagnostic pop

namespace bd::optimize::detail {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

bool same_point(const VectorXd& a, const VectorXd& b) {
  return a.size() == b.size() && a.size() > 0 && a == b;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// TrackedNlp

TrackedNlp::TrackedNlp(const Program& nlp, double constraint_tolerance)
    : nlp_(nlp), tolerance_(constraint_tolerance) {}

double TrackedNlp::objective(const VectorXd& x, VectorXd* grad) {
  const double f = nlp_.objective(x, grad);
  ++evaluations_;
  x_f_ = x;
  f_ = f;
  consider();
  return f;
}

void TrackedNlp::equalities(const VectorXd& x, VectorXd& c, MatrixXd* jac) {
  nlp_.equalities(x, c, jac);
  x_eq_ = x;
  violation_eq_ = c.size() > 0 ? c.cwiseAbs().maxCoeff() : 0.0;
  if (!std::isfinite(violation_eq_)) violation_eq_ = std::numeric_limits<double>::infinity();
  consider();
}

void TrackedNlp::inequalities(const VectorXd& x, VectorXd& c, MatrixXd* jac) {
  nlp_.inequalities(x, c, jac);
  x_in_ = x;
  violation_in_ = c.size() > 0 ? std::max(0.0, c.maxCoeff()) : 0.0;
  if (!std::isfinite(violation_in_)) violation_in_ = std::numeric_limits<double>::infinity();
  consider();
}

void TrackedNlp::consider() {
  // f, c_eq and c_in must all be known at the same x (a part without constraints is always known)
  if (x_f_.size() == 0 || !std::isfinite(f_)) return;
  if (nlp_.n_eq() > 0 && !same_point(x_f_, x_eq_)) return;
  if (nlp_.n_ineq() > 0 && !same_point(x_f_, x_in_)) return;
  const double violation =
      std::max(nlp_.n_eq() > 0 ? violation_eq_ : 0.0, nlp_.n_ineq() > 0 ? violation_in_ : 0.0);
  if (violation > tolerance_ || f_ >= best_f_) return;
  has_best_ = true;
  best_f_ = f_;
  best_x_ = x_f_;
}

double constraint_violation(const Program& nlp, const VectorXd& x, int* worst, double* value) {
  double largest = 0.0;
  int index = -1;
  double at = 0.0;
  VectorXd c;
  if (nlp.n_eq() > 0) {
    nlp.equalities(x, c, nullptr);
    for (int i = 0; i < c.size(); ++i) {
      const double v =
          std::isfinite(c[i]) ? std::abs(c[i]) : std::numeric_limits<double>::infinity();
      if (v > largest) largest = v, index = i, at = c[i];
    }
  }
  if (nlp.n_ineq() > 0) {
    nlp.inequalities(x, c, nullptr);
    for (int i = 0; i < c.size(); ++i) {
      const double v = std::isfinite(c[i]) ? c[i] : std::numeric_limits<double>::infinity();
      if (v > largest) largest = v, index = nlp.n_eq() + i, at = c[i];
    }
  }
  if (worst) *worst = index;
  if (value) *value = at;
  return largest;
}

// ---------------------------------------------------------------------------------------------
// NLopt

namespace {

// what the callbacks share; NLopt's C callbacks must not throw, so an exception is stored here,
// the run is stopped, and the message is reported
struct Context {
  TrackedNlp* tracked{};
  nlopt_opt opt{};
  double delta{};  // mma: how far the inequalities are tightened
  VectorXd x, grad, c;
  MatrixXd jac;
  std::string error;  // what a callback threw
};

void fail(Context& ctx, const std::exception& e) {
  if (ctx.error.empty()) ctx.error = e.what();
  nlopt_force_stop(ctx.opt);
}

double objective_cb(unsigned n, const double* x, double* grad, void* data) {
  Context& ctx = *static_cast<Context*>(data);
  try {
    ctx.x = Eigen::Map<const VectorXd>(x, n);
    double f;
    if (grad) {
      ctx.grad.resize(n);
      f = ctx.tracked->objective(ctx.x, &ctx.grad);
      Eigen::Map<VectorXd>(grad, n) = ctx.grad;
    } else {
      f = ctx.tracked->objective(ctx.x, nullptr);
    }
    // a design the evaluation cannot handle is infinitely bad, never NaN
    return std::isfinite(f) ? f : HUGE_VAL;
  } catch (const std::exception& e) {
    fail(ctx, e);
    return HUGE_VAL;
  }
}

// c_eq(x) = 0 as one vector constraint; NLopt's gradient is m x n row-major
void equalities_cb(unsigned m, double* result, unsigned n, const double* x, double* gradient,
                   void* data) {
  Context& ctx = *static_cast<Context*>(data);
  try {
    ctx.x = Eigen::Map<const VectorXd>(x, n);
    ctx.tracked->equalities(ctx.x, ctx.c, gradient ? &ctx.jac : nullptr);
    Eigen::Map<VectorXd>(result, m) = ctx.c;
    if (gradient) Eigen::Map<RowMajorMatrix>(gradient, m, n) = ctx.jac;
  } catch (const std::exception& e) {
    fail(ctx, e);
    std::fill(result, result + m, HUGE_VAL);
  }
}

void inequalities_cb(unsigned m, double* result, unsigned n, const double* x, double* gradient,
                     void* data) {
  Context& ctx = *static_cast<Context*>(data);
  try {
    ctx.x = Eigen::Map<const VectorXd>(x, n);
    ctx.tracked->inequalities(ctx.x, ctx.c, gradient ? &ctx.jac : nullptr);
    Eigen::Map<VectorXd>(result, m) = ctx.c;
    if (gradient) Eigen::Map<RowMajorMatrix>(gradient, m, n) = ctx.jac;
  } catch (const std::exception& e) {
    fail(ctx, e);
    std::fill(result, result + m, HUGE_VAL);
  }
}

// mma: c_in + δ <= 0 (MMA's last iterates may lie slightly outside the constraints)
void tightened_inequalities_cb(unsigned m, double* result, unsigned n, const double* x,
                               double* gradient, void* data) {
  inequalities_cb(m, result, n, x, gradient, data);
  const Context& ctx = *static_cast<const Context*>(data);
  for (unsigned i = 0; i < m; ++i) result[i] += ctx.delta;
}

Termination termination_of(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
    case NLOPT_STOPVAL_REACHED:
    case NLOPT_FTOL_REACHED:
    case NLOPT_XTOL_REACHED:
      return Termination::kConverged;
    case NLOPT_MAXEVAL_REACHED:
    case NLOPT_MAXTIME_REACHED:
      return Termination::kMaxEvaluations;
    default:
      return Termination::kFailed;
  }
}

std::string describe(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "stopval reached";
    case NLOPT_FTOL_REACHED:
      return "ftol_rel reached";
    case NLOPT_XTOL_REACHED:
      return "xtol_rel reached";
    case NLOPT_MAXEVAL_REACHED:
      return "evaluation budget spent";
    case NLOPT_MAXTIME_REACHED:
      return "time budget spent";
    case NLOPT_FAILURE:
      return "generic failure";
    case NLOPT_INVALID_ARGS:
      return "invalid arguments";
    case NLOPT_OUT_OF_MEMORY:
      return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff errors limited progress";
    case NLOPT_FORCED_STOP:
      return "forced stop";
    default:
      return "unknown NLopt result " + std::to_string(static_cast<int>(r));
  }
}

const char* nlopt_name(Algorithm a) {
  switch (a) {
    case Algorithm::kSlsqp:
      return "NLopt LD_SLSQP";
    case Algorithm::kMma:
      return "NLopt LD_MMA";
    case Algorithm::kMlsl:
      return "multistart of NLopt LD_SLSQP";
    case Algorithm::kIsres:
      return "NLopt GN_ISRES";
    case Algorithm::kCobyla:
      return "NLopt LN_COBYLA";
    case Algorithm::kIpopt:
      break;
  }
  return "NLopt";
}

// bounds a global method can sample: an infinite bound becomes x0 ± 10 max(1, |x0|)
void finite_bounds(const VectorXd& x0, VectorXd& lower, VectorXd& upper) {
  for (int i = 0; i < x0.size(); ++i) {
    const double reach = 10.0 * std::max(1.0, std::abs(x0[i]));
    if (!std::isfinite(lower[i])) lower[i] = std::min(x0[i], upper[i]) - reach;
    if (!std::isfinite(upper[i])) upper[i] = std::max(x0[i], lower[i]) + reach;
  }
}

// one NLopt run: the outcome with the point NLopt returned and its objective
struct Run {
  nlopt_result result{NLOPT_FAILURE};
  VectorXd x;
  double f = HUGE_VAL;
  std::string error;  // a callback's exception or NLopt's own error message
};

Run run_nlopt(nlopt_algorithm algorithm, bool mma, TrackedNlp& tracked, const VectorXd& x0,
              const VectorXd& lower, const VectorXd& upper, int max_evaluations,
              const OptimizeOptions& options, bool stop_on_tolerances) {
  const Program& nlp = tracked.nlp();
  const unsigned n = static_cast<unsigned>(nlp.n());
  Run run;
  Context ctx;
  ctx.tracked = &tracked;
  ctx.delta = 0.5 * options.constraint_tolerance;
  ctx.opt = nlopt_create(algorithm, n);
  if (!ctx.opt) {
    run.error = "nlopt_create failed";
    return run;
  }
  // the options; any failure here is an invalid argument, reported as such
  nlopt_result status = NLOPT_SUCCESS;
  auto check = [&status](nlopt_result r) {
    if (r < 0 && status >= 0) status = r;
  };
  check(nlopt_set_lower_bounds(ctx.opt, lower.data()));
  check(nlopt_set_upper_bounds(ctx.opt, upper.data()));
  check(nlopt_set_min_objective(ctx.opt, objective_cb, &ctx));
  const double tol = 0.1 * options.constraint_tolerance;
  const unsigned n_eq = static_cast<unsigned>(nlp.n_eq());
  const unsigned n_in = static_cast<unsigned>(nlp.n_ineq());
  if (n_eq > 0) {  // optimize() refuses equalities with mma
    const std::vector<double> tols(n_eq, tol);
    check(nlopt_add_equality_mconstraint(ctx.opt, n_eq, equalities_cb, &ctx, tols.data()));
  }
  if (n_in > 0) {
    if (mma) {
      // MMA's iterates approach the constraints' boundary from either side: tightened by δ
      check(nlopt_add_inequality_mconstraint(ctx.opt, n_in, tightened_inequalities_cb, &ctx,
                                             std::vector<double>(n_in, 0.0).data()));
    } else {
      const std::vector<double> tols(n_in, tol);
      check(nlopt_add_inequality_mconstraint(ctx.opt, n_in, inequalities_cb, &ctx, tols.data()));
    }
  }
  check(nlopt_set_maxeval(ctx.opt, std::max(1, max_evaluations)));
  // MMA solves a dual subproblem per iteration, one multiplier per inequality, by default to
  // ftol_rel 1e-14 within as many steps as the outer budget (up to 100 000). With a peak term
  // (one inequality per sample, nearly dependent) that dual never gets there and a run takes
  // orders of magnitude longer; capped at 1000 steps, the runs whose duals converge are
  // unchanged (docs/performance.md, "MMA with a peak term")
  if (mma) check(nlopt_set_param(ctx.opt, "dual_maxeval", 1000));
  if (stop_on_tolerances) {
    check(nlopt_set_xtol_rel(ctx.opt, options.relative_tolerance));
    check(nlopt_set_ftol_rel(ctx.opt, options.relative_tolerance));
  }

  // the start inside the bounds (NLopt requires it)
  run.x = x0.cwiseMax(lower).cwiseMin(upper);
  if (status >= 0) {
    double f = HUGE_VAL;
    status = nlopt_optimize(ctx.opt, run.x.data(), &f);
    run.f = f;
  }
  run.result = status;
  if (!ctx.error.empty()) {
    run.error = ctx.error;
  } else if (status < 0) {
    if (const char* msg = nlopt_get_errmsg(ctx.opt)) run.error = msg;
    // NLopt's SLSQP says "bug: more than iter SQP iterations" when its line search gives up;
    // it is not a bug of anyone's, and a user should not read it as one
    if (run.error.find("more than iter SQP iterations") != std::string::npos) {
      run.error = "its line search made no progress";
    }
  }
  nlopt_destroy(ctx.opt);
  return run;
}

// SLSQP, restarted from its last iterate while it stops on a tolerance with a last iterate
// better than the point it returns (nlopt_driver.hpp says why)
Run run_slsqp(TrackedNlp& tracked, const VectorXd& x0, const VectorXd& lower, const VectorXd& upper,
              int max_evaluations, const OptimizeOptions& options) {
  const int first = tracked.evaluations();
  Run run =
      run_nlopt(NLOPT_LD_SLSQP, false, tracked, x0, lower, upper, max_evaluations, options, true);
  for (int restart = 0; restart < 3; ++restart) {
    const int left = max_evaluations - (tracked.evaluations() - first);
    const VectorXd last = tracked.last_x();
    if (termination_of(run.result) != Termination::kConverged || left <= 0 ||
        last.size() != run.x.size() || last == run.x || !(tracked.last_objective() < run.f)) {
      break;
    }
    Run next = run_nlopt(NLOPT_LD_SLSQP, false, tracked, last, lower, upper, left, options, true);
    // keep the better of the two by NLopt's own account (its f is of a feasible point when it
    // saw one); an error ends the restarts
    if (!next.error.empty() || next.result < 0) break;
    if (next.f <= run.f || termination_of(next.result) == Termination::kConverged) run = next;
  }
  // a restart that ended early may still have visited a better feasible point
  if (tracked.has_best() && tracked.best_objective() < run.f &&
      termination_of(run.result) == Termination::kConverged) {
    run.x = tracked.best_x();
    run.f = tracked.best_objective();
  }
  return run;
}

// the point to report from a run: NLopt's own if it converged at a feasible point, else the
// best feasible point the run visited (when better than NLopt's)
VectorXd chosen_point(const Run& run, const TrackedNlp& tracked, double tolerance,
                      std::string& note) {
  const Program& nlp = tracked.nlp();
  const bool feasible = constraint_violation(nlp, run.x) <= tolerance;
  const bool converged = termination_of(run.result) == Termination::kConverged;
  if (feasible && (converged || !tracked.has_best() || run.f <= tracked.best_objective())) {
    return run.x;
  }
  if (tracked.has_best()) {
    note = "; the best feasible point evaluated is returned";
    return tracked.best_x();
  }
  return run.x;
}

std::string run_message(Algorithm a, const Run& run, int max_evaluations) {
  std::string m = std::string(nlopt_name(a)) + ": " + describe(run.result);
  if (run.result == NLOPT_MAXEVAL_REACHED) m += " (" + std::to_string(max_evaluations) + ")";
  if (!run.error.empty()) m += ": " + run.error;
  return m;
}

// the first primes, one per Halton dimension
std::vector<int> primes(int count) {
  std::vector<int> p;
  for (int k = 2; static_cast<int>(p.size()) < count; ++k) {
    bool prime = true;
    for (int q : p) {
      if (q * q > k) break;
      if (k % q == 0) {
        prime = false;
        break;
      }
    }
    if (prime) p.push_back(k);
  }
  return p;
}

// the radical inverse of i in base b (Halton coordinate) in [0, 1)
double radical_inverse(int i, int b) {
  double f = 1.0, r = 0.0;
  for (int k = i; k > 0; k /= b) {
    f /= b;
    r += f * (k % b);
  }
  return r;
}

// the local runs of a multistart, one after the other in this thread (no StartPool given)
std::vector<LocalRun> run_here(int count, const std::function<LocalRun(int)>& run) {
  std::vector<LocalRun> runs;
  runs.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) runs.push_back(run(i));
  return runs;
}

// "mlsl": a multistart of SLSQP runs from x0 and from Halton points (randomly shifted by the
// seed, a Cranley-Patterson rotation) within the bounds, the best feasible optimum kept. Each
// run has a budget of its own and depends on its index alone, so the runs may be computed
// anywhere (options.start_pool) and give the same result.
DriverOutcome multistart(const Program& nlp, const VectorXd& x0, const OptimizeOptions& options) {
  const int starts = std::max(options.starts, 1);
  VectorXd lower = nlp.lower(), upper = nlp.upper();
  finite_bounds(x0, lower, upper);
  const int n = nlp.n();
  const std::vector<int> base = primes(n);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  VectorXd shift(n);
  for (int i = 0; i < n; ++i) shift[i] = uniform(rng);

  const auto local_run = [&](int s) {
    const int budget = std::max(1, options.max_evaluations / starts +
                                       (s < options.max_evaluations % starts ? 1 : 0));
    VectorXd start = x0;
    if (s > 0) {
      for (int i = 0; i < n; ++i) {
        const double u = std::fmod(radical_inverse(s, base[i]) + shift[i], 1.0);
        start[i] = lower[i] + u * (upper[i] - lower[i]);
      }
    }
    TrackedNlp tracked(nlp, options.constraint_tolerance);
    Run run = run_slsqp(tracked, start, nlp.lower(), nlp.upper(), budget, options);
    std::string note;
    LocalRun out;
    out.x = chosen_point(run, tracked, options.constraint_tolerance, note);
    out.violation = constraint_violation(nlp, out.x);
    out.objective =
        out.violation <= options.constraint_tolerance ? nlp.objective(out.x, nullptr) : run.f;
    out.evaluations = tracked.evaluations();
    out.result = run.result;
    out.error = run.error;
    return out;
  };
  const std::vector<LocalRun> runs = options.start_pool
                                         ? options.start_pool->run_all(starts, local_run)
                                         : run_here(starts, local_run);

  DriverOutcome out;
  bool have = false, have_feasible = false;
  double best_f = HUGE_VAL, best_violation = HUGE_VAL;
  int best_start = 0, feasible_runs = 0;
  const LocalRun* best = nullptr;
  for (int s = 0; s < starts; ++s) {
    const LocalRun& run = runs[static_cast<std::size_t>(s)];
    out.evaluations += run.evaluations;
    const bool feasible = run.violation <= options.constraint_tolerance;
    if (feasible) ++feasible_runs;
    // a feasible run beats an infeasible one; among feasible ones the lower objective wins,
    // among infeasible ones the smaller violation
    const bool better = !have || (feasible && (!have_feasible || run.objective < best_f)) ||
                        (!feasible && !have_feasible && run.violation < best_violation);
    if (better) {
      have = true;
      have_feasible = feasible;
      best_f = run.objective;
      best_violation = run.violation;
      best_start = s + 1;
      best = &run;
    }
  }
  out.x = best->x;
  out.iterations = out.evaluations;
  out.termination = termination_of(static_cast<nlopt_result>(best->result));
  out.starts = starts;
  for (const LocalRun& run : runs) {
    if (run.violation <= options.constraint_tolerance &&
        run.objective <= best_f + kSameValue * std::max(std::abs(best_f), 1.0)) {
      ++out.starts_at_best;
    }
  }
  out.message = "multistart of NLopt LD_SLSQP (mlsl): " + std::to_string(starts) +
                " local runs, " + std::to_string(feasible_runs) + " feasible, " +
                std::to_string(out.starts_at_best) + " reaching the best value; best from start " +
                std::to_string(best_start) + ": " + describe(static_cast<nlopt_result>(best->result));
  if (!best->error.empty()) out.message += ": " + best->error;
  return out;
}

}  // namespace

DriverOutcome solve_with_nlopt(const Program& nlp, const VectorXd& x0,
                               const OptimizeOptions& options) {
  if (options.algorithm == Algorithm::kMlsl) return multistart(nlp, x0, options);

  nlopt_algorithm algorithm = NLOPT_LD_SLSQP;
  bool global = false;
  switch (options.algorithm) {
    case Algorithm::kSlsqp:
      algorithm = NLOPT_LD_SLSQP;
      break;
    case Algorithm::kMma:
      algorithm = NLOPT_LD_MMA;
      break;
    case Algorithm::kCobyla:
      algorithm = NLOPT_LN_COBYLA;
      break;
    case Algorithm::kIsres:
      algorithm = NLOPT_GN_ISRES;
      global = true;
      break;
    case Algorithm::kMlsl:
    case Algorithm::kIpopt:
      break;
  }
  VectorXd lower = nlp.lower(), upper = nlp.upper();
  if (global) {
    finite_bounds(x0, lower, upper);
    nlopt_srand(options.seed);
  }
  TrackedNlp tracked(nlp, options.constraint_tolerance);
  // ISRES is stochastic: it runs to its budget rather than stopping on a quiet generation
  Run run = options.algorithm == Algorithm::kSlsqp
                ? run_slsqp(tracked, x0, lower, upper, options.max_evaluations, options)
                : run_nlopt(algorithm, options.algorithm == Algorithm::kMma, tracked, x0, lower,
                            upper, options.max_evaluations, options, !global);
  if (global) nlopt_srand_time();

  DriverOutcome out;
  std::string note;
  out.x = chosen_point(run, tracked, options.constraint_tolerance, note);
  out.termination = termination_of(run.result);
  out.message = run_message(options.algorithm, run, options.max_evaluations) + note;
  out.evaluations = tracked.evaluations();
  out.iterations = out.evaluations;
  return out;
}

}  // namespace bd::optimize::detail
