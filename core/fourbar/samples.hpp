#pragma once
/// Shared test and example mechanisms (one source for tests, benchmarks and examples).
#include <random>

#include "core/fourbar/model.hpp"

namespace bd::core::samples {

/// The paper's §5.1 example (eq. 56), with its applied loads, no gravity.
FourBar paper_fourbar();
/// The same linkage without applied loads.
FourBar paper_fourbar_unloaded();
/// A parallelogram (l1 = l3, l2 = l4): the coupler keeps its angle. On branch +1 it is the
/// parallelogram for theta1 in (0, pi); for theta1 in (pi, 2 pi) the parallelogram is branch -1
/// (branch +1 there is the crossed antiparallelogram). theta1 = 0, pi are change points.
FourBar parallelogram();
/// A double crank (drag link): the frame is the shortest link, crank and rocker turn fully.
FourBar double_crank();
/// A triple rocker (non-Grashof, l_min + l_max = 5.5 > 4): the crank swings within
/// |theta1| < 1.553 rad, where coupler and rocker stretch into a line (|A1A3| = l2 + l3).
FourBar triple_rocker();
/// A triple rocker whose limit is |A1A3| = |l2 - l3| (the coupler folds back onto the rocker):
/// the crank swings within theta1 in [0.6402, 2 pi - 0.6402] rad.
FourBar folding_rocker();
/// The model with the paper's applied loads (eq. 56) on its links and the given gravity.
FourBar with_paper_loads(FourBar model, const Vec2& gravity = Vec2(0, 0));
/// A random linkage that assembles at every crank angle (a crank-rocker on a random branch),
/// with random mass distributions (f != 0), random loads and random gravity.
FourBar random_crank_rocker(std::mt19937_64& rng);

}  // namespace bd::core::samples
