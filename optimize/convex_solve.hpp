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
/// start_scaled(double), start_at(), from_positions(), to_positions(), why_not_convex() and
/// free_scene().
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "core/types.hpp"
#include "optimize/first_order.hpp"
#include "optimize/fixed_variables.hpp"
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

/// Below this fraction of its mass_max a counterweight at a solver's end is taken as vanishing:
/// its mass moment's direction is then round-off (the cone has no gradient at its apex).
inline constexpr double kVanishingCounterweight = 1e-6;

/// The variables (mass and mass moment) of the counterweights whose mass at x is below
/// `fraction` of their mass_max (Program::vanishing_counterweight_variables(), in mass-moment
/// variables); `first` holds each counterweight's first variable, its mass.
template <class Counterweight>
std::vector<int> vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                   const std::vector<int>& first,
                                                   const std::vector<Counterweight>& counterweights,
                                                   double fraction) {
  std::vector<int> out;
  for (std::size_t c = 0; c < first.size(); ++c) {
    const int j = first[c];
    if (x(j) < fraction * counterweights[c].mass_max) out.insert(out.end(), {j, j + 1, j + 2});
  }
  return out;
}

/// The subgradients the first-order check adds at a cone's apex besides the one facing -g: the
/// unit vectors u_k = (cos 2πk/K, sin 2πk/K). Nonnegative combinations of the rows
/// (-1 / mass_max, u_k / (mass_max d)) are the multiples of the cone's subgradients there whose u
/// lies in the regular K-gon inscribed in the unit disc (every u with |u| <= 1 is one), so the
/// multipliers can face whatever the other active rows leave in p: where the objective reads p
/// only through them (a peak's bound variable), -g has no p part to face. The K-gon reaches
/// cos(π/K) = 0.995 of the disc's radius in every direction.
inline constexpr int kApexSubgradients = 32;

/// Row `row` of the inequalities as the first-order check reads a counterweight's cone whose
/// variables are x(j) = m, x(j + 1), x(j + 2) = p: (|p| - m d) / (mass_max d), its gradient
/// (-1 / mass_max, u / (mass_max d)) with u = p / |p|; at the apex the unit vector facing -g,
/// and kApexSubgradients more rows appended to c and jac, each 0 there with one of the apex's
/// subgradients (Program::first_order_inequalities()).
inline void cone_first_order_row(const Eigen::VectorXd& x, const Eigen::VectorXd& g, int j,
                                 double mass_max, double distance_max, Eigen::Index row,
                                 Eigen::VectorXd& c, Eigen::MatrixXd& jac) {
  const double pmax = mass_max * distance_max;
  const Vec2 p(x(j + 1), x(j + 2));
  Vec2 u = p;
  const bool apex = !(u.norm() > 1e-12 * pmax);
  if (apex) u = -Vec2(g(j + 1), g(j + 2));
  if (u.norm() > 0) u.normalize();
  c(row) = (p.norm() - x(j) * distance_max) / pmax;
  jac.row(row).setZero();
  jac(row, j) = -1 / mass_max;
  jac(row, j + 1) = u.x() / pmax;
  jac(row, j + 2) = u.y() / pmax;
  if (!apex) return;
  const Eigen::Index first = c.size();
  c.conservativeResize(first + kApexSubgradients);
  jac.conservativeResize(first + kApexSubgradients, Eigen::NoChange);
  for (int k = 0; k < kApexSubgradients; ++k) {
    const double angle = 2 * std::numbers::pi * k / kApexSubgradients;
    const Eigen::Index r = first + k;
    c(r) = c(row);
    jac.row(r).setZero();
    jac(r, j) = -1 / mass_max;
    jac(r, j + 1) = std::cos(angle) / pmax;
    jac(r, j + 2) = std::sin(angle) / pmax;
  }
}

/// A lower bound of the objective over every feasible design, and how it was found.
struct LowerBound {
  double value = std::numeric_limits<double>::quiet_NaN();  // NaN: none
  std::string words;
};

struct ConvexAwareSolve {
  Solved solved;  // in the position variables
  Optimality optimality;
  LowerBound bound;
};

/// A lower bound from tight_bound(), and the best design its refining runs reached where that is
/// better than the design it started from (`better` empty otherwise).
struct TightBound {
  double value = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd better;
  double objective = std::numeric_limits<double>::quiet_NaN();  // at `better`
  std::string by;  // the refinement that reached it, in words ("slsqp", "ipopt", ...)
};

/// The best Lagrangian bound (first_order()) of a convex program near x. The bound is as tight as
/// the first-order conditions hold, and a solver's usual end, within sqrt(tolerance) of them,
/// leaves it up to ~1e-4 of the objective below the optimum; so it is taken at x, at x without
/// the counterweights below 1e-6 of their mass_max (a vanishing counterweight's mass moment has
/// a direction of round-off, which the conditions cannot meet; on the apex the cone's
/// subgradient can), where that leaves it more than 1e-7 of the objective's size below the best
/// design known, at x taken on by Newton steps on its active set (newton_polish(); where
/// counterweights vanish, after an SLSQP run to 1e-14 with them held on the apex), and where
/// even that leaves it open, at the ends of up to three SLSQP runs on from x to a relative
/// tolerance of 1e-14 (each restart renews its Hessian), and, where these leave it more than 1e-7
/// of the objective's size below f(x), at the end of an Ipopt run to 1e-10 (its interior path
/// reaches an optimum on the cone's apex, where SLSQP's steps turn with the round-off). Each is a
/// bound; the largest is kept. The runs' feasible ends are designs too: the best, where it is below
/// f(x), comes back as `better` (a solver that stalled short of a convex optimum, as MMA can,
/// is taken on to it).
template <class Nlp>
TightBound tight_bound(const Nlp& program, const Eigen::VectorXd& x,
                       const OptimizeOptions& options) {
  TightBound out;
  double& bound = out.value;
  bound = std::max(
      first_order(program, x).lower_bound,
      first_order(program, program.without_vanishing_counterweights(x, kVanishingCounterweight))
          .lower_bound);
  OptimizeOptions tight = options;
  tight.algorithm = Algorithm::kSlsqp;
  tight.relative_tolerance = 1e-14;
  tight.check_gradients = false;
  // a refinement polishes a converged end: near a regular Karush-Kuhn-Tucker point SLSQP and
  // Ipopt converge superlinearly, in tens of iterations; where the conditions cannot be met
  // (a degenerate end: constraints whose gradients are dependent, multipliers without bound)
  // more iterations do not close the gap, and a run to the user's budget cost seconds each
  tight.max_evaluations = refinement_evaluations(program, options.max_evaluations);
  const double f = program.objective(x, nullptr), close = 1e-7 * std::max(std::abs(f), 1.0);
  const auto keep = [&](const Solved& refined, const std::string& by) {
    if (!found_design(refined.termination) ||
        !(refined.constraint_violation <= options.constraint_tolerance)) {
      return;
    }
    const double best = out.better.size() > 0 ? out.objective : f;
    if (refined.objective < best) {
      out.better = refined.x;
      out.objective = refined.objective;
      out.by = by;
    }
  };
  // the gap still open between the bound and the best design known
  const auto open = [&] { return (out.better.size() > 0 ? out.objective : f) - bound > close; };
  if (open()) {
    // Newton steps on the active set's conditions (newton_polish()); first, where counterweights
    // vanish, those held on their cones' apex and the rest solved again (FixedVariables: smooth
    // there). The bound at the end is the whole program's, the apex read by the cone's subgradient
    const std::vector<int> held_at_apex =
        program.vanishing_counterweight_variables(x, kVanishingCounterweight);
    Solved polished;
    polished.termination = Termination::kConverged;
    if (held_at_apex.empty()) {
      polished.x = newton_polish(program, x, options.constraint_tolerance);
    } else {
      const Eigen::VectorXd snapped =
          program.without_vanishing_counterweights(x, kVanishingCounterweight);
      const FixedVariables held(program, held_at_apex, snapped);
      const Solved refined = solve(held, held.reduce(snapped), tight, false);
      polished.termination = refined.termination;
      if (refined.x.size() == held.n()) {
        polished.x = held.expand(newton_polish(held, refined.x, options.constraint_tolerance));
      }
    }
    if (polished.x.size() == x.size()) {
      polished.objective = program.objective(polished.x, nullptr);
      polished.constraint_violation = constraint_violation(program, polished.x);
      keep(polished, held_at_apex.empty()
                           ? "Newton steps on the active set"
                           : "slsqp with the vanishing counterweights held on the apex, then "
                             "Newton steps on the active set");
      bound = std::max(bound, first_order(program, polished.x).lower_bound);
    }
  }
  Eigen::VectorXd at = x;
  for (int run = 0; run < 3 && open(); ++run) {
    const Solved refined = solve(program, at, tight);
    if (refined.x.size() != x.size()) break;
    keep(refined, "slsqp");
    const double next = first_order(program, refined.x).lower_bound;
    const bool gained = next > bound + 1e-12 * std::max(std::abs(bound), 1.0);
    bound = std::max(bound, next);
    at = refined.x;
    if (!gained) break;
  }
  if (open()) {
    tight.algorithm = Algorithm::kIpopt;
    tight.relative_tolerance = 1e-10;
    const Solved refined = solve(program, x, tight);
    if (refined.x.size() == x.size()) {
      keep(refined, "ipopt");
      bound = std::max(bound, first_order(program, refined.x).lower_bound);
    }
  }
  return out;
}

/// The lower bound of a problem that is not convex: the Lagrangian bound (first_order()) of its
/// convex relaxation (CounterweightVariablesAs::kRelaxation) at the relaxation's own solve from
/// its starts and from `best` (the best design found, in position variables), where the
/// relaxation is convex; else none, with the reason.
template <class Nlp, class Problem>
LowerBound relaxation_bound(const Problem& problem, const Eigen::VectorXd& best,
                            const OptimizeOptions& options) {
  LowerBound out;
  const Nlp relaxed(problem, CounterweightVariablesAs::kRelaxation);
  if (const std::string why = relaxed.why_not_convex(); !why.empty()) {
    out.words = "no lower bound: even with the counterweights' inertias relaxed, " + why;
    return out;
  }
  OptimizeOptions local = options;
  if (!uses_gradients(local.algorithm) || local.algorithm == Algorithm::kMlsl) {
    local.algorithm = Algorithm::kSlsqp;
  }
  local.check_gradients = false;
  std::vector<Eigen::VectorXd> starts;
  if (best.size() > 0) starts.push_back(relaxed.start_at(relaxed.from_positions(best)));
  for (double fraction = 1; fraction > 1e-3; fraction /= 4) {
    starts.push_back(relaxed.start_scaled(fraction));
  }
  starts.push_back(relaxed.start(true));
  const Solved solved = solve_from(relaxed, starts, local);
  out.value = tight_bound(relaxed, solved.x, local).value;
  out.words = "from the convex relaxation in which each counterweight's inertia about its pivot "
              "(mass x distance², and a disc's own inertia) may take any value between its "
              "least for the mass and mass moment and its largest within distance_max";
  if (!std::isfinite(out.value)) out.words = "no lower bound: the relaxation's solve gave none";
  return out;
}

/// The optimality and the lower bound of out.solved (a design of `nlp`, position variables):
/// where the program is convex (`convex`, its mass-moment form, not null; `why_not` empty) the
/// first-order conditions and the Lagrangian bound, whose refining runs may return a better
/// design (out.solved then replaced); else the convex relaxation's bound, or why there is none.
template <class Nlp, class Problem>
void certify(const Nlp& nlp, const Problem& problem, const Nlp* convex, const std::string& why_not,
             const OptimizeOptions& options, ConvexAwareSolve& out) {
  Solved& solved = out.solved;
  const bool found = found_design(solved.termination);
  double stationarity = solved.stationarity;
  if (convex && found) {
    // the certificate and the bound from the convex program's first-order conditions at the design
    const Eigen::VectorXd at = convex->from_positions(solved.x);
    const TightBound tight = tight_bound(*convex, at, options);
    out.bound.value = tight.value;
    out.bound.words = "the first-order (Lagrangian) bound of the convex problem at the design";
    stationarity = first_order(*convex, at).residual;
    if (tight.better.size() > 0) {
      // the bound's refining runs went on to a better design of the convex problem: return it
      Eigen::VectorXd x = nlp.start_at(convex->to_positions(tight.better));
      nlp.polish(x);
      const double f = nlp.objective(x, nullptr);
      if (f < solved.objective && constraint_violation(nlp, x) <= options.constraint_tolerance) {
        const double residual = first_order(*convex, convex->from_positions(x)).residual;
        solved.message += "; the lower bound's refinement (" + tight.by +
                          " on the convex problem) went on to a design " +
                          text::digits(solved.objective - f, 2) +
                          " lower in the objective, which is returned";
        solved.x = x;
        solved.objective = f;
        solved.constraint_violation = constraint_violation(nlp, x);
        stationarity = residual;
        if (!(residual > stationarity_tolerance(options.relative_tolerance))) {
          solved.termination = Termination::kConverged;
        }
      }
    }
  } else if (nlp.free_scene()) {
    // no relaxation to try (building one would cost a simulation to say so)
    out.bound.words = "no lower bound: in a free scene the motion itself changes with the "
                      "design, so the forces are not linear in the masses and no convex problem "
                      "bounds the objective from below";
  } else if (!why_not.empty() && nlp.has_gradients()) {
    out.bound = relaxation_bound<Nlp>(problem, found ? solved.x : Eigen::VectorXd(), options);
  } else if (!why_not.empty()) {
    out.bound.words = "no lower bound: " + why_not;
  }
  out.optimality = optimality(why_not, solved.termination == Termination::kConverged,
                              stationarity, options.relative_tolerance);
  // a design within kSameValue of a lower bound is a global optimum to that, convex or not
  const double gap = solved.objective - out.bound.value;
  if (!out.optimality.global && found && !why_not.empty() &&
      gap <= kSameValue * std::max(std::abs(solved.objective), 1.0)) {
    out.optimality = {true, "global to within " + (gap > 0 ? text::digits(gap, 2) : "round-off") +
                                " of the objective: the problem is not convex (" + why_not +
                                "), but no design can go below its convex relaxation's lower "
                                "bound, which the design's objective meets to that"};
  }
}

/// Solves `nlp` (position variables) from `designs` (its variables: results' x), then its
/// natural start with each counterweight's mass scaled by 1, 1/4, ..., 1/256 (the first that
/// fits an added-mass budget), then the original design (no counterweight: feasible for any
/// budget >= 0). `problem` is nlp's; where nlp.why_not_convex() is empty the same problem is
/// also set up in mass-moment variables (Nlp(problem, CounterweightVariablesAs::kMassMoments)).
/// With `with_certificate` the end is certify()'d; without, its optimality and bound are left
/// unassessed (a round whose design is only a step towards the result: certified() later).
template <class Nlp, class Problem>
ConvexAwareSolve solve_convex_aware(const Nlp& nlp, const Problem& problem,
                                    const std::vector<Eigen::VectorXd>& designs,
                                    const OptimizeOptions& options, bool with_certificate = true) {
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
  if (with_certificate) certify(nlp, problem, convex ? &*convex : nullptr, why_not, options, out);
  return out;
}

/// `solved`, a design of `nlp` from solve_convex_aware() without its certificate, certify()'d.
template <class Nlp, class Problem>
ConvexAwareSolve certified(const Nlp& nlp, const Problem& problem, Solved solved,
                           const OptimizeOptions& options) {
  ConvexAwareSolve out;
  out.solved = std::move(solved);
  const std::string why_not = nlp.why_not_convex();
  std::optional<Nlp> convex;
  if (why_not.empty()) convex.emplace(problem, CounterweightVariablesAs::kMassMoments);
  certify(nlp, problem, convex ? &*convex : nullptr, why_not, options, out);
  return out;
}

}  // namespace bd::optimize::detail
