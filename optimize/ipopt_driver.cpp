#include "optimize/ipopt_driver.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <string>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <coin/IpIpoptApplication.hpp>
#include <coin/IpSolveStatistics.hpp>
#include <coin/IpTNLP.hpp>
#pragma GCC diagnostic pop

namespace bd::optimize::detail {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Ipopt::Index;
using Ipopt::Number;

// Ipopt's "no bound" (nlp_lower_bound_inf / nlp_upper_bound_inf default to -1e19 / 1e19)
constexpr double kNoBound = 1e20;

// The Nlp as an Ipopt TNLP: g = (c_eq; c_in) with bounds (0, 0) and (-inf, 0), a dense Jacobian,
// no exact Hessian (limited-memory approximation). A callback that throws or gives a
// non-finite value returns false, so Ipopt backs off (its line search cuts the step).
class Tnlp : public Ipopt::TNLP {
 public:
  Tnlp(TrackedNlp& tracked, const VectorXd& x0, int max_evaluations)
      : tracked_(tracked), nlp_(tracked.nlp()), x0_(x0), max_evaluations_(max_evaluations) {}

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = nlp_.n();
    m = nlp_.n_eq() + nlp_.n_ineq();
    nnz_jac_g = n * m;
    nnz_h_lag = 0;
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = std::isfinite(nlp_.lower()[i]) ? nlp_.lower()[i] : -kNoBound;
      x_u[i] = std::isfinite(nlp_.upper()[i]) ? nlp_.upper()[i] : kNoBound;
    }
    for (Index j = 0; j < m; ++j) {
      g_l[j] = j < nlp_.n_eq() ? 0.0 : -kNoBound;
      g_u[j] = 0.0;
    }
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number*, Number*, Index,
                          bool init_lambda, Number*) override {
    if (init_z || init_lambda) return false;  // a cold start only
    if (init_x) {
      for (Index i = 0; i < n; ++i) x[i] = x0_[i];
    }
    return true;
  }

  bool eval_f(Index n, const Number* x, bool, Number& obj_value) override {
    return guarded([&] {
      x_ = Eigen::Map<const VectorXd>(x, n);
      obj_value = tracked_.objective(x_, nullptr);
      return std::isfinite(obj_value);
    });
  }

  bool eval_grad_f(Index n, const Number* x, bool, Number* grad_f) override {
    return guarded([&] {
      x_ = Eigen::Map<const VectorXd>(x, n);
      grad_.resize(n);
      // the Nlp gives f and its gradient together; only f-only calls count as evaluations
      // of the objective for the budget, so this one is not counted twice
      nlp_.objective(x_, &grad_);
      Eigen::Map<VectorXd>(grad_f, n) = grad_;
      return grad_.allFinite();
    });
  }

  bool eval_g(Index n, const Number* x, bool, Index m, Number* g) override {
    return guarded([&] {
      x_ = Eigen::Map<const VectorXd>(x, n);
      Eigen::Map<VectorXd> out(g, m);
      if (nlp_.n_eq() > 0) {
        tracked_.equalities(x_, c_, nullptr);
        out.head(nlp_.n_eq()) = c_;
      }
      if (nlp_.n_ineq() > 0) {
        tracked_.inequalities(x_, c_, nullptr);
        out.tail(nlp_.n_ineq()) = c_;
      }
      return out.allFinite();
    });
  }

  bool eval_jac_g(Index n, const Number* x, bool, Index m, Index, Index* iRow, Index* jCol,
                  Number* values) override {
    if (values == nullptr) {
      // the structure: dense, row by row
      for (Index j = 0, k = 0; j < m; ++j) {
        for (Index i = 0; i < n; ++i, ++k) {
          iRow[k] = j;
          jCol[k] = i;
        }
      }
      return true;
    }
    return guarded([&] {
      x_ = Eigen::Map<const VectorXd>(x, n);
      using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      Eigen::Map<RowMajor> out(values, m, n);
      if (nlp_.n_eq() > 0) {
        nlp_.equalities(x_, c_, &jac_);
        out.topRows(nlp_.n_eq()) = jac_;
      }
      if (nlp_.n_ineq() > 0) {
        nlp_.inequalities(x_, c_, &jac_);
        out.bottomRows(nlp_.n_ineq()) = jac_;
      }
      return out.allFinite();
    });
  }

  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*,
                         const Number*, Index, const Number*, const Number*, Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    solution_ = Eigen::Map<const VectorXd>(x, n);
  }

  // stops the run once the budget of objective evaluations is spent
  bool intermediate_callback(Ipopt::AlgorithmMode, Index, Number, Number, Number, Number, Number,
                             Number, Number, Number, Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    if (tracked_.evaluations() >= max_evaluations_) {
      budget_spent_ = true;
      return false;
    }
    return true;
  }

  const VectorXd& solution() const { return solution_; }
  bool budget_spent() const { return budget_spent_; }
  const std::string& error() const { return error_; }

 private:
  template <class F>
  bool guarded(F&& f) {
    try {
      return f();
    } catch (const std::exception& e) {
      if (error_.empty()) error_ = e.what();
      return false;
    }
  }

  TrackedNlp& tracked_;
  const Program& nlp_;
  VectorXd x0_;
  int max_evaluations_;
  VectorXd x_, grad_, c_, solution_;
  MatrixXd jac_;
  bool budget_spent_ = false;
  std::string error_;
};

Termination termination_of(Ipopt::ApplicationReturnStatus s, bool budget_spent) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
    case Ipopt::Solved_To_Acceptable_Level:
    case Ipopt::Feasible_Point_Found:
    // steps below working precision (solve_with_ipopt() accepts it at a feasible point only):
    // stationary as far as double precision can tell, with a tolerance tighter than the
    // problem's conditioning allows (the linear objective's smoothed kink, where a metric
    // reaches 0, has curvature ~1/smoothing); NLopt calls the same event xtol_rel
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return Termination::kConverged;
    case Ipopt::Infeasible_Problem_Detected:
      return Termination::kInfeasible;
    case Ipopt::Maximum_Iterations_Exceeded:
    case Ipopt::Maximum_CpuTime_Exceeded:
      return Termination::kMaxEvaluations;
    case Ipopt::User_Requested_Stop:
      return budget_spent ? Termination::kMaxEvaluations : Termination::kFailed;
    default:
      return Termination::kFailed;
  }
}

std::string describe(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
      return "optimal solution found";
    case Ipopt::Solved_To_Acceptable_Level:
      return "solved to an acceptable level";
    case Ipopt::Infeasible_Problem_Detected:
      return "converged to a point of local infeasibility";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "search direction became too small (stationary to working precision)";
    case Ipopt::Diverging_Iterates:
      return "iterates diverging";
    case Ipopt::User_Requested_Stop:
      return "stopped";
    case Ipopt::Feasible_Point_Found:
      return "feasible point found";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "maximum number of iterations exceeded";
    case Ipopt::Restoration_Failed:
      return "restoration phase failed";
    case Ipopt::Error_In_Step_Computation:
      return "error in step computation";
    case Ipopt::Maximum_CpuTime_Exceeded:
      return "maximum CPU time exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return "not enough degrees of freedom";
    case Ipopt::Invalid_Problem_Definition:
      return "invalid problem definition";
    case Ipopt::Invalid_Option:
      return "invalid option";
    case Ipopt::Invalid_Number_Detected:
      return "invalid number detected";
    case Ipopt::Unrecoverable_Exception:
      return "unrecoverable exception";
    case Ipopt::NonIpopt_Exception_Thrown:
      return "non-Ipopt exception thrown";
    case Ipopt::Insufficient_Memory:
      return "insufficient memory";
    case Ipopt::Internal_Error:
      return "internal error";
  }
  return "unknown Ipopt status " + std::to_string(static_cast<int>(s));
}

// Ipopt's options: silent, quasi-Newton Hessian, our tolerances and budget; false if Ipopt
// refused one
bool set_options(Ipopt::OptionsList& o, const OptimizeOptions& options) {
  bool set = true;
  set &= o.SetStringValue("sb", "yes");  // no banner
  set &= o.SetIntegerValue("print_level", 0);
  set &= o.SetStringValue("hessian_approximation", "limited-memory");
  // the L-BFGS start sigma = y'y / s'y rather than s'y / s's: far fewer evaluations where the
  // curvature varies most (a metric approaching 0 at the optimum), a few more on some problems
  // (docs/performance.md, "The objective's form")
  set &= o.SetStringValue("limited_memory_initialization", "scalar2");
  set &= o.SetNumericValue("tol", options.relative_tolerance);
  set &= o.SetNumericValue("constr_viol_tol", 0.1 * options.constraint_tolerance);
  set &= o.SetNumericValue("acceptable_constr_viol_tol", 0.1 * options.constraint_tolerance);
  set &= o.SetIntegerValue("max_iter", options.max_evaluations);
  set &= o.SetNumericValue("nlp_lower_bound_inf", -0.5 * kNoBound);
  set &= o.SetNumericValue("nlp_upper_bound_inf", 0.5 * kNoBound);
  set &= o.SetStringValue("honor_original_bounds", "yes");
  // Ipopt relaxes every bound, the constraints' included, by 1e-8 by default: far more than
  // the feasibility we report, so the relaxation is kept below it
  set &= o.SetNumericValue("bound_relax_factor", 0.1 * options.constraint_tolerance);
  return set;
}

// Ipopt 3.11 (Debian 12) calls MUMPS, which is not thread-safe and has no lock of its own: one
// Ipopt application at a time in this process, held from its creation to its destruction
std::mutex ipopt_mutex;

}  // namespace

DriverOutcome solve_with_ipopt(const Program& nlp, const VectorXd& x0,
                               const OptimizeOptions& options) {
  const std::lock_guard<std::mutex> lock(ipopt_mutex);  // outlives the application below
  DriverOutcome out;
  out.x = x0;
  TrackedNlp tracked(nlp, options.constraint_tolerance);
  Ipopt::SmartPtr<Tnlp> problem =
      new Tnlp(tracked, x0.cwiseMax(nlp.lower()).cwiseMin(nlp.upper()), options.max_evaluations);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  if (!set_options(*app->Options(), options)) {
    out.termination = Termination::kFailed;
    out.message = "Ipopt: an option was refused";
    return out;
  }
  if (app->Initialize("") != Ipopt::Solve_Succeeded) {
    out.termination = Termination::kFailed;
    out.message = "Ipopt: initialisation failed";
    return out;
  }

  Ipopt::ApplicationReturnStatus status = Ipopt::Internal_Error;
  try {
    status = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(problem)));
  } catch (const std::exception& e) {
    out.termination = Termination::kFailed;
    out.message = std::string("Ipopt: ") + e.what();
    out.evaluations = tracked.evaluations();
    return out;
  }

  // the point: Ipopt's own when it converged feasibly, else the best feasible one evaluated
  out.termination = termination_of(status, problem->budget_spent());
  out.message = "Ipopt: " + describe(status);
  if (problem->budget_spent()) {
    out.message += ": evaluation budget (" + std::to_string(options.max_evaluations) + ") spent";
  }
  if (!problem->error().empty()) out.message += ": " + problem->error();
  if (problem->solution().size() == nlp.n()) out.x = problem->solution();
  const bool feasible = problem->solution().size() == nlp.n() &&
                        constraint_violation(nlp, out.x) <= options.constraint_tolerance;
  if (status == Ipopt::Search_Direction_Becomes_Too_Small && !feasible) {
    out.termination = Termination::kFailed;  // stuck, not stationary
  }
  if (out.termination != Termination::kConverged && tracked.has_best()) {
    const double f = feasible ? nlp.objective(out.x, nullptr) : HUGE_VAL;
    if (!feasible || tracked.best_objective() < f) {
      out.x = tracked.best_x();
      out.message += "; the best feasible point evaluated is returned";
    }
  }
  out.evaluations = tracked.evaluations();
  const Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics();
  out.iterations = Ipopt::IsValid(stats) ? stats->IterationCount() : 0;
  return out;
}

}  // namespace bd::optimize::detail
