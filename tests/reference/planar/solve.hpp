#pragma once
// Internal: position closure (Newton), the factorized constraint Jacobian, and the full state of
// one instant (positions, velocities, accelerations, multipliers) turned into a Sample.
#include <optional>
#include <string>

#include "tests/reference/planar/model.hpp"

namespace bd::referee::detail {

/// Below this reciprocal condition number (Factorized::rcond) of the scaled Jacobian, a position
/// is reported singular. The scaled Jacobian (angles and angle-input rows multiplied by the
/// characteristic length) has rcond ~ 1e-2..1 for ordinary positions and ~ distance to the
/// singularity / length near one, so 1e-9 flags only positions within ~1e-9 of a singular one.
inline constexpr double kSingularRcond = 1e-9;

/// The n x n constraint Jacobian J (all rows, inputs included) factorized by full-pivoting LU in
/// scaled variables: J~ = Dr J Dc, Dc = 1/length on angle columns, Dr = length on angle-input
/// rows, so that J~ is dimensionless.
class Factorized {
 public:
  Factorized(const Model& model, const MatrixXd& J);
  /// Reciprocal condition indicator: the smaller of LU's 1-norm estimate and the ratio of the
  /// smallest to the largest pivot (the estimate alone misses exactly singular matrices, whose
  /// zero pivot the pseudo-solve skips).
  double rcond() const;
  VectorXd solve(const VectorXd& b) const;             ///< x with J x = b
  VectorXd solve_transposed(const VectorXd& b) const;  ///< y with J^T y = b

 private:
  VectorXd dr_, dc_;
  MatrixXd scaled_;
  Eigen::FullPivLU<MatrixXd> lu_;
  mutable std::optional<Eigen::FullPivLU<MatrixXd>> lu_transposed_;  // on first use
};

/// Newton on residual(q, values) = 0 from q (updated in place) to machine precision; returns the
/// Jacobian factorized at the solution. @throws std::domain_error (text `what` + reason) when
/// Newton does not converge or the solution is singular.
Factorized close_loop(const Model& model, const VectorXd& values, VectorXd& q,
                      const std::string& what);

/// close_loop continued from the input values `from` to `to` in steps of at most 0.1 rad /
/// 0.05 length per input, so the branch of q is followed.
Factorized continue_loop(const Model& model, const VectorXd& from, const VectorXd& to, VectorXd& q,
                         const std::string& what);

/// Everything about one instant in maximal coordinates.
struct State {
  double t = 0;
  VectorXd q, qd, qdd;
  VectorXd lambda;  ///< n multipliers: m constraint forces, then the input efforts
  double input_work = 0, damper_work = 0, applied_work = 0;
};

/// Builds the public Sample of a complete State.
Sample make_sample(const Model& model, const Mechanism& mech, const State& s);

}  // namespace bd::referee::detail
