// Gragg's modified midpoint rule (Hairer, Norsett & Wanner, Solving ODEs I, II.9):
//   z0 = y, z1 = z0 + h f(t, z0), z(i+1) = z(i-1) + 2 h f(t + i h, z(i)) (i = 1 .. n-1),
//   T = (z(n) + z(n-1) + h f(t + H, z(n))) / 2,     h = H / n, n even,
// has an error expansion in even powers of h, so the Aitken–Neville scheme
//   T(j,k+1) = T(j,k) + (T(j,k) - T(j-1,k)) / ((n_j / n_(j-k))^2 - 1)
// with n_j = 2j raises the order by two per column: T(j,j) has order 2j.
#include "tests/reference/planar/extrapolation.hpp"

#include <utility>
#include <vector>

namespace bd::referee::detail {

namespace {

VecX midpoint_row(OdeSystem& sys, Real t, const VecX& y, const VecX& f0, Real H, int n) {
  sys.restart();
  const Real h = H / n;
  VecX prev = y;
  VecX z = y + h * f0;
  for (int i = 1; i < n; ++i) {
    VecX next = prev + 2 * h * sys.rhs(t + i * h, z);
    prev = std::move(z);
    z = std::move(next);
  }
  return 0.5 * (z + prev + h * sys.rhs(t + H, z));
}

}  // namespace

StepOutcome gbs_step(OdeSystem& sys, Real t, const VecX& y, const VecX& f0, Real H,
                     const VecX& scale, Real tol) {
  const Eigen::Index nc = scale.size();
  std::vector<VecX> T;  // T[k] = T(j, k+1) of the current row j
  StepOutcome out;
  for (int j = 1; j <= kMaxRow; ++j) {
    std::vector<VecX> row{midpoint_row(sys, t, y, f0, H, 2 * j)};
    for (int k = 1; k < j; ++k) {
      const Real ratio = static_cast<Real>(j) / (j - k);  // n_j / n_(j-k)
      row.push_back(row[k - 1] + (row[k - 1] - T[k - 1]) / (ratio * ratio - 1));
    }
    T = std::move(row);
    if (j < 2) continue;
    const VecX diff = (T[j - 1] - T[j - 2]).head(nc);
    const Real previous = out.error;
    out.error = (diff.cwiseAbs().array() / (tol * scale.array())).maxCoeff();
    out.row = j;
    // two consecutive rows within the tolerance: one estimate alone can be small by accident
    // (a component's difference crossing zero) and let a poor step through
    if (j >= kMinRow && out.error <= 1 && previous <= 1) {
      out.converged = true;
      break;
    }
  }
  out.y = T.back();
  return out;
}

}  // namespace bd::referee::detail
