#pragma once
/// Shared test and example mechanisms (one source for tests, benchmarks and examples).
#include <random>

#include "core/model.hpp"

namespace bd::core::samples {

/// The paper's §5.1 example (eq. 56), with its applied loads, no gravity.
FourBar paper_fourbar();
/// The same linkage without applied loads.
FourBar paper_fourbar_unloaded();
/// A parallelogram (l1 = l3, l2 = l4): the coupler keeps its angle.
FourBar parallelogram();
/// A random linkage that assembles at every crank angle (a crank-rocker on a random branch),
/// with random mass distributions (f != 0), random loads and random gravity.
FourBar random_crank_rocker(std::mt19937_64& rng);

}  // namespace bd::core::samples
