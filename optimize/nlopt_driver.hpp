#pragma once
/// Internal to bd_optimize (included by its optimize*.cpp and ipopt_driver.cpp only): what a solver
/// driver returns, the evaluation counter that remembers the best feasible point a solver has
/// seen, and the NLopt driver. NLopt's own header appears only in nlopt_driver.cpp.
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "optimize/optimize.hpp"
#include "optimize/program.hpp"

namespace bd::optimize::detail {

/// What a driver found and why it stopped. optimize() turns it into an OptimizeResult (and
/// re-checks feasibility itself).
struct DriverOutcome {
  Termination termination = Termination::kFailed;
  std::string message;  // the solver's reason in words, e.g. "NLopt SLSQP: ftol_rel reached"
  Eigen::VectorXd x;    // the point returned (the solver's, or the best feasible one it saw)
  int iterations{};     // solver iterations (NLopt exposes none: its evaluations are reported)
  int evaluations{};    // objective evaluations
  /// A multistart (mlsl): its local runs, and how many of them ended feasible within
  /// kSameValue of the best objective (0 and 0 for a single run).
  int starts{}, starts_at_best{};
};

/// Two local runs' objectives count as the same value within this, relative to the larger of
/// the best objective's size and 1 (the objectives are normalised: 1 at the original design).
inline constexpr double kSameValue = 1e-6;

/// The Nlp as a solver sees it: every call is forwarded, objective evaluations are counted, and
/// the best point at which the objective and all constraints were evaluated (in any order) with
/// a scaled violation <= the tolerance is remembered, so a run stopped by its budget can return
/// the best feasible point it visited rather than its last iterate.
class TrackedNlp {
 public:
  TrackedNlp(const Program& nlp, double constraint_tolerance);

  const Program& nlp() const { return nlp_; }
  double objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad);
  void equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac);
  void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac);

  int evaluations() const { return evaluations_; }
  /// The point of the last objective evaluation and its value (empty before the first).
  const Eigen::VectorXd& last_x() const { return x_f_; }
  double last_objective() const { return f_; }
  bool has_best() const { return has_best_; }
  const Eigen::VectorXd& best_x() const { return best_x_; }
  double best_objective() const { return best_f_; }
  /// Forgets the best point (a new local run of a multistart keeps counting evaluations).
  void reset_best() {
    has_best_ = false;
    best_f_ = std::numeric_limits<double>::infinity();
  }

 private:
  void consider();  // a candidate when f, c_eq and c_in are known at one x

  const Program& nlp_;
  double tolerance_;
  int evaluations_{};
  Eigen::VectorXd x_f_, x_eq_, x_in_;  // where each part was last evaluated
  double f_{}, violation_eq_{}, violation_in_{};
  bool has_best_{false};
  Eigen::VectorXd best_x_;
  double best_f_ = std::numeric_limits<double>::infinity();
};

/// Largest scaled constraint violation at x: max(|c_eq|, max(c_in, 0)), 0 without constraints.
/// `worst` (if not null) receives the index into nlp.constraint_names() of the worst one (-1 if
/// none is violated) and `value` its value.
double constraint_violation(const Program& nlp, const Eigen::VectorXd& x, int* worst = nullptr,
                            double* value = nullptr);

/// Runs the NLopt algorithm of options.algorithm (slsqp, mma, mlsl, isres, cobyla) from x0.
/// - slsqp, cobyla, isres: NLopt's LD_SLSQP, LN_COBYLA, GN_ISRES with the equalities and
///   inequalities as vector constraints (tolerance 0.1 · options.constraint_tolerance each).
///   NLopt's SLSQP tests ftol_rel and xtol_rel at every iterate, feasible or not, once any
///   feasible point has been seen, and then returns the best feasible point it visited: when
///   the iterates approach the constraints from outside it can stop next to the optimum yet
///   return a point far from it (docs/performance.md, "The objective's form"). So an
///   SLSQP run that stops on a tolerance with a last iterate better than the point returned is
///   restarted from that iterate, up to three times within the budget (mlsl's runs too).
/// - mma: LD_MMA takes inequalities only (optimize() refuses equalities: as pairs ±c <= δ they
///   stall MMA far from the optimum); they are tightened to c + δ <= 0 with
///   δ = 0.5 · options.constraint_tolerance, as MMA's last iterates may lie just outside.
/// - mlsl: a multistart of options.starts LD_SLSQP runs (NLopt's own G_MLSL cannot take
///   constraints): the first from x0, the others from a randomly shifted Halton sequence within
///   the bounds (seeded by options.seed), each with its own share of the budget, so that each
///   depends on its index alone and options.start_pool may compute them anywhere; the best
///   feasible local optimum is kept (the first of equals).
/// Budget: options.max_evaluations objective evaluations in all; xtol_rel = ftol_rel =
/// options.relative_tolerance for the local methods, the budget alone for isres.
/// A program solved by options.algorithm from x0, with the feasibility of the point returned
/// checked whatever the solver said (the message then names the binding constraint). With
/// options.check_gradients and exact gradients, the analytic derivatives are first compared with
/// central differences at x0; a disagreement ends it there (kFailed at x0, the worst entry in the
/// message, gradient_check_failed set).
struct Solved {
  Termination termination = Termination::kFailed;
  std::string message;
  Eigen::VectorXd x;
  int iterations{}, evaluations{};
  double seconds{}, objective{}, constraint_violation{};
  /// The first-order conditions' residual at x (optimize/first_order.hpp), for a program with
  /// gradients and a design found; NaN otherwise.
  double stationarity = std::numeric_limits<double>::quiet_NaN();
  bool gradient_check_failed{};
  int starts{}, starts_at_best{};  // a multistart's local runs (DriverOutcome)
};
/// A converged end, in a program with gradients, where the first-order conditions do not hold
/// to stationarity_tolerance() (optimize/first_order.hpp) is not taken as converged: the run goes on from there, by the same
/// algorithm once more and then by another local method (ipopt, or slsqp after ipopt), keeping
/// each continuation that finds a design no worse; where they still do not hold, the result is
/// Termination::kStoppedShort with the residual in the message. Without `to_first_order`, the
/// solver's end as it is (the first-order conditions not checked: a refinement whose caller
/// reads them itself).
Solved solve(const Program& program, const Eigen::VectorXd& x0, const OptimizeOptions& options,
             bool to_first_order = true);
/// solve() from the first of `starts` that is feasible, or, when none is, from the least
/// violated; when that finds no design, from each other start in turn, keeping the first design
/// found (or the least violated end). Counts and times add up over the runs.
Solved solve_from(const Program& program, const std::vector<Eigen::VectorXd>& starts,
                  const OptimizeOptions& options);

/// A start for a point of a front from its neighbour's design `from`, which may miss this point's
/// tighter bound: program.start_at() of the design nearest `from` on the segment to `to` (a
/// design that meets the bound: the second metric's minimiser) that meets every constraint of
/// `program`, by bisection on the segment to 2^-30 of it; start_at(from) itself when it is
/// feasible or `to` is not. Designs are position variables (their first entries; any bound
/// variables after them are set by start_at()). A local method started there goes on along the
/// front from the neighbour; started at `to` it can stay where the first metric has no gradient
/// (a counterweight of no mass, whose place does not matter).
template <class DesignProgram>
Eigen::VectorXd feasible_towards(const DesignProgram& program, const Eigen::VectorXd& from,
                                 const Eigen::VectorXd& to, double tolerance) {
  const Eigen::Index k = std::min(from.size(), to.size());
  const Eigen::VectorXd a = from.head(k), d = to.head(k) - a;
  auto at = [&](double t) { return program.start_at(a + t * d); };
  auto feasible = [&](double t) { return constraint_violation(program, at(t)) <= tolerance; };
  if (feasible(0) || !feasible(1)) return at(0);
  double lo = 0, hi = 1;  // infeasible at lo, feasible at hi
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    (feasible(mid) ? hi : lo) = mid;
  }
  return at(hi);
}

/// x with the variables it leaves at round-off from a bound (within 1e-12 of the variable's
/// range: a counterweight of 1e-35 kg, a solver's end at mass 0 or on a cone's apex) put on the
/// bound, so that such a counterweight is exactly none in the design, its tables and the study
/// written; x itself when that changes the objective beyond round-off or the constraints'
/// violation above max(violation, the tolerance). `objective` and `violation` are x's.
Eigen::VectorXd snapped_to_bounds(const Program& program, const OptimizeOptions& options,
                                  const Eigen::VectorXd& x, double objective, double violation);

/// x without the counterweights that change nothing the problem reads: each one that has mass at
/// x is taken away (its mass and its other two variables 0), in turn, where that leaves the
/// objective within 1e-12 of `objective` (relative; or lowers it) and the constraints' violation
/// within max(`violation`, the tolerance). A solver leaves such a counterweight where its start
/// put it (a counterweight on a crank turning at constant speed about the origin moves no drive
/// torque and no shaking moment about the origin: half its mass_max at half its distance_max), a
/// mass the designer would pay for and gain nothing by. A counterweight the problem reads only
/// by its mass moment (a shaking force, not an inertia: its mass and distance trade off freely)
/// is moved out to its distance_max with the mass that keeps its moment, where that reads the
/// same (position variables, Program::counterweight_reach()): the least mass for what it does.
/// `said`, when not null, gets what to append to the message ("; the crank counterweight
/// changed nothing ... and is left out", "; the rocker counterweight is moved out to ...").
Eigen::VectorXd without_needless_counterweights(const Program& program,
                                                const OptimizeOptions& options,
                                                const Eigen::VectorXd& x, double objective,
                                                double violation, std::string* said);

/// The feasibility of the point r.x, whatever the solver said: r.constraint_violation, and the
/// termination and message when they disagree with it (`solver` is the solver's message).
void check_feasibility(const Program& program, const OptimizeOptions& options,
                       const std::string& solver, Solved& r);

DriverOutcome solve_with_nlopt(const Program& nlp, const Eigen::VectorXd& x0,
                               const OptimizeOptions& options);

}  // namespace bd::optimize::detail
