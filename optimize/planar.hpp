#pragma once
/// Optimisation of any planar linkage's mass design in a driven scene: counterweights on its
/// links and its links' own mass parameters as variables, an objective and limits on the
/// linkage's metrics (core/planar/metrics.hpp) and the added mass, and full force balance as
/// linear equalities (balance/planar.hpp). Solved by the same drivers as the four-bar
/// (optimize/program.hpp).
///
/// In a driven scene the motion is prescribed, so every output of the engine's table (shaking
/// force and moment, drive efforts, every support and joint force) is affine in the mass
/// parameters π (per link m, m e, m f and J about its first node; per point mass m): the
/// regressor y = y0 + A (π - π0) is taken from the engine itself, one driven run per parameter
/// (exact: the outputs are affine, so a difference is a column). Every metric and its exact
/// gradient through ∂π/∂x then costs no simulation. Link forces applied at a centre of mass
/// would move with the design's centre of mass (not affine in π): such a linkage is refused.
///
/// Variables, in this order: per counterweight its mass in [0, mass_max] [kg] and its centre
/// (x, y) [m] in the link's axes from its pivot (the link's ground node, or its first node),
/// boxed in [-distance_max, distance_max] with the envelope x² + y² <= distance_max²; per link
/// parameter its value within its bounds.
///
/// Objective: Σ w sqrt(r² + ε²) over the RMS terms, r = metric / original (ε the smoothing, as
/// the four-bar's linear form, optimize/nlp.hpp), + Σ w t over the peaks (a `_max`
/// metric), each with a bound variable t (a fraction of the original's peak) and
/// sqrt(|y_s|² / original² + ε²) <= t at every sample,
/// + w added_mass / (original total mass). Limits: (metric / (value original))² - 1
/// <= 0 for an RMS; the same at every sample for a peak; (added_mass - value) / (original total
/// mass) <= 0. Force balance: the independent rows of the momentum conditions.
#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "balance/counterweight.hpp"
#include "balance/planar.hpp"
#include "core/planar/metrics.hpp"
#include "core/planar/model.hpp"
#include "core/planar/simulate.hpp"
#include "optimize/optimize.hpp"
#include "optimize/problem.hpp"
#include "optimize/program.hpp"

namespace bd::optimize::planar {

namespace cp = core::planar;

/// A counterweight as design variables on a link (grounded or floating).
struct CounterweightVariables {
  int link{};
  double mass_max = 10.0;     // [kg] > 0
  double distance_max = 1.0;  // [m] > 0, from the link's pivot
  balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
  double thickness = 0.02;  // disc [m] > 0
  double density = 7850.0;  // disc [kg/m^3] > 0
};

/// One of a link's own mass parameters as a variable, within bounds.
struct LinkParameterVariable {
  int link{};
  using Parameter = optimize::LinkParameterVariable::Parameter;
  Parameter parameter = Parameter::kMass;
  double lower{}, upper{};  // [kg], [m], [m], [kg m^2]; mass lower > 0, inertia lower >= 0
};

/// A term of the objective: a metric of the linkage's table by name (an RMS, "Fsh_rms",
/// "RA0_rms", "tau_rms"), or "added_mass".
struct Term {
  std::string metric;
  double weight = 1.0;  // >= 0
};
/// metric <= value · original (a metric of the table, RMS or peak), or added_mass <= value [kg].
struct Limit {
  std::string metric;
  double value = 1.0;
};

struct DesignProblem {
  cp::Linkage original;
  /// A driven scene: exact gradients from the regressor. A free scene: every evaluation is a
  /// simulation of the design (`simulate`: by default the reduced route with cvode-adams), its
  /// gradients from the same run's forward sensitivities with respect to the varied links' mass
  /// parameters (core/planar/simulate.hpp, simulate_free_sensitivities(); none on the dae route
  /// or with an ERK pair: cobyla, isres only); the optimum is verified by the other route.
  std::variant<cp::DrivenScene, cp::FreeScene> scene;
  cp::SimulateOptions simulate;  // a free scene's integration
  std::vector<CounterweightVariables> counterweights;
  std::vector<LinkParameterVariable> link_parameters;
  std::vector<Term> objective;
  std::vector<Limit> limits;
  bool force_balance = false;  // full force balance as equalities
  double smoothing = kDefaultSmoothing;
  /// Peaks bounded over the motion, not only at the samples (the default), as the four-bar's
  /// DesignProblem::resolve_peaks; the original's peaks that normalise the objective and the
  /// limits are then its resolved ones. Driven scenes: exchange steps: where a peak of the
  /// objective or of a limit, resolved between the samples at the optimum, rises above the peak
  /// the program bounded (by more than 1e-9 of the original's), instants around it are added to
  /// peak_times and the problem is solved again from that optimum; once bounded, the result is
  /// the lean program's. Free scenes: each simulation's peaks of the objective and the limits
  /// resolved between its samples, their gradients at the peaks' instants
  /// (PlanarNlp::free_run_metrics(), cp::free_derivatives_at()).
  bool resolve_peaks = true;
  /// Driven scenes: times [s] at which the peaks are bounded besides the scene's samples (the
  /// exchange steps add to them); the RMS metrics stay the samples'. Each must lie within the
  /// run (0 to its duration).
  std::vector<double> peak_times;
  /// Empty when valid, else the first problem; its field: "counterweights" or
  /// "link_parameters" with the element's index, "objective" or "limits" with the term's
  /// index, "original" (a link force at a centre of mass), "scene"; e.g. text()
  /// "objective[0]: Fsh_max is a peak; minimise an RMS and limit the peak".
  bd::Problem validate() const;
};

/// The program the drivers solve (optimize/program.hpp), with what a study needs to report it.
class PlanarNlp final : public Program {
 public:
  /// @throws bd::InputError for an invalid problem, an original that cannot run in the scene,
  ///         or a normaliser (the original's metric) that is zero.
  /// With CounterweightVariablesAs::kMassMoments each counterweight's (x, y) become its mass
  /// moment p = m (x, y) about the pivot [kg m], in [-mass_max distance_max, mass_max
  /// distance_max], its envelope the smoothed cone (optimize/program.hpp).
  explicit PlanarNlp(const DesignProblem& problem,
                     CounterweightVariablesAs as = CounterweightVariablesAs::kPositions);
  ~PlanarNlp() override;
  /// The constructor's checks (an invalid problem, an original that cannot run in the scene, a
  /// link without mass, force balance out of reach, a normaliser that is zero) at the cost of
  /// the original's run alone, without the regressor's runs of perturbed designs (two per mass
  /// parameter): what a study's validation needs. Nothing is kept.
  /// @throws bd::InputError as the constructor does.
  static void check(const DesignProblem& problem);
  PlanarNlp(const PlanarNlp&) = delete;
  PlanarNlp& operator=(const PlanarNlp&) = delete;

  int n() const override;
  int n_eq() const override;
  int n_ineq() const override;
  const Eigen::VectorXd& lower() const override;
  const Eigen::VectorXd& upper() const override;
  const std::vector<std::string>& variable_names() const override;
  const std::vector<std::string>& constraint_names() const override;
  bool has_gradients() const override;
  /// True in a free scene (every evaluation a simulation).
  bool free_scene() const;
  double objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const override;
  void equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                  Eigen::MatrixXd* jac) const override;
  void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                    Eigen::MatrixXd* jac) const override;
  std::string constraint_text(int i, const Eigen::VectorXd& x) const override;
  void polish(Eigen::VectorXd& x) const override;
  /// With mass-moment variables, each envelope row as |p| - m distance_max, scaled (the four-bar
  /// Nlp's, optimize/nlp.hpp).
  void first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& g,
                                Eigen::VectorXd& c, Eigen::MatrixXd& jac) const override;
  /// Empty when the problem is convex in mass-moment variables, else why not, as the four-bar
  /// Nlp's why_not_convex() decides it: a driven scene, and no metric of the objective or the
  /// limits with a regressor column (to 1e-9 of its largest) on a link's inertia about its first
  /// node where a counterweight's position or the link's e or f vary, or on its first moments
  /// where its mass and e or f vary together.
  std::string why_not_convex() const;
  /// A design in position variables (results' x) in this program's variables, and back (the
  /// design variables only; positions within distance_max, the pivot where m = 0), as the
  /// four-bar Nlp's.
  Eigen::VectorXd from_positions(const Eigen::VectorXd& x) const;
  Eigen::VectorXd to_positions(const Eigen::VectorXd& x) const;
  /// (As Nlp's.) x with each counterweight whose mass is below `fraction` of its mass_max taken away
  /// (mass and mass moment 0; in position variables x itself): a solver's end near the apex,
  /// where the direction of a vanishing mass moment is round-off, put on the apex itself.
  Eigen::VectorXd without_vanishing_counterweights(const Eigen::VectorXd& x,
                                                   double fraction) const override;
  std::vector<int> vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                     double fraction) const override;
  std::vector<int> counterweight_mass_variables() const override;
  std::vector<double> counterweight_reach() const override;
  Eigen::VectorXd within_envelopes(const Eigen::VectorXd& x) const override {
    return from_positions(to_positions(x));
  }
  /// start() with each counterweight's mass (and mass moment) scaled by `fraction`.
  Eigen::VectorXd start_scaled(double fraction) const;

  /// The design's own variables: the first ones of x (then one bound variable per peak of the
  /// objective, t >= the peak's magnitude at every sample).
  int design_variables() const;
  /// The original's link parameters (clamped to their bounds); each counterweight at half its
  /// mass_max (0 with `original`: the original design itself), half its distance_max from the
  /// pivot away from the link's other node; with force balance (and not `original`), the
  /// counterweights then moved onto the balance conditions (least-norm in their positions, more
  /// mass where a position would leave its envelope).
  Eigen::VectorXd start(bool original = false) const;
  /// The start at another design of the same variables (e.g. a Pareto front's neighbour): its
  /// design variables clamped to their bounds, each bound variable a hair above its peak there.
  Eigen::VectorXd start_at(const Eigen::VectorXd& design) const;
  /// The design at x: its links with their parameters and counterweights merged in.
  cp::Linkage design(const Eigen::VectorXd& x) const;
  std::vector<balance::planar::LinkCounterweight> counterweights(const Eigen::VectorXd& x) const;
  /// The metric table's values at x from the regressor (in core's table order), and the added
  /// mass [kg].
  std::vector<double> metrics(const Eigen::VectorXd& x) const;
  double added_mass(const Eigen::VectorXd& x) const;
  /// The times besides the samples at which a peak the program bounds has a local maximum over
  /// the program's instants at x, within `within` of the original's peak below its largest
  /// there, as the four-bar Nlp::peak_instants(). Empty in a free scene.
  std::vector<double> peak_instants(const Eigen::VectorXd& x, double within) const;
  /// The metric table's values over a free run of a design (`run` = cp::simulate_free(model, the
  /// problem's scene, options)) as this program evaluates its designs: the peaks of the
  /// objective and the limits resolved between the samples (with resolve_peaks), the others
  /// the largest samples. `peaks`, when given, receives where the resolved ones lie (the
  /// others' value 0).
  std::vector<double> free_run_metrics(const cp::Model& model, const cp::Trajectory& run,
                                       const cp::SimulateOptions& options,
                                       std::vector<core::Peak>* peaks = nullptr) const;
  /// The metric table (names, units) and the original's values.
  const std::vector<cp::ColumnMetric>& metric_table() const;
  const std::vector<double>& original_metrics() const;

 private:
  struct Impl;
  // checks_only: the original's run and the checks, no regressor columns (check())
  PlanarNlp(const DesignProblem& problem, CounterweightVariablesAs as, bool checks_only);
  /// A free scene's evaluation at x (optimize/planar.cpp).
  struct Evaluation;
  Evaluation simulated(const Eigen::VectorXd& x, bool gradient) const;
  /// start()'s design variables in positions (bound variables not set).
  Eigen::VectorXd positions_start(bool original) const;
  void set_bound_variables(Eigen::VectorXd& x) const;
  std::unique_ptr<Impl> impl_;
};

struct Result {
  Algorithm algorithm = Algorithm::kSlsqp;
  Termination termination = Termination::kNotRun;
  std::string message;
  Eigen::VectorXd x;
  std::vector<std::string> variable_names;
  int design_variables{};  // the first ones of x; the rest are bound variables of peaks
  double objective{}, constraint_violation{};
  int iterations{}, evaluations{};
  double seconds{};
  cp::Linkage design;
  std::vector<balance::planar::LinkCounterweight> counterweights;
  std::vector<cp::ColumnMetric> metric_table;
  std::vector<double> original, metrics;  // as the regressor evaluates them
  double added_mass{};                    // [kg]
  std::vector<double> verified;           // the design simulated by the engine
  /// Times [s] besides the samples at which the peaks were bounded (the problem's peak_times,
  /// then those the exchange steps added: resolved peaks of earlier rounds and instants around
  /// them); `metrics` and `verified` take their peaks over the samples and these.
  std::vector<double> peak_times;
  double verification_error{};            // largest relative difference metrics vs verified
  /// A second route: the optimum's inertial shaking force and moment from Newton's law on each
  /// body's centre of mass (the balance layer, kinematics alone) against the engine's (its
  /// support forces): the largest difference relative to the largest value; NaN when not run.
  double inertial_error = std::numeric_limits<double>::quiet_NaN();
  /// True when the optimum is proven global (as OptimizeResult::global); `optimality` says why,
  /// or why that is not proven.
  bool global{};
  std::string optimality;
  /// A lower bound of the objective over every feasible design (NaN: none) and how it was found
  /// (as OptimizeResult::lower_bound).
  double lower_bound = std::numeric_limits<double>::quiet_NaN();
  std::string lower_bound_source;
  int starts{}, starts_at_best{};  // mlsl's local runs (as OptimizeResult's)
  bool ok() const { return found_design(termination); }
  /// One line: algorithm, termination, iterations, evaluations, seconds, objective, constraint
  /// violation, verification.
  std::string brief_report() const;
};

/// Empty when the algorithm can take the problem, else why not (field "algorithm"): a gradient
/// method in a free scene whose simulation has no sensitivities (the dae route, an ERK pair),
/// mma with force balance.
bd::Problem check_algorithm(const DesignProblem& problem, const OptimizeOptions& options);

/// Solves the problem from PlanarNlp::start() (and, when that finds no design, once more from the
/// original design) and verifies the optimum by simulating it.
/// @throws bd::InputError as PlanarNlp's constructor, for invalid options, or for an
///         algorithm that cannot take the problem (mma with force balance).
/// `designs`: further starting points (results' x of the same variables), tried before the
/// natural start where they are feasible.
Result optimize(const DesignProblem& problem, const OptimizeOptions& options,
                const std::vector<Eigen::VectorXd>& designs = {});

/// A point of a Pareto front: the bound ε on the second metric (a fraction of the original's,
/// or kg for added_mass) and the design found under it.
struct ParetoPoint {
  double epsilon{};
  Result result;
};

/// The ε-constraint trade-off between two metrics of the problem's linkage (names of its metric
/// table, or "added_mass"), as the four-bar's pareto_front() (optimize/optimize.hpp): minimise
/// `first` alone under the problem's constraints and second <= ε for `points` values of ε spaced
/// between the extremes found by minimising each metric alone. `first` is an RMS or added_mass;
/// `second` any metric. The problem's own objective is not used.
/// @throws bd::InputError for points < 2, equal metrics, a metric the problem cannot take (a
///         peak as `first`, a name not in the table), or a second metric that is 0 for the
///         original (no bound relative to it).
std::vector<ParetoPoint> pareto_front(const DesignProblem& problem, const std::string& first,
                                      const std::string& second, int points,
                                      const OptimizeOptions& options);

}  // namespace bd::optimize::planar
