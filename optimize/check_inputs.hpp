#pragma once
/// Internal to bd_optimize (optimize.cpp, pareto.cpp): the inputs' checks at the entry points.
#include "optimize/optimize.hpp"
#include "optimize/problem.hpp"

namespace bd::optimize::detail {

/// Throws bd::InputError for the options' first problem ("optimize options: " and its text),
/// else for the problem's ("design problem: " and its text).
void check_inputs(const DesignProblem& problem, const OptimizeOptions& options);

}  // namespace bd::optimize::detail
