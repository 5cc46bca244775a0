// pareto_front: the ε-constraint method (Haimes, Lasdon & Wismer 1971) over two metrics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "optimize/check_inputs.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize {

namespace {

// the value of `m` at a result, in the units of a Limit on it: the fraction of the original's
// value, or kg for added_mass
double limit_value(const OptimizeResult& r, const DesignProblem& problem, const Nlp& nlp,
                   Metric m) {
  if (m == Metric::kAddedMass) {
    return core::total_mass(r.design) - core::total_mass(problem.original);
  }
  return value(r.metrics, m) / nlp.original(m);
}

DesignProblem minimising(const DesignProblem& problem, Metric m) {
  DesignProblem p = problem;
  p.objective = {Term{m, 1.0}};
  return p;
}

}  // namespace

std::vector<ParetoPoint> pareto_front(const DesignProblem& problem, Metric first, Metric second,
                                      int points, const OptimizeOptions& options) {
  if (points < 2) {
    throw InputError("pareto_front: points must be >= 2, got " + std::to_string(points));
  }
  if (first == second) {
    throw InputError(std::string("pareto_front: the two metrics must differ, got ") +
                     to_string(first) + " twice");
  }
  detail::check_inputs(problem, options);
  const Nlp nlp(problem);  // the original's metrics: the normalisers of the bounds
  if (second != Metric::kAddedMass && !(nlp.original(second) > 0)) {
    throw InputError(std::string("pareto_front: ") + to_string(second) +
                     " of the original design is " + text::digits(nlp.original(second), 6) +
                     ", so no bound relative to it can be set");
  }

  // the extremes: each metric minimised alone. The first's minimiser need not be unique (a
  // force-balanced design keeps Fsh = 0 whatever the counterweights' masses, and those change
  // the shaking moment), so the loose end is lexicographic: the second minimised with the first
  // held within 1e-3 of its range above its minimum.
  const OptimizeResult best_first = optimize(minimising(problem, first), options);
  const OptimizeResult best_second = optimize(minimising(problem, second), options);
  const double first_lo = limit_value(best_first, problem, nlp, first);
  const double first_hi = limit_value(best_second, problem, nlp, first);
  double bound = first_lo + 1e-3 * std::max(0.0, first_hi - first_lo);
  if (first != Metric::kAddedMass) bound = std::max(bound, 1e-12);  // a limit must be > 0
  DesignProblem lexicographic = minimising(problem, second);
  lexicographic.limits.push_back(Limit{first, bound});
  const OptimizeResult loose = optimize(lexicographic, options);
  const double a = loose.ok()
                       ? limit_value(loose, problem, nlp, second)
                       : limit_value(best_first, problem, nlp, second);  // loosest useful bound
  const double b = limit_value(best_second, problem, nlp, second);       // tightest reachable bound
  const double hi = std::max(a, b), lo = std::min(a, b);

  // ε from hi down to lo; the tightest is kept 1e-3 of the span above lo, so the feasible set
  // at the last point is not a single design the solver must hit exactly
  std::vector<ParetoPoint> front;
  front.reserve(static_cast<size_t>(points));
  for (int i = 0; i < points; ++i) {
    const double fraction = static_cast<double>(i) / (points - 1);
    double epsilon = hi - (hi - lo) * fraction * (1.0 - 1e-3);
    if (second != Metric::kAddedMass) epsilon = std::max(epsilon, 1e-12);  // a limit is > 0
    DesignProblem p = minimising(problem, first);
    p.limits.push_back(Limit{second, epsilon});
    front.push_back(ParetoPoint{epsilon, optimize(p, options)});
  }
  return front;
}

}  // namespace bd::optimize
