#pragma once
/// Internal to bd_optimize: whether a point a solver returned satisfies the first-order
/// (Karush-Kuhn-Tucker) conditions of a Program, checked from the program's own derivatives
/// rather than taken from the solver's word.
///
/// At a feasible x, with each variable measured in units of its box width w_j = upper - lower
/// (1 where a bound is infinite), the active set is every equality, every inequality with
/// c_i >= -activity and every bound within activity · w_j of x. The multipliers
///   min || w ∘ (∇f + Σ λ_i ∇c_i + Σ ν_k ∇h_k - μ_lower + μ_upper) ||,  λ, μ >= 0
/// are fitted by least squares (bounded_least_squares() where some come out of the wrong sign),
/// and the residual's largest entry, divided by the largest of |f|, the scaled gradient's
/// largest entry and 1 (the objectives are normalised: 1 per unit weight at the original
/// design), is the stationarity residual: the objective's relative rate of
/// decrease, per whole box width, along the best direction that the active constraints allow to
/// first order. It is 0 at a Karush-Kuhn-Tucker point and of order one far from one.
///
/// Its tolerance is sqrt(relative tolerance) (1e-4 for the default 1e-8): a solver that stops
/// when the objective changes by less than δ relative is within δ of a minimum of curvature H
/// where the gradient is about sqrt(2 H δ), so that is what a converged end can show.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "optimize/program.hpp"

namespace bd::optimize::detail {

/// The default activity threshold (scaled constraints and box-width units).
inline constexpr double kActivity = 1e-6;

/// The tolerance of the stationarity residual for a solver's relative tolerance.
inline double stationarity_tolerance(double relative_tolerance) {
  return std::sqrt(relative_tolerance);
}

/// The evaluations a run by SLSQP or Ipopt that goes on from a converged end may take (a
/// continuation where the first-order conditions do not hold there, a lower bound's
/// refinement): 20 per variable and 20 more, within the budget left (`max_evaluations`). Near a
/// regular Karush-Kuhn-Tucker point these converge superlinearly, in tens of iterations; at a
/// degenerate end (constraints whose gradients are dependent, multipliers without bound, as at
/// the tightest point of a Pareto front) more iterations do not help, and a run to a budget of
/// thousands cost tens of seconds where hundreds of constraints are active.
inline int refinement_evaluations(const Program& program, int max_evaluations) {
  return std::min(max_evaluations, 20 * (program.n() + 1));
}

/// The stationarity residual at x (see above), for a program with gradients.
double stationarity_residual(const Program& program, const Eigen::VectorXd& x,
                             double activity = kActivity);

/// The first-order conditions at x: the stationarity residual, and the Lagrangian bound
///   L(x) - Σ_j |w_j ∂L/∂x_j(x)|,   L = f + Σ λ_i c_i + Σ μ (bound rows)
/// with the fitted multipliers (λ >= 0 on inequalities and bounds). Where the program is convex
/// (f and every inequality convex, the equalities linear) no feasible point of the box has a
/// smaller objective: L <= f there, and L lies above its tangent at x, which cannot fall by more
/// than that sum across the box (less 1e-12 of its size for round-off). It holds at any x, feasible or not, and tends to f(x) as x
/// tends to a Karush-Kuhn-Tucker point; -infinity where a variable's box is unbounded.
struct FirstOrder {
  double residual{};
  double lower_bound{};
};
FirstOrder first_order(const Program& program, const Eigen::VectorXd& x,
                       double activity = kActivity);

/// Whether a solved program's design is a proven global optimum, and why (or why that is not
/// proven) in words for the result and summary.json.
struct Optimality {
  bool global = false;
  std::string words;
};
/// Global when the program is convex (`why_not_convex` empty, as Nlp::why_not_convex() says) and
/// the solver converged to a design whose stationarity residual is within the tolerance: a
/// first-order point of a convex program is a global minimum. `converged` and `stationarity`
/// are the solver's end (Solved).
Optimality optimality(const std::string& why_not_convex, bool converged, double stationarity,
                      double relative_tolerance);

/// x taken closer to a Karush-Kuhn-Tucker point by Newton steps on the conditions of its active
/// set (the equalities, the inequalities within `activity` of 0, held as equalities; the
/// variables at a bound held there): each step solves the linearised conditions
///   [H  Aᵀ] [dx]     [∇f + Aᵀ z]
///   [A  0 ] [dz] = - [c_A      ]
/// with H the Hessian of the Lagrangian by central differences of its exact gradient (the
/// multipliers z by least squares at each point); of the points reached, the one of least
/// stationarity residual among those within `constraint_tolerance` of feasible is returned.
/// For a certificate, not a search: where a solver's own end meets the conditions to ~1e-6
/// only (NLopt's SLSQP stops when its steps stop changing the objective, which near a minimum
/// of a flat direction happens first), a few such steps take them to round-off, as an
/// interior-point method's last iterations would, without its cost. (A polish of this kind is the
/// last step of OSQP's solves.) At most `steps` steps; x itself when none helped.
Eigen::VectorXd newton_polish(const Program& program, const Eigen::VectorXd& x,
                              double constraint_tolerance, int steps = 4,
                              double activity = kActivity);

/// min ½ |A z - b|² subject to z_i >= lower_i (lower_i may be -infinity: free), by the active-set
/// method of Lawson and Hanson (Solving Least Squares Problems, 1974, ch. 23), the free
/// variables held in its passive set throughout. Its cost grows with the number of columns it
/// takes in, at most about the rank of A: a peak's hundreds of active rows at a balanced design
/// (columns nearly parallel, n = a handful of variables) cost a few small solves, where a
/// general solver on the quadratic in all columns costs seconds and may stop short. Exact to
/// round-off: Aᵀ(A z - b) vanishes on the free and the inactive components and is >= 0 (to
/// round-off) on those at their bound.
Eigen::VectorXd bounded_least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                      const Eigen::VectorXd& lower);

}  // namespace bd::optimize::detail
