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
inline constexpr Real kSingularRcond = 1e-9;

/// The n x n constraint Jacobian J (all rows, inputs included) factorized by full-pivoting LU in
/// scaled variables: J~ = Dr J Dc, Dc = 1/length on angle columns, Dr = length on angle-input
/// rows, so that J~ is dimensionless.
class Factorized {
 public:
  Factorized(const Model& model, const MatX& J);
  /// Reciprocal condition indicator: the smaller of LU's 1-norm estimate and the ratio of the
  /// smallest to the largest pivot (the estimate alone misses exactly singular matrices, whose
  /// zero pivot the pseudo-solve skips).
  Real rcond() const;
  VecX solve(const VecX& b) const;             ///< x with J x = b
  VecX solve_transposed(const VecX& b) const;  ///< y with J^T y = b

 private:
  VecX dr_, dc_;
  MatX scaled_;
  Eigen::FullPivLU<MatX> lu_;
  mutable std::optional<Eigen::FullPivLU<MatX>> lu_transposed_;  // on first use
};

/// Newton on residual(q, values) = 0 from q (updated in place) to machine precision; returns the
/// Jacobian factorized at the solution. With `chord` (a factorization at a nearby solution) it
/// first tries simplified Newton iterations with it, falling back to Newton. @throws
/// std::domain_error (text `what` + reason) when Newton does not converge or the solution is
/// singular.
Factorized close_loop(const Model& model, const VecX& values, VecX& q, const std::string& what,
                      const Factorized* chord = nullptr);

/// close_loop continued from the input values `from` to `to` in steps of at most 0.1 rad /
/// 0.05 length per input, so the branch of q is followed.
Factorized continue_loop(const Model& model, const VecX& from, const VecX& to, VecX& q,
                         const std::string& what);

/// Everything about one instant in maximal coordinates.
struct State {
  Real t = 0;
  VecX q, qd, qdd;
  VecX lambda;  ///< n multipliers: m constraint forces, then the input efforts
  Real input_work = 0, damper_work = 0, applied_work = 0;
};

/// Builds the public Sample of a complete State.
Sample make_sample(const Model& model, const Mechanism& mech, const State& s);

}  // namespace bd::referee::detail
