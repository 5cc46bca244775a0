// pareto_front: the ε-constraint method (Haimes, Lasdon & Wismer 1971) over two metrics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "optimize/check_inputs.hpp"
#include "optimize/epsilon_front.hpp"
#include "optimize/nlopt_driver.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize {

namespace {

// the four-bar's problems for the ε-constraint method (epsilon_front.hpp)
struct FourBarFront {
  using Problem = DesignProblem;
  using Metric = optimize::Metric;
  using Result = OptimizeResult;
  const DesignProblem& problem;
  const OptimizeOptions& options;
  const Nlp& nlp;  // the original's metrics: the normalisers of the bounds
  Problem minimising(Metric m) const {
    DesignProblem p = problem;
    p.objective = {Term{m, 1.0}};
    return p;
  }
  static void limit(Problem& p, Metric m, double bound) { p.limits.push_back(Limit{m, bound}); }
  Result solve(const Problem& p, const std::vector<const Result*>& warm) const {
    std::vector<Eigen::VectorXd> designs;
    for (const Result* r : warm)
      if (r->ok()) designs.push_back(r->x);
    // the neighbour's design first: optimize() brings it within this point's bound towards the
    // last (the second metric's minimiser), and the solve goes on along the front from there
    return optimize(p, options, designs);
  }
  // the value of `m` at a result, in the units of a Limit on it: the fraction of the original's
  // value, or kg for added_mass
  double value(const Result& r, Metric m) const {
    if (m == Metric::kAddedMass) {
      return core::total_mass(r.design) - core::total_mass(problem.original);
    }
    return optimize::value(r.metrics, m) / nlp.original(m);
  }
  static bool is_mass(Metric m) { return m == Metric::kAddedMass; }
};

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
  // each point starts from its neighbour's design: its counterweights stay (OptimizeOptions)
  OptimizeOptions along = options;
  along.leave_out_needless_counterweights = false;
  std::vector<ParetoPoint> front;
  for (auto& [epsilon, result] :
       detail::epsilon_front(FourBarFront{problem, along, nlp}, first, second, points)) {
    front.push_back(ParetoPoint{epsilon, std::move(result)});
  }
  return front;
}

}  // namespace bd::optimize
