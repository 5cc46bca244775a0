#pragma once
/// Internal to bd_optimize (nlp.cpp, driven_nlp.cpp, free_nlp.cpp): the program behind Nlp.
///
/// NlpProgram is the nonlinear program the drivers see through Nlp, with what every scene
/// shares: the variables, their bounds and names, the original's metrics (the normalisers),
/// the inertial parameters q(x) with their Jacobian, the design at x, the force-balance
/// equalities, and, of the inequalities, the counterweight envelopes and the added-mass limits.
/// Its two implementations evaluate the metrics: the driven scene's regressor
/// (make_driven_nlp(), driven_nlp.cpp) and the free scene's simulations (make_free_nlp(),
/// free_nlp.cpp). optimize/nlp.hpp documents the program's formulas.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"
#include "optimize/problem.hpp"
#include "optimize/relaxation.hpp"

namespace bd::optimize::detail {

// Layout of q = (π, ρ, 1): per link k = 1, 2, 3 at 4(k-1): m, m e, m f, J = I + m|s̄|² about the
// first joint; the counter-rotation inertias; the links' centres of mass (e, f) where the
// applied forces act; the constant 1 (the column y0 of the regressor).
inline constexpr int kQ = 21;
inline constexpr int kCrankDisc = 12, kRockerDisc = 13;
inline constexpr int kOne = 20;
constexpr int link_base(int k) { return 4 * (k - 1); }
constexpr int rho_base(int k) { return 14 + 2 * (k - 1); }
using VecQ = Eigen::Matrix<double, kQ, 1>;

/// q(x) and its Jacobian ∂q/∂x (kQ x n; empty unless asked for).
struct Inertial {
  VecQ q = VecQ::Zero();
  Eigen::MatrixXd B;
};

/// A run of inequality constraints of one kind.
struct Block {
  enum class Kind {
    kEnvelope,
    kRmsLimit,
    kPeakLimit,
    kAddedMassLimit,
    kPeakBound,
    kRelaxation  // a counterweight's relaxed inertia (CounterweightVariablesAs::kRelaxation)
  } kind{};
  int counterweight{-1};  // envelope, relaxation: its counterweight
  Metric metric{};        // limits and peak bounds
  double value{};         // a limit's value
  int bound_var{-1};      // peak bound: the variable t
  int count{};            // constraints in the block
};

/// The link parameter `p` of a link: its mass, e, f or inertia.
double& parameter(core::Link& link, LinkParameterVariable::Parameter p);

/// sqrt(r2 + eps²) for r2 = r² >= 0: the linear form's smoothed magnitude.
inline double smoothed(double r2, double eps) { return std::sqrt(r2 + eps * eps); }

class NlpProgram {
 public:
  virtual ~NlpProgram() = default;
  NlpProgram(const NlpProgram&) = delete;
  NlpProgram& operator=(const NlpProgram&) = delete;

  int n() const { return n_; }
  int n_eq() const { return n_eq_; }
  int n_ineq() const { return n_ineq_; }
  const Eigen::VectorXd& lower() const { return lower_; }
  const Eigen::VectorXd& upper() const { return upper_; }
  const std::vector<std::string>& variable_names() const { return variable_names_; }
  const std::vector<std::string>& constraint_names() const { return constraint_names_; }
  virtual bool has_gradients() const = 0;
  bool free_scene() const { return std::holds_alternative<core::FreeScene>(problem_.scene); }
  /// Nlp::why_not_convex(); the default: not convex, a free scene.
  virtual std::string why_not_convex() const;
  Eigen::VectorXd from_positions(const Eigen::VectorXd& x) const;
  Eigen::VectorXd to_positions(const Eigen::VectorXd& x) const;
  Eigen::VectorXd without_vanishing_counterweights(const Eigen::VectorXd& x, double fraction) const;
  std::vector<int> vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                     double fraction) const;

  // Nlp's functions of the same names; x has n() entries (Nlp checks)
  Eigen::VectorXd start(bool original = false) const;
  Eigen::VectorXd start_scaled(double fraction) const;
  /// The start at another design: its design variables (the first entries of `design`, as in
  /// this program's order), each within its bounds, and the rest set for it.
  Eigen::VectorXd start_at(const Eigen::VectorXd& design) const;
  virtual double objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const = 0;
  void equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const;
  void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const;
  void first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& g,
                                Eigen::VectorXd& c, Eigen::MatrixXd& jac) const;
  core::FourBar design(const Eigen::VectorXd& x) const;
  std::vector<PlacedCounterweight> counterweights(const Eigen::VectorXd& x) const;
  virtual core::Trajectory trajectory(const Eigen::VectorXd& x) const = 0;
  virtual core::Metrics metrics(const Eigen::VectorXd& x) const = 0;
  /// The first variable (the mass) of each counterweight.
  const std::vector<int>& cw_var() const { return cw_var_; }
  /// Program::counterweight_reach(): each counterweight's distance_max in position variables.
  std::vector<double> counterweight_reach() const {
    std::vector<double> out;
    if (moments_) return out;
    for (const CounterweightVariables& c : problem_.counterweights) out.push_back(c.distance_max);
    return out;
  }
  /// Nlp::peak_instants(); the default: none (a free scene has no added instants).
  virtual std::vector<double> peak_instants(const Eigen::VectorXd& /*x*/, double /*within*/) const {
    return {};
  }
  double metric(const Eigen::VectorXd& x, Metric m) const;
  /// The normaliser of a metric: the original's value, for added_mass its total mass [kg].
  double original(Metric m) const;
  /// Constraint i at x in words with units ("the added mass is 3.2 kg, at most 3 kg"), as
  /// Program::constraint_text(); "" for a row without words (a relaxation's, a peak bound's).
  std::string constraint_text(int i, const Eigen::VectorXd& x) const;

 protected:
  /// Validates the problem, evaluates the original in its scene (by core's own simulation) and
  /// checks its normalisers, and sets up the design variables. An implementation's constructor
  /// then adds its own variables and calls set_up_constraints().
  /// @throws bd::InputError as Nlp's constructor says: an invalid problem (its message after
  /// "invalid design problem: "); an original that cannot be evaluated (no field: the problem
  /// as a whole); a normaliser that vanishes (field "objective" or "limits" with the index of
  /// the term or limit).
  NlpProgram(const DesignProblem& problem, CounterweightVariablesAs as);

  /// The inertial parameters (entries of q) that are not affine in the variables, each with why
  /// in words ("the rocker's inertia about A3, which varies with the square of its
  /// counterweight's position"), as Nlp::why_not_convex() lists them.
  std::vector<std::pair<int, std::string>> non_affine_parameters() const;

  /// Adds a variable in [lower, upper]; returns its index.
  int add_variable(double lower, double upper, std::string name);
  /// The force-balance equalities, then the inequalities: the counterweight envelopes and the
  /// limits (a peak limit's rows named by peak_limit_names()).
  void set_up_constraints();
  /// Appends a block of inequalities with the names of its rows (block.count of them).
  void add_block(const Block& block, std::vector<std::string> names);
  /// The names of a peak limit's rows: the limit's own name for one row (the default).
  virtual std::vector<std::string> peak_limit_names(const std::string& name) const;
  /// Sets the variables beyond the design's at the start (the default sets none).
  virtual void start_extra_variables(Eigen::VectorXd& x) const;
  /// Fills the rows of the limits on reaction metrics and of the peak bounds (every block but
  /// the envelopes and the added-mass limits), and their Jacobian rows when jac is not null.
  virtual void metric_inequalities(const Eigen::VectorXd& x, const Inertial& in, Eigen::VectorXd& c,
                                   Eigen::MatrixXd* jac) const = 0;
  /// A reaction metric (any but added_mass) at x.
  virtual double reaction_metric(const Eigen::VectorXd& x, Metric m) const = 0;

  /// core's simulation of a model in the problem's scene, formulation and tolerance.
  core::Trajectory simulate(const core::FourBar& model) const;
  /// The options of simulate() (and of a free scene's runs with sensitivities).
  core::SimulateOptions simulate_options() const;
  /// q(x), with ∂q/∂x when asked for.
  Inertial inertial(const Eigen::VectorXd& x, bool with_jacobian) const;
  /// The added mass [kg] of the design whose inertial parameters are q.
  double added_mass(const VecQ& q) const;
  /// Throws std::logic_error when a derivative is asked for (`asked`) and there is none.
  void require_gradients(bool asked, const char* function) const;
  /// After require_gradients(): c resized to m and *jac (when asked for) zeroed to m x n();
  /// false when there are no such constraints (m = 0).
  bool sized(int m, Eigen::VectorXd& c, Eigen::MatrixXd* jac, const char* function) const;

  DesignProblem problem_;  // the original made consistent (core::make_fourbar)
  bool moments_{};         // counterweights as (m, p = m r): CounterweightVariablesAs::kMassMoments
  bool relaxed_{};         // and their inertias relaxed: CounterweightVariablesAs::kRelaxation
  core::Metrics original_metrics_;
  double original_mass_{};
  bool linear_{};                                     // ObjectiveForm::kLinear
  double eps_{};                                      // its smoothing
  std::array<double, std::size(kMetrics)> weight_{};  // aggregated objective weights per metric
  int n_{};
  Eigen::VectorXd lower_, upper_;
  std::vector<std::string> variable_names_, constraint_names_;
  std::vector<int> cw_var_;     // first variable (the mass) of each counterweight
  std::vector<int> param_var_;  // the variable of each link parameter
  std::vector<RelaxedCounterweight> relaxed_cw_;  // kRelaxation: each counterweight's variables
  int n_eq_{}, n_ineq_{};
  std::vector<Block> blocks_;
  Eigen::Matrix<double, 4, kQ> balance_ = Eigen::Matrix<double, 4, kQ>::Zero();

 private:
  void check_normalisers() const;
  void set_up_design_variables();
  /// kRelaxation: each counterweight's relaxed inertias at their real values for x's design.
  void set_relaxed_variables(Eigen::VectorXd& x) const;
  void set_up_force_balance();
  core::Link add_link(int k, const Eigen::VectorXd& x, Inertial& out, bool with_jacobian) const;
  void add_counterweight(int k, const core::Link& l, const Eigen::VectorXd& x, Inertial& out,
                         bool with_jacobian) const;
};

/// The index of a metric in kMetrics (and in weight_).
inline std::size_t metric_index(Metric m) { return static_cast<std::size_t>(m); }

/// The program of a problem in a driven scene: every metric from the regressor, exact gradients.
std::unique_ptr<NlpProgram> make_driven_nlp(const DesignProblem& problem,
                                            CounterweightVariablesAs as);
/// The program of a problem in a free scene: every evaluation a simulation, no gradients.
std::unique_ptr<NlpProgram> make_free_nlp(const DesignProblem& problem,
                                          CounterweightVariablesAs as);

}  // namespace bd::optimize::detail
