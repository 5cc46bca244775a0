#pragma once
/// A smooth nonlinear program as the solver drivers see it:
///   minimise f(x)  subject to  c_eq(x) = 0,  c_in(x) <= 0,  lower <= x <= upper.
/// The drivers (NLopt, Ipopt), the gradient check and the feasibility check work on this and
/// nothing else, so any linkage type's design problem is solved by the same code: the
/// four-bar's Nlp (optimize/nlp.hpp) and the general planar linkage's PlanarNlp
/// (optimize/planar.hpp) implement it. Constraints are scaled to be of order one.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace bd::optimize {

/// How a counterweight enters as variables.
enum class CounterweightVariablesAs {
  /// Its mass m and its centre r = (x, y) from the pivot: [kg], [m], [m] (the default; the
  /// envelope (x² + y²)/distance_max² - 1 <= 0).
  kPositions,
  /// Its mass m and its mass moment p = m r about the pivot: [kg], [kg m], [kg m], each moment in
  /// [-mass_max distance_max, mass_max distance_max]. The links' masses and first moments are
  /// then affine in the variables, and the envelope is the convex cone |p| <= m distance_max,
  /// smoothed where it meets its apex (m = 0, p = 0) as
  ///   (sqrt(|p|² + δ²) - δ) / (mass_max distance_max) - m / mass_max <= 0,  δ = kConeSmoothing
  /// (relative to mass_max distance_max): the same cone up to δ, never tighter, with a gradient
  /// everywhere (the plain |p|² <= m² distance_max² has none at the apex, where "no
  /// counterweight" lies). The design at x takes r = p / m, within distance_max (the δ of slack
  /// removed), and r = 0 where m = 0. Used for the problems that are convex in these variables
  /// (Nlp::why_not_convex(), planar::PlanarNlp::why_not_convex()).
  kMassMoments,
  /// As kMassMoments, and each counterweight's inertia about its pivot (m |r|², and a disc's own
  /// inertia) a variable of its own within a convex set that holds every real counterweight
  /// (optimize/relaxation.hpp): the convex relaxation of a problem whose metrics read those
  /// inertias (the shaking moment, the drive torque). Its minimum is a lower bound of the real
  /// problem's; its designs are not real ones (solve_convex_aware() reports the bound only).
  kRelaxation,
};
/// δ of the smoothed cone, relative to mass_max distance_max: the design's mass moment moves by
/// at most δ when its position is brought within distance_max, so the objective by ~1e-10.
inline constexpr double kConeSmoothing = 1e-10;

class Program {
 public:
  virtual ~Program() = default;

  virtual int n() const = 0;       // variables
  virtual int n_eq() const = 0;    // equality constraints
  virtual int n_ineq() const = 0;  // inequality constraints (c <= 0)
  virtual const Eigen::VectorXd& lower() const = 0;
  virtual const Eigen::VectorXd& upper() const = 0;
  /// Names of the variables and of the constraints (equalities first), for messages.
  virtual const std::vector<std::string>& variable_names() const = 0;
  virtual const std::vector<std::string>& constraint_names() const = 0;
  /// True when exact gradients are available; asking for one otherwise throws
  /// std::logic_error.
  virtual bool has_gradients() const = 0;
  /// The objective and, when `grad` is not null, its gradient.
  virtual double objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const = 0;
  /// c_eq(x) (size n_eq) and, when `jac` is not null, its Jacobian (n_eq x n).
  virtual void equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                          Eigen::MatrixXd* jac) const = 0;
  /// c_in(x) (size n_ineq) and, when `jac` is not null, its Jacobian (n_ineq x n).
  virtual void inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                            Eigen::MatrixXd* jac) const = 0;
  /// The inequalities as the first-order check (optimize/first_order.hpp) reads them, given the
  /// objective's gradient g at x: by default inequalities(x, c, jac). A program whose
  /// constraint function loses its gradient where the set it bounds has a corner (a cone
  /// |p|² <= m² d² at its apex) gives there the rows of an equivalent convex function
  /// (|p| - m d), with the subgradient that faces -g, so that the check sees the constraint;
  /// at the apex, where the subgradients form a disc, it may append rows after the n_ineq()
  /// ones, each 0 with another subgradient (cone_first_order_row(), convex_solve.hpp).
  virtual void first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& /*g*/,
                                        Eigen::VectorXd& c, Eigen::MatrixXd& jac) const {
    inequalities(x, c, &jac);
  }
  /// Sets the variables that only bound others (a peak's bound variable t >= |y_s|) to their
  /// tightest feasible values at x, in place: a solver may return them a little loose (the
  /// objective then overstates), a little tight (their rows then look violated although the
  /// design is not), or, stopped where nothing is feasible, below the peak. The design's own
  /// variables are not touched. Default: nothing to do.
  virtual void polish(Eigen::VectorXd& /*x*/) const {}
  /// Constraint i (equalities first) at x in an engineer's words and units, e.g. "Fsh_rms is
  /// 0.31 x the original's, at most 0.0001 x"; empty when the program has no such words (a
  /// message then gives the scaled value).
  virtual std::string constraint_text(int /*i*/, const Eigen::VectorXd& /*x*/) const { return {}; }
  /// In mass-moment variables (kMassMoments, kRelaxation), the variables (mass and mass moment,
  /// three each) of the counterweights whose mass at x is below `fraction` of their mass_max: a
  /// solver's end near a cone's apex, where the direction of a vanishing mass moment is
  /// round-off. None in position variables, which have no apex (a counterweight without mass
  /// has a position that changes nothing: holding it anywhere would make a false stationary
  /// point). Default: none.
  virtual std::vector<int> vanishing_counterweight_variables(const Eigen::VectorXd& /*x*/,
                                                             double /*fraction*/) const {
    return {};
  }
  /// The first variable of each counterweight, its mass (the next two are its position or its
  /// mass moment), in the problem's order. Default: none.
  virtual std::vector<int> counterweight_mass_variables() const { return {}; }
  /// In position variables, each counterweight's distance_max [m], in the order of
  /// counterweight_mass_variables(); empty in mass-moment variables. Default: empty.
  virtual std::vector<double> counterweight_reach() const { return {}; }
  /// x with those counterweights taken away (their variables 0, the variables that only bound
  /// them set for it): put on the cone's apex itself. Default, and in position variables: x.
  virtual Eigen::VectorXd without_vanishing_counterweights(const Eigen::VectorXd& x,
                                                           double /*fraction*/) const {
    return x;
  }
  /// x with each counterweight brought within its envelope (in mass-moment variables
  /// |p| <= m distance_max: a solver's end may hold a little more, within the constraint
  /// tolerance, which a vanishing mass makes a distance far beyond distance_max) and the
  /// variables that only bound others set for it (each a hair above what it bounds). Default,
  /// and in position variables: x.
  virtual Eigen::VectorXd within_envelopes(const Eigen::VectorXd& x) const { return x; }
};

}  // namespace bd::optimize
