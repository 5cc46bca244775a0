#pragma once
// Internal: one step of Gragg–Bulirsch–Stoer extrapolation (modified midpoint rule with
// Richardson extrapolation in h^2), with the number of rows chosen by convergence.
//
// Why this method for the referee: it reaches any order (here up to 20) with a trivially
// verifiable implementation (no tables of coefficients to mistype), its error estimate
// T(j,j) - T(j,j-1) is conservative (it is the error of the lower-order value while the higher
// one is kept), and it is efficient at the very tight tolerances (1e-13 .. 1e-14 local) the
// referee needs, where low-order methods need millions of steps and accumulate rounding.
#include "tests/reference/planar/model.hpp"

namespace bd::referee::detail {

class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  /// Called before each modified-midpoint row: the following evaluations start again from the
  /// step's initial point (the free system resets its Newton guess there).
  virtual void restart() = 0;
  virtual VecX rhs(Real t, const VecX& y) = 0;
};

struct StepOutcome {
  bool converged = false;
  int row = 0;     ///< the row (1-based) at which the error estimate met the tolerance
  Real error = 0;  ///< that estimate, in units of the tolerance (<= 1 when converged)
  VecX y;
};

inline constexpr int kMinRow = 4;   // accept at order 8 or more (n = 2, 4, 6, 8, ...)
inline constexpr int kMaxRow = 10;  // up to order 20 (n = 20)

/// One step of size H from (t, y) with f0 = f(t, y). The error norm is the maximum over the
/// first scale.size() components of |T(j,j) - T(j,j-1)| / (tol * scale); the rest of y
/// (quadratures) is extrapolated but not controlled. Exceptions of the system propagate.
StepOutcome gbs_step(OdeSystem& sys, Real t, const VecX& y, const VecX& f0, Real H,
                     const VecX& scale, Real tol);

}  // namespace bd::referee::detail
