#pragma once
/// Internal to optimize/: the ε-constraint method (Haimes, Lasdon & Wismer 1971) over two metrics,
/// for either linkage type's design problem (pareto_front() in optimize.hpp and planar.hpp).
#include <algorithm>
#include <utility>
#include <vector>

namespace bd::optimize::detail {

/// `Front` says how to pose and solve the problems of one linkage type:
///   using Problem, Metric, Result;
///   Problem minimising(Metric m) const;              // the base problem, objective m alone
///   void limit(Problem& p, Metric m, double bound);  // adds m <= bound (a Limit's units)
///   Result solve(const Problem& p, const std::vector<const Result*>& warm) const;
///                                                    // optimises and verifies, trying the
///                                                    // designs of `warm` (when found) first
///   double value(const Result& r, Metric m) const;   // r's m in a Limit's units
///   bool is_mass(Metric m) const;                    // added_mass: its bound may be <= 0
/// Returns (ε, result) per point: minimise `first` subject to the base constraints and
/// second <= ε, ε spaced from the loosest useful bound down to the tightest reachable one. Each
/// point starts from its neighbour's design (the first point: the loose end's design, which
/// meets its bound and minimises `first` there), brought within its bound towards the design
/// that minimises `second` alone (which meets every bound of the front) by optimize(), given
/// both as starts in Front::solve() (detail::exchange_rounds(): a first start of several is
/// moved towards the first later one that is feasible), else as a lone solve.
template <class Front>
std::vector<std::pair<double, typename Front::Result>> epsilon_front(const Front& f,
                                                                     typename Front::Metric first,
                                                                     typename Front::Metric second,
                                                                     int points) {
  using Result = typename Front::Result;
  // the extremes: each metric minimised alone. The first's minimiser need not be unique (a
  // force-balanced design keeps Fsh = 0 whatever the counterweights' masses, and those change
  // the shaking moment), so the loose end is lexicographic: the second minimised with the first
  // held within 1e-3 of its range above its minimum.
  const Result best_first = f.solve(f.minimising(first), {});
  const Result best_second = f.solve(f.minimising(second), {});
  const double first_lo = f.value(best_first, first);
  const double first_hi = f.value(best_second, first);
  double bound = first_lo + 1e-3 * std::max(0.0, first_hi - first_lo);
  if (!f.is_mass(first)) bound = std::max(bound, 1e-12);  // a limit must be > 0
  auto lexicographic = f.minimising(second);
  f.limit(lexicographic, first, bound);
  const Result loose = f.solve(lexicographic, {&best_first});
  const double a =
      loose.ok() ? f.value(loose, second) : f.value(best_first, second);  // loosest useful bound
  const double b = f.value(best_second, second);  // tightest reachable bound
  const double hi = std::max(a, b), lo = std::min(a, b);

  // ε from hi down to lo; the tightest is kept 1e-3 of the span above lo, so the feasible set
  // at the last point is not a single design the solver must hit exactly
  std::vector<std::pair<double, Result>> front;
  front.reserve(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) {
    const double fraction = static_cast<double>(i) / (points - 1);
    double epsilon = hi - (hi - lo) * fraction * (1.0 - 1e-3);
    if (!f.is_mass(second)) epsilon = std::max(epsilon, 1e-12);  // a limit is > 0
    auto p = f.minimising(first);
    f.limit(p, second, epsilon);
    std::vector<const Result*> warm;
    // the loose end's design, not the second's minimiser, starts the front: from the latter a
    // local method can stay where `first` is no better than the original's (a counterweight of
    // no mass, whose place then has no gradient), and every later point starts from there
    if (!front.empty()) {
      warm.push_back(&front.back().second);
    } else if (loose.ok()) {
      warm.push_back(&loose);
    }
    warm.push_back(&best_second);
    front.emplace_back(epsilon, f.solve(p, warm));
  }
  return front;
}

}  // namespace bd::optimize::detail
