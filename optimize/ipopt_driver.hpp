#pragma once
/// Internal to bd_optimize (included by optimize.cpp only): the Ipopt driver. Ipopt's own
/// headers appear only in ipopt_driver.cpp.
#include <Eigen/Core>

#include "optimize/nlopt_driver.hpp"  // DriverOutcome, TrackedNlp
#include "optimize/optimize.hpp"
#include "optimize/program.hpp"

namespace bd::optimize::detail {

/// Runs Ipopt's interior-point method from x0 with exact first derivatives (a dense Jacobian of
/// the equalities, then the inequalities as g(x) <= 0) and a limited-memory (L-BFGS) Hessian of
/// the Lagrangian. tol = options.relative_tolerance, constr_viol_tol =
/// 0.1 · options.constraint_tolerance, max_iter = options.max_evaluations, and the run is stopped
/// once options.max_evaluations objective evaluations are spent. Nothing is printed.
/// Thread-safe: solves from several threads run one at a time (Debian 12's Ipopt 3.11 calls
/// MUMPS, which is not thread-safe).
DriverOutcome solve_with_ipopt(const Program& nlp, const Eigen::VectorXd& x0,
                               const OptimizeOptions& options);

}  // namespace bd::optimize::detail
