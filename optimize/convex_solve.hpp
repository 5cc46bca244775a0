#pragma once
/// Internal to bd_optimize: the solve both linkage types' optimize() share. A problem convex in
/// the counterweights' masses and mass moments (the program's why_not_convex() is empty) is
/// solved in those variables (CounterweightVariablesAs::kMassMoments) by the local gradient
/// methods, where a first-order point is the global optimum, and its design taken back to the
/// position variables, the ones the results and the rest of the tool read; MLSL and the
/// derivative-free methods, whose steps are scaled for the positions, keep them. Either way the
/// first-order conditions of the convex program are checked at the design found: the
/// certificate of a global optimum (detail::optimality()).
///
/// `Nlp` is a linkage type's program (Nlp, planar::PlanarNlp) with start(bool),
/// start_scaled(double), start_at(), from_positions(), to_positions() and why_not_convex().
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "optimize/first_order.hpp"
#include "optimize/nlopt_driver.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize::detail {

/// A counterweight's centre from its mass and mass moment p about the pivot: p / m within
/// distance_max (the smoothed cone's slack removed), the pivot itself without mass.
inline Vec2 position_of(double mass, const Vec2& moment, double distance_max) {
  if (!(mass > 0)) return Vec2::Zero();
  Vec2 r = moment / mass;
  const double d = r.norm();
  if (d > distance_max) r *= distance_max / d;
  return r;
}

/// Row `row` of the inequalities as the first-order check reads a counterweight's cone whose
/// variables are x(j) = m, x(j + 1), x(j + 2) = p: (|p| - m d) / (mass_max d), its gradient
/// (-1 / mass_max, u / (mass_max d)) with u = p / |p|, or at the apex the unit vector facing -g
/// (Program::first_order_inequalities()).
inline void cone_first_order_row(const Eigen::VectorXd& x, const Eigen::VectorXd& g, int j,
                                 double mass_max, double distance_max, Eigen::Index row,
                                 Eigen::VectorXd& c, Eigen::MatrixXd& jac) {
  const double pmax = mass_max * distance_max;
  const Vec2 p(x(j + 1), x(j + 2));
  Vec2 u = p;
  if (!(u.norm() > 1e-12 * pmax)) u = -Vec2(g(j + 1), g(j + 2));
  if (u.norm() > 0) u.normalize();
  c(row) = (p.norm() - x(j) * distance_max) / pmax;
  jac.row(row).setZero();
  jac(row, j) = -1 / mass_max;
  jac(row, j + 1) = u.x() / pmax;
  jac(row, j + 2) = u.y() / pmax;
}

struct ConvexAwareSolve {
  Solved solved;  // in the position variables
  Optimality optimality;
};

/// Solves `nlp` (position variables) from `designs` (its variables: results' x), then its
/// natural start with each counterweight's mass scaled by 1, 1/4, ..., 1/256 (the first that
/// fits an added-mass budget), then the original design (no counterweight: feasible for any
/// budget >= 0). `problem` is nlp's; where nlp.why_not_convex() is empty the same problem is
/// also set up in mass-moment variables (Nlp(problem, CounterweightVariablesAs::kMassMoments)).
template <class Nlp, class Problem>
ConvexAwareSolve solve_convex_aware(const Nlp& nlp, const Problem& problem,
                                    const std::vector<Eigen::VectorXd>& designs,
                                    const OptimizeOptions& options) {
  const std::string why_not = nlp.why_not_convex();
  std::optional<Nlp> convex;
  if (why_not.empty()) convex.emplace(problem, CounterweightVariablesAs::kMassMoments);
  const bool in_moments =
      convex && uses_gradients(options.algorithm) && options.algorithm != Algorithm::kMlsl;
  const Nlp& program = in_moments ? *convex : nlp;
  std::vector<Eigen::VectorXd> starts;
  for (const Eigen::VectorXd& d : designs) starts.push_back(program.from_positions(d));
  for (double fraction = 1; fraction > 1e-3; fraction /= 4) {
    starts.push_back(program.start_scaled(fraction));
  }
  starts.push_back(program.start(true));
  ConvexAwareSolve out;
  Solved& solved = out.solved;
  solved = solve_from(program, starts, options);
  if (in_moments) {
    // the design in positions, its bound variables tight, and its feasibility there (what a
    // message says is the returned design's: an infeasible end's mass moments may lie outside
    // the cone, and in positions they are brought onto it)
    solved.x = nlp.start_at(convex->to_positions(solved.x));
    nlp.polish(solved.x);
    solved.objective = nlp.objective(solved.x, nullptr);
    std::string solver = solved.message;
    if (const auto open = solver.rfind(" ["); open != std::string::npos && solver.back() == ']' &&
                                              solver.starts_with("no feasible design found")) {
      solver = solver.substr(open + 2, solver.size() - open - 3);
    }
    check_feasibility(nlp, options, solver, solved);
  }
  const bool found = found_design(solved.termination);
  out.optimality = optimality(
      why_not, solved.termination == Termination::kConverged,
      convex && found ? stationarity_residual(*convex, convex->from_positions(solved.x))
                      : solved.stationarity,
      options.relative_tolerance);
  return out;
}

}  // namespace bd::optimize::detail
