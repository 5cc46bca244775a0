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

Eigen::VectorXd midpoint_row(OdeSystem& sys, double t, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& f0, double H, int n) {
  sys.restart();
  const double h = H / n;
  Eigen::VectorXd prev = y;
  Eigen::VectorXd z = y + h * f0;
  for (int i = 1; i < n; ++i) {
    Eigen::VectorXd next = prev + 2 * h * sys.rhs(t + i * h, z);
    prev = std::move(z);
    z = std::move(next);
  }
  return 0.5 * (z + prev + h * sys.rhs(t + H, z));
}

}  // namespace

StepOutcome gbs_step(OdeSystem& sys, double t, const Eigen::VectorXd& y, const Eigen::VectorXd& f0,
                     double H, const Eigen::VectorXd& scale, double tol) {
  const Eigen::Index nc = scale.size();
  std::vector<Eigen::VectorXd> T;  // T[k] = T(j, k+1) of the current row j
  StepOutcome out;
  for (int j = 1; j <= kMaxRow; ++j) {
    std::vector<Eigen::VectorXd> row{midpoint_row(sys, t, y, f0, H, 2 * j)};
    for (int k = 1; k < j; ++k) {
      const double ratio = static_cast<double>(j) / (j - k);  // n_j / n_(j-k)
      row.push_back(row[k - 1] + (row[k - 1] - T[k - 1]) / (ratio * ratio - 1));
    }
    T = std::move(row);
    if (j < 2) continue;
    const Eigen::VectorXd diff = (T[j - 1] - T[j - 2]).head(nc);
    out.error = (diff.cwiseAbs().array() / (tol * scale.array())).maxCoeff();
    out.row = j;
    if (j >= kMinRow && out.error <= 1) {
      out.converged = true;
      break;
    }
  }
  out.y = T.back();
  return out;
}

}  // namespace bd::referee::detail
