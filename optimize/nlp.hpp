#pragma once
/// A DesignProblem as a smooth nonlinear program in the variables x:
///   minimise f(x)  subject to  c_eq(x) = 0,  c_in(x) <= 0,  lower <= x <= upper.
///
/// Variables, in this order (all in SI units, each of order one):
/// - per counterweight (problem order): its mass m_c in [0, mass_max] [kg], then its centre
///   (x, y) in link axes from the pivot (A0 for the crank, A3 for the rocker) [m], boxed in
///   [-distance_max, distance_max] with the smooth envelope x² + y² <= distance_max² as an
///   inequality. Cartesian rather than polar: an angle bound would cut the circle at ±π (a local
///   solver could not pass through it) and the polar form is degenerate at the pivot;
/// - per link parameter (problem order): its value within its bounds;
/// - driven scenes only: one bound variable t per peak metric of the objective [N or N m]: the
///   peak enters through smooth constraints on t at every sample, never as a non-smooth max.
///   t_max is a proven upper bound of that peak over the variable box; t lies in [0, t_max]
///   (squared form) or [-t_max, t_max] (linear form, where its constraints alone keep it > 0; a
///   bound at 0 would stall NLopt's SLSQP, see bound_peaks() in nlp.cpp). Free scenes have no
///   bound variables (their peaks are evaluated directly; the solvers there are
///   derivative-free).
///
/// Objective (problem.objective_form), with r_k = metric_k / metric_k(original) and
/// ε = problem.smoothing:
/// - linear (the default): Σ_k w_k · s(r_k) + w · added_mass / (original total mass), the
///   weighted sum of the normalised metrics, with each magnitude smoothed as
///   s(r) = sqrt(r² + ε²). |·| has a kink where it reaches 0 (a force-balanced design has
///   Fsh = 0), so s keeps the objective smooth there: its curvature at r = 0 is 1/ε. An RMS term
///   is s(sqrt(|R q|² / N) / o) (o the original's value); a peak term is w t / o with the
///   constraints (sqrt(|y_i|² + (ε o)²) - t) / o <= 0 at every sample i (linear in t, so their
///   gradient never vanishes; the earlier |y_i|² <= t² has none at t = 0, where it stalled
///   SLSQP and Ipopt at force-balanced optima). Free scenes: RMS terms s(r), peak terms r.
///   Accuracy: r <= s(r) <= r + min(ε, ε² / (2 r)), so with f the exact weighted sum and
///   f~ this objective, f <= f~ <= f + ε Σ w at every design, and at the minimiser x~ of f~
///       f(x*) <= f(x~) <= f~(x~) <= f(x*) + Σ_k w_k min(ε, ε² / (2 r_k(x*)))
///   for any minimiser x* of f: the reported objective brackets the exact optimum to ε Σ w
///   (terms that vanish at x*), or to O(ε²) when none does. With a single term f~ is a
///   monotone function of f, so both have the same minimisers.
/// - squared: Σ_k w_k r_k² + w · added_mass / (original total mass) (a peak term (t / o)² with
///   the constraints (|y_i|² - t²) / o² <= 0). Smooth everywhere, the same minimisers as the
///   linear form for a single term, but it weighs a term's large ratios more when there are
///   several (docs/performance.md, "The objective's form").
/// Limits (either form): (metric / (value · original))² - 1 <= 0 (RMS: one constraint; peak:
/// one per sample, |y_i|² against the limit; free scenes: one, on the directly evaluated
/// peak); (added_mass - value) / (original total mass) <= 0. A limit's value is > 0, so its
/// gradient does not vanish on its boundary.
/// Force balance (eq. 57): four linear equalities in the inertial parameters, divided by the
/// original total mass.
///
/// Driven scenes: the reactions, torque, shaking force and moment of every sample are affine in
/// q = (π, ρ, 1): π the 14 inertial parameters (per link m, m e, m f, and J = I + m|s̄|² about the
/// first joint; then the crank's and the rocker's counter-rotation inertias), ρ the links'
/// centres of mass (e, f) where the applied forces F̄k act (core applies F̄k at the centre of
/// mass, so its moment is linear in ρ, not in π), because the motion is prescribed. The
/// regressor y_i = A_i q is computed once from core's inverse dynamics; every metric is then a
/// quadratic form in q with an exact gradient through ∂q/∂x, at a cost independent of the
/// number of samples for RMS metrics (|A q|² = |R q|² with R from a QR of the stacked rows).
/// Free scenes: every evaluation is a forward simulation (core::simulate_free). With the
/// reduced equation in theta1 (formulations mass-matrix, complex-masses) the gradients come from
/// the same simulation's forward sensitivities (core/fourbar/sensitivity.hpp, CVODES) with
/// respect to the varied links' mass parameters, chained through ∂q/∂x; a peak's gradient is
/// its largest sample's. On the opened loop (opened-loop) has_gradients() is false:
/// derivative-free solvers only. A design whose simulation fails evaluates to +infinity
/// (objective, limit constraints and every metric; gradient 0).
///
/// Evaluations are const; free scenes keep the last simulation in a mutex-guarded cache, so the
/// objective and the constraints at the same x simulate once.
///
/// Nlp holds the program of its problem's scene (optimize/nlp_program.hpp): driven_nlp.cpp
/// evaluates by the regressor, free_nlp.cpp by simulation, nlp_program.cpp has what both share.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "optimize/optimize.hpp"
#include "optimize/problem.hpp"
#include "optimize/program.hpp"

namespace bd::optimize {

namespace detail {
class NlpProgram;
}

class Nlp final : public Program {
 public:
  /// Precomputes what the problem needs (the regressor for a driven scene, the original's
  /// metrics for the normalisation).
  /// @throws bd::InputError if problem.validate() finds a problem ("invalid design problem: "
  /// and its text).
  /// @throws bd::InputError also if the scene cannot be evaluated for the original (a driven
  /// crank that cannot turn, a failed free simulation; no field: the problem as a whole), or if
  /// the original's value of a metric in the objective or a limit is zero (to 1e-10 of the
  /// original's reactions), so that it cannot normalise: field "objective" or "limits", index
  /// that of the term or limit, e.g. text() "objective[0]: the original design's Fsh_rms is 0 N,
  /// too small to normalise by (it is already minimal)".
  explicit Nlp(const DesignProblem& problem,
               CounterweightVariablesAs as = CounterweightVariablesAs::kPositions);
  ~Nlp() override;
  Nlp(const Nlp&) = delete;
  Nlp& operator=(const Nlp&) = delete;

  int n() const override;       // variables, bound variables included
  int n_eq() const override;    // equality constraints
  int n_ineq() const override;  // inequality constraints (c <= 0)
  const Eigen::VectorXd& lower() const override;
  const Eigen::VectorXd& upper() const override;
  /// The natural start: each link parameter at its value in the original design (clamped to its
  /// bounds); each counterweight, which the original lacks, at half its mass_max and half its
  /// distance_max on the far side of the pivot (crank: (-d/2, 0) from A0; rocker: (d/2, 0) from
  /// A3, beyond the pivot); bound variables at the start design's peaks (feasible).
  /// With `original`: the original design itself (every counterweight's mass 0, at the same
  /// place), which meets any added-mass limit >= 0 and every limit of 1 or more.
  Eigen::VectorXd start(bool original = false) const;
  /// The natural start with each counterweight's mass (and mass moment) scaled by `fraction`
  /// (start() is 1, start(true) is 0): between the two, for a feasible start inside an
  /// added-mass budget.
  Eigen::VectorXd start_scaled(double fraction) const;
  /// The start at another design of the same problem's variables (e.g. a Pareto front's
  /// neighbour): its design variables, clamped to their bounds, the bound variables set for it.
  Eigen::VectorXd start_at(const Eigen::VectorXd& design) const;
  /// Names of the variables and of the constraints, for messages ("crank counterweight mass [kg]",
  /// "force balance, crank side (real part)", "Fsh_rms <= 0.2 x original", ...).
  const std::vector<std::string>& variable_names() const override;
  const std::vector<std::string>& constraint_names() const override;  // equalities first
  std::string constraint_text(int i, const Eigen::VectorXd& x) const override;
  /// True when exact gradients are available (driven scenes; free scenes on the reduced
  /// equation, by forward sensitivities).
  bool has_gradients() const override;
  /// True in a free scene (every evaluation a simulation).
  bool free_scene() const;
  /// Empty when the program is convex in mass-moment variables
  /// (CounterweightVariablesAs::kMassMoments), else why not in an engineer's words. Convex: a
  /// driven scene (the motion, so every sample's outputs, is then independent of the design);
  /// each metric of the objective and of the limits reads outputs that are affine in the
  /// variables, i.e. its regressor has no column (to 1e-9 of its largest) on an inertial
  /// parameter that is not: a link's inertia about its joint where a counterweight's position or
  /// the link's own e or f vary (it varies with their square), its first moments where its mass
  /// and e or f vary together, its centre of mass where an applied force acts on it and its mass
  /// varies; and the linear objective form where a peak is minimised (the squared form's
  /// |y|² <= t² is not convex in t). The objective (norms of affine maps, their smoothed
  /// magnitudes and squares, weighted by w >= 0, plus linear added mass), the limits (squared
  /// norms of affine maps below a constant), force balance (linear) and the envelopes (cones)
  /// are then convex: a point that meets the first-order conditions is a global minimum.
  std::string why_not_convex() const;
  /// A design of a kPositions program in this program's variables (the first design variables
  /// converted: r -> p = m r where this one takes moments), the rest set by start_at().
  Eigen::VectorXd from_positions(const Eigen::VectorXd& x) const;
  /// This program's design at x in position variables (p -> r = p / m within distance_max,
  /// r = 0 where m = 0): the first design variables only, to hand to a kPositions program's
  /// start_at().
  Eigen::VectorXd to_positions(const Eigen::VectorXd& x) const;
  /// x with each counterweight whose mass is below `fraction` of its mass_max taken away
  /// (mass and mass moment 0; in position variables x itself): a solver's end near the apex,
  /// where the direction of a vanishing mass moment is round-off, put on the apex itself.
  Eigen::VectorXd without_vanishing_counterweights(const Eigen::VectorXd& x,
                                                   double fraction) const override;
  std::vector<int> vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                     double fraction) const override;
  std::vector<int> counterweight_mass_variables() const override;
  std::vector<double> counterweight_reach() const override;
  Eigen::VectorXd within_envelopes(const Eigen::VectorXd& x) const override;

  /// The objective and, when `grad` is not null, its gradient.
  double objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const override;
  /// The equality constraints c_eq(x) (size n_eq) and, when `jac` is not null, their Jacobian
  /// (n_eq x n). Scaled by the original total mass.
  void equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                  Eigen::MatrixXd* jac) const override;
  /// The inequality constraints c_in(x) <= 0 (size n_ineq), Jacobian n_ineq x n, in this order:
  /// the counterweight envelopes (x² + y²)/distance_max² - 1, the limits (problem order), then
  /// the peak-bound constraints per sample for each peak objective term:
  /// (sqrt(|y_i|² + (ε original)²) - t)/original (linear form) or (|y_i|² - t²)/original²
  /// (squared form).
  /// Gradients (objective, equalities, inequalities) are exact where has_gradients(); asking for
  /// one otherwise throws std::logic_error. A wrong x.size() throws bd::InputError.
  void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                    Eigen::MatrixXd* jac) const override;
  /// With mass-moment variables, each envelope row as (|p| - m distance_max) / (mass_max
  /// distance_max), its gradient (-1/mass_max, p/|p| / (mass_max distance_max)), and at the apex
  /// (p = 0) the subgradient whose p part faces -g: the same cone, in a form whose gradient does
  /// not vanish there (Program::first_order_inequalities()).
  void first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& g,
                                Eigen::VectorXd& c, Eigen::MatrixXd& jac) const override;

  /// The design at x (counterweights merged into their links), and its counterweights.
  core::FourBar design(const Eigen::VectorXd& x) const;
  std::vector<PlacedCounterweight> counterweights(const Eigen::VectorXd& x) const;
  /// The samples of the design at x as this program evaluates them. Driven scenes: the
  /// regressor's RA0, RA3, Fsh, Msh and tau at each instant of the scene (t and state.theta1
  /// set, the rest of the state and RC1, RC3 zero); free scenes: core::simulate_free's trajectory.
  core::Trajectory trajectory(const Eigen::VectorXd& x) const;
  /// Metrics of the design at x as this program evaluates them (regressor or simulation):
  /// core::metrics(trajectory(x)), or +infinity throughout when a free simulation fails.
  core::Metrics metrics(const Eigen::VectorXd& x) const;
  /// The crank angles besides the samples at which a peak the program bounds (of the objective,
  /// weight > 0, or of a limit) has a local maximum over the program's instants (its samples and
  /// problem.peak_angles) at x, within `within` of the original's peak below its largest there
  /// and the added angles next to those (detail::add_local_maxima()): three angles per peak of
  /// a design whose peaks were bounded on grids of added angles. Empty in a free scene.
  std::vector<double> peak_instants(const Eigen::VectorXd& x, double within) const;
  /// The value of one metric at x (added_mass included).
  double metric(const Eigen::VectorXd& x, Metric m) const;
  /// The original design's value of a metric (the normaliser); for added_mass the original
  /// total mass [kg].
  double original(Metric m) const;

 private:
  /// The program, once x has n() entries (else bd::InputError).
  const detail::NlpProgram& at(const Eigen::VectorXd& x) const;

  std::unique_ptr<detail::NlpProgram> program_;  // the driven or the free scene's
};

}  // namespace bd::optimize
