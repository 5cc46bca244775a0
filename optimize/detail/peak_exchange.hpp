#pragma once
/// Internal to optimize/: the exchange step shared by the four-bar's and the planar linkage's
/// optimisers (DesignProblem::resolve_peaks): where a resolved peak of an optimum rises above
/// the peak the program bounded over its instants (samples and instants added so far), the next
/// round adds instants around it and solves again.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "optimize/convex_solve.hpp"
#include "optimize/detail/local_maxima.hpp"
#include "optimize/optimize.hpp"

namespace bd::optimize::detail {

/// At most this many exchange rounds (each a solve more); they end sooner as a rule, once the
/// optimum's resolved peaks are bounded (three or four rounds).
inline constexpr int kMaxExchangeRounds = 8;
/// A resolved peak above the peak over the program's instants by more than this fraction of the
/// original's peak (the objective's and the limits' unit) adds instants (the resolved peaks are
/// good to about 1e-14 of themselves).
inline constexpr double kPeakExchangeTolerance = 1e-9;
/// At most this many instants added around one peak in one round.
inline constexpr int kMaxInstantsPerPeak = 64;

/// Appends to `added` the instants (crank angles, or times) a next round bounds a peak at: its
/// own instant `at` and an even grid over the interval of `instants` (sorted: the program's
/// samples, the motion's end and the instants added so far) around it. Near a smooth peak the
/// excess goes with the square of the interval, so m intervals take it down m² times: m is
/// chosen for `excess` (the resolved peak minus the bounded one, over the original's) to fall to a
/// tenth of the tolerance, at most kMaxInstantsPerPeak, so that the next optimum, whose peak moves
/// a little, finds instants close around it. No grid when `at` lies outside the instants.
inline void add_peak_instants(const std::vector<double>& instants, double at, double excess,
                              std::vector<double>& added) {
  added.push_back(at);
  const auto right = std::upper_bound(instants.begin(), instants.end(), at);
  if (right == instants.begin() || right == instants.end()) return;
  const double a = *(right - 1), b = *right;
  const int intervals = static_cast<int>(std::min<double>(
      kMaxInstantsPerPeak, std::ceil(std::sqrt(10 * excess / kPeakExchangeTolerance))));
  for (int j = 1; j < intervals; ++j) {
    added.push_back(a + (b - a) * static_cast<double>(j) / static_cast<double>(intervals));
  }
}

/// Within this fraction of the original's peak below a design's largest peak, a local maximum
/// over the dense instants is kept in the lean program (exchange_rounds()); the rows of lower
/// ones are not active at that design.
inline constexpr double kLeanPeakWithin = 1e-4;

/// At most this many solves of the lean program (exchange_rounds()).
inline constexpr int kMaxLeanRounds = 3;

/// What the exchange rounds spent, over all of them, and what the last left undone.
struct ExchangeTotals {
  int iterations{}, evaluations{};
  double seconds{};
  /// "" when every resolved peak is bounded (or none was asked for); else what to append to the
  /// solver's message: the budget or the rounds ran out first, and where the peaks are bounded.
  std::string shortfall;

  void add(const Solved& s) {
    iterations += s.iterations;
    evaluations += s.evaluations;
    seconds += s.seconds;
  }
};

/// The fields either type's result (OptimizeResult, planar::Result) takes from the last
/// round's solve: optimality, lower bound, multistart counts, algorithm, termination, message,
/// the costs over the rounds, and the design variables x (snapped_to_bounds(): a counterweight
/// left at round-off of nothing is none; without_needless_counterweights(): nor is one that
/// changes nothing) with their objective and constraint violation.
template <class Result, class Program>
void set_solve_fields(Result& r, const Program& program, const ConvexAwareSolve& solve,
                      const OptimizeOptions& options, const ExchangeTotals& totals) {
  const Solved& s = solve.solved;
  r.global = solve.optimality.global && found_design(s.termination);
  r.optimality = solve.optimality.words;
  r.lower_bound = solve.bound.value;
  r.lower_bound_source = solve.bound.words;
  r.starts = s.starts;
  r.starts_at_best = s.starts_at_best;
  r.algorithm = options.algorithm;
  r.termination = s.termination;
  r.message = s.message;
  r.x = snapped_to_bounds(program, options, s.x, s.objective, s.constraint_violation);
  if (options.leave_out_needless_counterweights && found_design(s.termination)) {
    std::string left_out;
    r.x = without_needless_counterweights(program, options, r.x, s.objective,
                                          s.constraint_violation, &left_out);
    r.message += left_out;
  }
  const bool snapped = r.x != s.x;
  r.objective = snapped ? program.objective(r.x, nullptr) : s.objective;
  r.constraint_violation = snapped ? constraint_violation(program, r.x) : s.constraint_violation;
  r.iterations = totals.iterations;
  r.evaluations = totals.evaluations;
  r.seconds = totals.seconds;
}

/// The exchange rounds of either linkage type's optimiser: solve `problem` (its Nlp, by
/// solve_convex_aware() from `starts`); where short_peaks(problem, nlp, solved) names instants
/// at which a resolved peak rises above its bound, add them to problem.*instants and solve again
/// from that optimum, at most kMaxExchangeRounds more times, the rounds sharing
/// options.max_evaluations. Returns finish(nlp, problem, solve, totals) of the last round (the
/// Nlp lives only as long as the call). on_first(nlp) runs once, after the first Nlp is built
/// (its checks come first). `what` names the instants in the shortfall ("crank angles").
///
/// The last round's program holds grids of instants around each peak, whose rows are nearly
/// equal constraints: at a design whose peaks are equal (a minimax optimum) the first-order
/// conditions are then degenerate, met only to ~1e-2 and slow to bound. So the rounds are solved
/// without their certificate, and once the peaks are bounded the result is the lean program's:
/// the samples and three instants per peak of that design (nlp.peak_instants(): the local
/// maxima over the grids within kLeanPeakWithin and their neighbours), solved from it and
/// certified, where its own resolved peaks are bounded too (up to kMaxLeanRounds, each adding
/// the instants of the last lean optimum's peaks; else the last round's design, certified). The
/// lean program is a relaxation of the motion's (fewer instants), so its lower bound holds for
/// the motion's peaks as well.
/// A round starts from the last one's optimum moved towards a start that meets the rows just
/// added, just far enough to meet them too (feasible_towards()): a peak limit's rows at the
/// added instants are what the last optimum missed.
template <class Nlp, class Problem, class ShortPeaks, class OnFirst, class Finish>
auto exchange_rounds(const Problem& problem, std::vector<Eigen::VectorXd> starts,
                     const OptimizeOptions& options, std::vector<double> Problem::*instants,
                     const char* what, const ShortPeaks& short_peaks, const OnFirst& on_first,
                     const Finish& finish) {
  Problem exchanged = problem;
  ExchangeTotals totals;
  // the evaluations left; one at least (NLopt takes none as no limit)
  const auto budget = [&] {
    OptimizeOptions b = options;
    b.max_evaluations = std::max(1, options.max_evaluations - totals.evaluations);
    return b;
  };
  // enough left for another solve (mlsl: one evaluation per local run at least)
  const auto can_solve = [&] {
    return options.max_evaluations - totals.evaluations >=
           (options.algorithm == Algorithm::kMlsl ? options.starts : 1);
  };
  for (int round = 0;; ++round) {
    const Nlp nlp(exchanged);
    if (round == 0) on_first(nlp);
    if (round > 0 || starts.size() >= 2) {
      // the last optimum may miss the rows of the instants just added (a peak limit's, its peak
      // rising above the bound between the samples), and a first start of several (a Pareto
      // front's neighbour) its own problem's bound: without a feasible start nearby a local
      // method starts at the first feasible one and may stay there (a Pareto front's inner
      // points ended at the second metric's minimiser); so it moves towards the first later
      // start, or the original design, that meets them, just far enough to meet them too
      std::vector<Eigen::VectorXd> towards(starts.begin() + 1, starts.end());
      towards.push_back(nlp.start(true));
      for (const Eigen::VectorXd& to : towards) {
        if (constraint_violation(nlp, nlp.start_at(to)) <= options.constraint_tolerance) {
          starts.front() = feasible_towards(nlp, starts.front(), to, options.constraint_tolerance);
          break;
        }
      }
    }
    // no certificate for a round (without resolve_peaks, or in a free scene, whose peaks are
    // its samples', the only round is the last)
    const bool exchanging = problem.resolve_peaks && !nlp.free_scene();
    const ConvexAwareSolve solve =
        solve_convex_aware(nlp, exchanged, starts, budget(), !exchanging);
    const Solved& solved = solve.solved;
    totals.add(solved);
    if (!exchanging) return finish(nlp, exchanged, solve, totals);
    const std::vector<double> wanted = short_peaks(exchanged, nlp, solved);
    // each instant once: two peaks in one interval ask for the same grid
    std::vector<double>& bounded_at = exchanged.*instants;
    std::vector<double> added;
    for (const double a : wanted) {
      if (std::find(bounded_at.begin(), bounded_at.end(), a) == bounded_at.end() &&
          std::find(added.begin(), added.end(), a) == added.end()) {
        added.push_back(a);
      }
    }
    const bool another = round < kMaxExchangeRounds && can_solve();
    if (!added.empty() && another) {
      bounded_at.insert(bounded_at.end(), added.begin(), added.end());
      starts.insert(starts.begin(), solved.x);
      continue;
    }
    if (!wanted.empty() && added.empty()) {
      totals.shortfall =
          "; a resolved peak still rose above its bound, at instants already bounded";
    } else if (!added.empty()) {  // a peak still rises above its bound by more than the tolerance
      const std::string where = bounded_at.empty() ? "the samples only"
                                                   : "the samples and " +
                                                         std::to_string(bounded_at.size()) +
                                                         " more " + what;
      totals.shortfall = (round < kMaxExchangeRounds
                              ? "; the evaluation budget was spent before every resolved peak "
                                "was bounded (the peaks are bounded at "
                              : "; after " + std::to_string(kMaxExchangeRounds + 1) +
                                    " solves a resolved peak still rose above its bound (the "
                                    "peaks are bounded at ") +
                         where + ")";
    } else if (found_design(solved.termination) && bounded_at.size() > (problem.*instants).size()) {
      // bounded: the lean program, from this design, where it bounds its own peaks too; the
      // lean optimum's peaks move a little off its instants, so a lean round adds theirs (the
      // grid's local maxima at that design) and solves again
      Problem lean = problem;
      std::vector<double>& lean_at = lean.*instants;
      Eigen::VectorXd from = solved.x;
      for (int lean_round = 0; lean_round < kMaxLeanRounds && can_solve(); ++lean_round) {
        const std::size_t before = lean_at.size();
        for (const double a : nlp.peak_instants(from, kLeanPeakWithin)) {
          if (std::find(lean_at.begin(), lean_at.end(), a) == lean_at.end()) lean_at.push_back(a);
        }
        if (lean_round > 0 && lean_at.size() == before) break;  // nothing new to bound
        const Nlp lean_nlp(lean);
        const ConvexAwareSolve lean_solve =
            solve_convex_aware(lean_nlp, lean, {solved.x}, budget(), true);
        totals.add(lean_solve.solved);
        if (!found_design(lean_solve.solved.termination)) break;
        if (short_peaks(lean, lean_nlp, lean_solve.solved).empty()) {
          return finish(lean_nlp, lean, lean_solve, totals);
        }
        from = lean_solve.solved.x;
      }
    }
    // (the certificate's refining runs check a design and are not the solve's: the budget of
    // a single solve, as the first round's certificate would have had)
    return finish(nlp, exchanged, certified(nlp, exchanged, solved, options), totals);
  }
}

}  // namespace bd::optimize::detail
