#pragma once
/// Solving a DesignProblem with NLopt or Ipopt (Ceres-style: options in, result out). The
/// solvers' headers appear only in optimize/nlopt_driver.cpp and optimize/ipopt_driver.cpp.
#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "balance/counterweight.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/number_text.hpp"
#include "optimize/problem.hpp"

namespace bd::optimize {

enum class Algorithm {
  kSlsqp,   // NLopt SLSQP: local, gradient-based, equality and inequality constraints
  kMma,     // NLopt MMA (CCSA): local, gradient-based, inequality constraints only
  kIpopt,   // Ipopt interior point with exact first derivatives (limited-memory Hessian)
  kMlsl,    // NLopt MLSL (low-discrepancy multistart) with SLSQP as the local method: global
  kIsres,   // NLopt ISRES: global, derivative-free, handles constraints (evolution strategy)
  kCobyla,  // NLopt COBYLA: local, derivative-free
};
/// "slsqp", "mma", "ipopt", "mlsl", "isres", "cobyla" (the study file's names).
const char* to_string(Algorithm a);
std::optional<Algorithm> algorithm_named(const std::string& name);
/// True for the methods that need gradients.
bool uses_gradients(Algorithm a);
/// The methods other than `used` that can take a problem in such a scene, in the order worth
/// trying, as words: "ipopt, mlsl, slsqp" (driven scenes), "isres" (free scenes, after cobyla).
std::string other_algorithms(Algorithm used, bool free_scene);
/// The method a study gets when it names none: slsqp in a driven scene (exact gradients from
/// the regressor), cobyla in a free one (every evaluation a simulation; the gradient methods
/// there take the gradients of forward sensitivities, each evaluation dearer, and a simulation
/// that fails mid-search gives them no slope: docs/performance.md, "Free scenes", says why
/// cobyla stays).
constexpr Algorithm default_algorithm(bool free_scene) {
  return free_scene ? Algorithm::kCobyla : Algorithm::kSlsqp;
}

/// One local run of a multistart (mlsl): what the choice of the best run needs from it.
struct LocalRun {
  Eigen::VectorXd x;     // the point the run returns
  double objective{};    // at x (a feasible run's is re-evaluated there)
  double violation{};    // largest scaled constraint violation at x
  int evaluations{};     // objective evaluations the run spent
  int result{};          // NLopt's result code
  std::string error;     // what went wrong, if anything ("" when nothing)
};

/// Where a multistart's local runs are computed: each run depends on its index alone, so every
/// pool gives the same runs. Without one (OptimizeOptions::start_pool null) they run one after
/// the other in the calling thread; the command-line program's MPI job shares them among its
/// ranks (cli/mpi_sweep.hpp).
class StartPool {
 public:
  virtual ~StartPool() = default;
  /// runs[i] = run(i) for every i in [0, count), wherever each is computed.
  virtual std::vector<LocalRun> run_all(int count, const std::function<LocalRun(int)>& run) = 0;
};

struct OptimizeOptions {
  Algorithm algorithm = Algorithm::kSlsqp;
  int max_evaluations = 2000;
  /// mlsl: its local runs; each gets max_evaluations / starts evaluations (the first ones one
  /// more while the division leaves some), whatever the others spend
  int starts = 8;
  /// mlsl: where the local runs are computed (null: here, one after the other). Not owned.
  StartPool* start_pool = nullptr;
  double relative_tolerance = 1e-8;    // on x and on the objective
  double constraint_tolerance = 1e-9;  // feasibility of the reported optimum (scaled)
  bool check_gradients = false;        // compare analytic gradients with central differences first
  unsigned seed = 1;                   // global methods
  /// Leave out of the optimum each counterweight that changes nothing the problem reads, and
  /// move one the problem reads only by its mass moment out to its distance_max with the least
  /// mass (detail::without_needless_counterweights()). A Pareto front's points keep them: each
  /// point starts from its neighbour's design, and from a counterweight without mass (on its pivot)
  /// a local method has no gradient to grow it again where a tighter bound needs it.
  bool leave_out_needless_counterweights = true;
  /// Empty when valid, else the first problem, its field one of "algorithm",
  /// "max_evaluations", "starts", "relative_tolerance", "constraint_tolerance"; e.g. text()
  /// "max_evaluations must be >= 1, got 0".
  bd::Problem validate() const;
};

/// Whether options.algorithm can solve the problem at all, decided without solving anything:
/// a gradient method (uses_gradients()) in a free scene on the opened loop (formulation
/// kOpenedLoop, whose DAE has no sensitivities; the reduced equation's give the gradients of
/// every other free scene), or mma with force_balance (equalities, which mma does not take), is
/// a problem with field "algorithm", e.g. text() "algorithm 'slsqp' needs gradients, which a
/// free scene on the opened loop (method opened-loop) does not provide; use cobyla or isres, or
/// the method mass-matrix or complex-masses". optimize() refuses what this refuses.
bd::Problem check_algorithm(const DesignProblem& problem, const OptimizeOptions& options);
/// The same for any linkage type's problem: `without_gradients` empty where the problem has
/// gradients, else what lacks them and `instead` what would give them; with force balance or
/// not; e.g. text() "algorithm 'slsqp' needs gradients, which a free scene on the dae route
/// does not provide; use cobyla or isres, or the reduced route".
bd::Problem check_algorithm(const OptimizeOptions& options, const std::string& without_gradients,
                            const std::string& instead, bool force_balance);

enum class Termination {
  kNotRun,
  kConverged,       // a tolerance was met at a feasible point
  kMaxEvaluations,  // stopped by the budget; the best feasible point so far is returned
  /// the solver stopped at a feasible design where the first-order conditions do not hold to
  /// the tolerance (optimize/first_order.hpp), even after the restarts: a design, maybe not
  /// the best
  kStoppedShort,
  kInfeasible,      // no feasible point found; the message names the binding constraint
  kFailed,          // the solver failed (roundoff, invalid problem); the message says why
};
const char* to_string(Termination t);
/// True when a solver ending so returned a feasible design (converged, budget spent, stopped
/// short): it is simulated, verified and written.
constexpr bool found_design(Termination t) {
  return t == Termination::kConverged || t == Termination::kMaxEvaluations ||
         t == Termination::kStoppedShort;
}

/// A counterweight of the optimum, in the balance layer's terms.
struct PlacedCounterweight {
  int link{};  // 1 or 3
  balance::Counterweight counterweight;
};

/// The solver's part of a result's one-line report: "slsqp: converged, 12 iterations, 15
/// evaluations, 0.01 s, objective 0.2, constraint violation 0" (either linkage type's result).
template <class Result>
std::string solver_report(const Result& r) {
  return std::string(to_string(r.algorithm)) + ": " + to_string(r.termination) + ", " +
         std::to_string(r.iterations) + " iterations, " + std::to_string(r.evaluations) +
         " evaluations, " + text::digits(r.seconds, 3) + " s, objective " +
         text::digits(r.objective, 9) + ", constraint violation " +
         text::digits(r.constraint_violation, 2);
}

struct OptimizeResult {
  Termination termination = Termination::kNotRun;
  std::string message = "optimize() was not called";
  Algorithm algorithm = Algorithm::kSlsqp;
  Eigen::VectorXd x;                // the optimum's variables
  double objective{};               // at x
  double constraint_violation{};    // largest scaled violation at x (0 when feasible)
  int iterations{}, evaluations{};  // solver iterations, objective evaluations
  double seconds{};                 // wall time of the solve
  core::FourBar design;             // the optimum as a model (counterweights merged in)
  std::vector<PlacedCounterweight> counterweights;
  core::Metrics metrics;   // of the optimum, as the optimiser evaluated them
  core::Metrics verified;  // re-simulated with another formulation
  core::Formulation verified_with = core::Formulation::kMassMatrix;
  /// True where no closed form other than the optimiser's could follow the motion (a free scene
  /// that passes limit positions, which only the opened loop passes among them): the optimum
  /// was then verified on the general planar engine's DAE route (truss-dae).
  bool verified_on_general_engine = false;
  /// How the optimum was verified, in the study file's method names: "truss-dae" or
  /// verified_with's.
  std::string verified_by() const;
  double verification_error{};  // largest relative difference metrics vs verified
  /// True when the optimum is proven global: the problem is convex in the counterweights' masses
  /// and mass moments (Nlp::why_not_convex()) and the design meets the first-order conditions
  /// to the tolerance; `optimality` says why, or why that is not proven.
  bool global{};
  std::string optimality;
  /// A lower bound of the objective over every feasible design (NaN: none), so that the gap to
  /// `objective` shows what a better design could still gain; `lower_bound_source` says how it
  /// was found (the convex problem's first-order bound, or its convex relaxation's where the
  /// counterweights' inertias make it non-convex) or why there is none.
  double lower_bound = std::numeric_limits<double>::quiet_NaN();
  std::string lower_bound_source;
  /// mlsl: its local runs, and how many ended feasible at the best value (to 1e-6 of the
  /// objective's size); 0 and 0 for the single-start methods.
  int starts{}, starts_at_best{};
  /// Driven scenes: the crank angles [rad] where the optimum's peaks are bounded besides the
  /// samples (the problem's peak_angles, then those the exchange step added: resolved peaks of
  /// an optimum that rose above its sampled ones). `metrics` and `verified` take their peaks
  /// over the samples and these angles.
  std::vector<double> peak_angles;
  /// One line for the console and summary.json.
  std::string brief_report() const;
  bool ok() const { return found_design(termination); }
};

/// Solves the problem from its natural start (every variable at its value in the original
/// design, or mid-range where the original has none).
/// @throws bd::InputError if the problem or the options are invalid (validate()), if the problem
/// cannot be set up (Nlp's constructor), or if check_algorithm() finds a problem.
/// `designs` are further starting points (results' x of the same variables, e.g. a Pareto front's
/// neighbours), tried before the natural start where they are feasible (detail::solve_from).
OptimizeResult optimize(const DesignProblem& problem, const OptimizeOptions& options,
                        const std::vector<Eigen::VectorXd>& designs = {});

/// The ε-constraint trade-off between two metrics: minimise `first` subject to
/// second <= ε_i · second(original) for `points` values of ε spaced between the extremes found by
/// minimising each metric alone. Each point is a verified design.
struct ParetoPoint {
  double epsilon{};  // the bound on the second metric, fraction of the original
  OptimizeResult result;
};
std::vector<ParetoPoint> pareto_front(const DesignProblem& problem, Metric first, Metric second,
                                      int points, const OptimizeOptions& options);

}  // namespace bd::optimize
