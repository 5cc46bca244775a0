#include "optimize/first_order.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/number_text.hpp"
#include "optimize/nlopt_driver.hpp"

namespace bd::optimize::detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;

double stationarity_residual(const Program& p, const VectorXd& x, double activity) {
  return first_order(p, x, activity).residual;
}

namespace {

// each variable's unit: its box width, 1 where the box is unbounded or empty
VectorXd box_widths(const Program& p) {
  VectorXd w = (p.upper() - p.lower()).cwiseAbs();
  for (Eigen::Index j = 0; j < w.size(); ++j) {
    if (!std::isfinite(w[j]) || w[j] == 0) w[j] = 1;
  }
  return w;
}

}  // namespace

FirstOrder first_order(const Program& p, const VectorXd& x, double activity) {
  const int n = p.n();
  const VectorXd w = box_widths(p);
  VectorXd g(n);
  const double f = p.objective(x, &g);
  const VectorXd gw = w.cwiseProduct(g);
  // the columns of the active constraints' scaled gradients, with each multiplier's lower bound
  // and the value its term adds to the Lagrangian at x (c_i, or l_j - x_j, x_j - u_j for bounds)
  std::vector<VectorXd> columns;
  std::vector<double> floor, term;
  const double inf = std::numeric_limits<double>::infinity();
  VectorXd c;
  MatrixXd jac;
  if (p.n_eq() > 0) {
    p.equalities(x, c, &jac);
    for (int i = 0; i < c.size(); ++i) {
      columns.emplace_back(w.cwiseProduct(jac.row(i).transpose()));
      floor.push_back(-inf);
      term.push_back(c[i]);
    }
  }
  if (p.n_ineq() > 0) {
    p.first_order_inequalities(x, g, c, jac);
    for (int i = 0; i < c.size(); ++i) {
      if (!(c[i] >= -activity)) continue;
      columns.emplace_back(w.cwiseProduct(jac.row(i).transpose()));
      floor.push_back(0);
      term.push_back(c[i]);
    }
  }
  for (int j = 0; j < n; ++j) {
    VectorXd e = VectorXd::Zero(n);
    if (x[j] - p.lower()[j] <= activity * w[j]) {
      e[j] = -w[j];  // -μ at a lower bound, in scaled units: the bound's gradient is -1
      term.push_back(p.lower()[j] - x[j]);
    } else if (p.upper()[j] - x[j] <= activity * w[j]) {
      e[j] = w[j];
      term.push_back(x[j] - p.upper()[j]);
    } else {
      continue;
    }
    columns.push_back(std::move(e));
    floor.push_back(0);
  }
  // relative to the objective's size or its gradient's, whichever is larger, and at least 1:
  // the programs' objectives are normalised (1 per unit weight at the original design), so near
  // an optimum where the objective itself nearly vanishes (a force-balanced design's smoothed
  // Fsh, ~1e-6) the residual is still measured on the problem's own scale
  const double size = std::max({std::abs(f), gw.cwiseAbs().maxCoeff(), 1.0});
  // L(y) >= L(x) + ∇L(x)·(y - x) >= L(x) - Σ_j |w_j ∂L/∂x_j| for y in the box, and L <= f on
  // the feasible set (multipliers of the right sign): a lower bound where L is convex
  const bool finite_box = ((p.upper() - p.lower()).array().isFinite()).all();
  // (less 1e-12 of its size for the round-off of the sums: a bound must not overstate)
  auto bound = [&](const VectorXd& r, double lagrangian) {
    const double value = lagrangian - r.cwiseAbs().sum();
    return finite_box ? value - 1e-12 * std::max(std::abs(value), 1.0) : -inf;
  };
  if (columns.empty()) return {gw.cwiseAbs().maxCoeff() / size, bound(gw, f)};
  MatrixXd A(n, static_cast<Eigen::Index>(columns.size()));
  VectorXd lower(A.cols());
  for (Eigen::Index k = 0; k < A.cols(); ++k) {
    A.col(k) = columns[static_cast<std::size_t>(k)];
    lower[k] = floor[static_cast<std::size_t>(k)];
  }
  // the least-squares multipliers of every active constraint first (the common case: none of
  // them of the wrong sign); bounded least squares from there where some are
  VectorXd z = A.completeOrthogonalDecomposition().solve(-gw);
  const double scale = gw.cwiseAbs().maxCoeff();
  bool signs = true;
  for (Eigen::Index k = 0; k < z.size(); ++k) {
    if (z[k] < lower[k] - 1e-12 * scale) signs = false;
  }
  if (!signs) z = bounded_least_squares(A, -gw, lower);
  z = z.cwiseMax(lower);  // a bounded solve's round-off below a floor would void the bound
  const VectorXd r = gw + A * z;
  double lagrangian = f;
  for (Eigen::Index k = 0; k < z.size(); ++k)
    lagrangian += z[k] * term[static_cast<std::size_t>(k)];
  return {r.cwiseAbs().maxCoeff() / size, bound(r, lagrangian)};
}

namespace {

// The active rows at x (equalities, inequalities within `activity`, bounds within activity w_j
// as unit rows) and their values, and the gradient of the Lagrangian with least-squares
// multipliers
struct ActiveSet {
  MatrixXd a;  // rows: active constraints' gradients
  VectorXd c;  // their values (0 on the set)
  VectorXd z;  // multipliers
  VectorXd grad_l;
};

std::vector<int> active_rows(const Program& p, const VectorXd& x, double activity,
                             std::vector<int>& bounds) {
  std::vector<int> rows;
  if (p.n_ineq() > 0) {
    VectorXd c;
    p.inequalities(x, c, nullptr);
    for (int i = 0; i < c.size(); ++i) {
      if (c[i] >= -activity) rows.push_back(i);
    }
  }
  bounds.clear();
  const VectorXd w = box_widths(p);
  for (int j = 0; j < p.n(); ++j) {
    if (x[j] - p.lower()[j] <= activity * w[j] || p.upper()[j] - x[j] <= activity * w[j]) {
      bounds.push_back(j);
    }
  }
  return rows;
}

// The rows of a fixed active set at x, and ∇L = ∇f + Aᵀ z at the multipliers z (given, or fitted
// by least squares when empty)
ActiveSet active_set(const Program& p, const VectorXd& x, const std::vector<int>& rows,
                     const std::vector<int>& bounds, const VectorXd* z) {
  const int n = p.n();
  const auto m = static_cast<Eigen::Index>(p.n_eq() + rows.size() + bounds.size());
  ActiveSet s;
  s.a.setZero(m, n);
  s.c.setZero(m);
  Eigen::Index k = 0;
  VectorXd c;
  MatrixXd jac;
  if (p.n_eq() > 0) {
    p.equalities(x, c, &jac);
    s.a.topRows(p.n_eq()) = jac;
    s.c.head(p.n_eq()) = c;
    k = p.n_eq();
  }
  if (!rows.empty()) {
    p.inequalities(x, c, &jac);
    for (int i : rows) {
      s.a.row(k) = jac.row(i);
      s.c[k++] = c[i];
    }
  }
  for (int j : bounds) {
    s.a(k, j) = 1;
    s.c[k++] = 0;  // held where it is
  }
  VectorXd g(n);
  p.objective(x, &g);
  if (z != nullptr) {
    s.z = *z;
  } else if (m == 0) {
    s.z.resize(0);
  } else {
    s.z = s.a.transpose().completeOrthogonalDecomposition().solve(-g);
  }
  s.grad_l = g + s.a.transpose() * s.z;
  return s;
}

}  // namespace

VectorXd newton_polish(const Program& p, const VectorXd& x0, double constraint_tolerance, int steps,
                       double activity) {
  const int n = p.n();
  VectorXd x = x0, best = x0;
  double least = stationarity_residual(p, x, activity);
  std::vector<int> bounds;
  const std::vector<int> rows = active_rows(p, x, activity, bounds);
  const VectorXd w = box_widths(p);
  for (int step = 0; step < steps && least > 0; ++step) {
    const ActiveSet s = active_set(p, x, rows, bounds, nullptr);
    const auto m = s.a.rows();
    // the Lagrangian's Hessian by central differences of its gradient at fixed multipliers
    MatrixXd h(n, n);
    for (int j = 0; j < n; ++j) {
      const double e = 1e-6 * std::max(w[j], std::abs(x[j]));
      VectorXd plus = x, minus = x;
      plus[j] += e;
      minus[j] -= e;
      h.col(j) = (active_set(p, plus, rows, bounds, &s.z).grad_l -
                  active_set(p, minus, rows, bounds, &s.z).grad_l) /
                 (2 * e);
    }
    MatrixXd kkt = MatrixXd::Zero(n + m, n + m);
    kkt.topLeftCorner(n, n) = 0.5 * (h + h.transpose());
    kkt.topRightCorner(n, m) = s.a.transpose();
    kkt.bottomLeftCorner(m, n) = s.a;
    VectorXd rhs(n + m);
    rhs << -s.grad_l, -s.c;
    const VectorXd d = kkt.completeOrthogonalDecomposition().solve(rhs);
    x = (x + d.head(n)).cwiseMax(p.lower()).cwiseMin(p.upper());
    if (!x.allFinite()) break;
    // a step along a curved constraint leaves it violated to second order, which the next
    // step takes back: only feasible points are kept
    if (constraint_violation(p, x) > constraint_tolerance) continue;
    const double r = stationarity_residual(p, x, activity);
    if (r < least) best = x, least = r;
  }
  return best;
}

VectorXd bounded_least_squares(const MatrixXd& A, const VectorXd& b, const VectorXd& lower) {
  const Eigen::Index m = A.cols();
  // y = z - lower >= 0 on the bounded components; the free ones (lower -inf) are y itself
  std::vector<bool> free(static_cast<std::size_t>(m)), passive(static_cast<std::size_t>(m));
  VectorXd shift = VectorXd::Zero(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const auto i = static_cast<std::size_t>(k);
    free[i] = passive[i] = !std::isfinite(lower[k]);
    if (!free[i]) shift[k] = lower[k];
  }
  const VectorXd rhs = b - A * shift;
  VectorXd y = VectorXd::Zero(m);
  // the least-squares solution on the passive columns, 0 elsewhere (rank-revealing: the
  // passive columns may be dependent, as the rows of one peak nearly are)
  const auto solve_passive = [&] {
    std::vector<Eigen::Index> cols;
    for (Eigen::Index k = 0; k < m; ++k) {
      if (passive[static_cast<std::size_t>(k)]) cols.push_back(k);
    }
    VectorXd s = VectorXd::Zero(m);
    if (cols.empty()) return s;
    MatrixXd ap(A.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c)
      ap.col(static_cast<Eigen::Index>(c)) = A.col(cols[c]);
    const VectorXd sp = ap.completeOrthogonalDecomposition().solve(rhs);
    for (std::size_t c = 0; c < cols.size(); ++c) s[cols[c]] = sp[static_cast<Eigen::Index>(c)];
    return s;
  };
  if (std::find(free.begin(), free.end(), true) != free.end()) y = solve_passive();
  // a component enters only where the residual's gradient clearly points into its half-space
  const double tolerance = 10 * std::numeric_limits<double>::epsilon() *
                           std::max(1.0, static_cast<double>(std::max(A.rows(), m))) *
                           std::max(A.cwiseAbs().maxCoeff(), 1e-300) *
                           std::max(rhs.cwiseAbs().maxCoeff(), 1e-300);
  // a column whose least-squares value comes out <= 0 as it enters (round-off, on nearly
  // dependent columns) is barred until the point moves
  std::vector<bool> barred(static_cast<std::size_t>(m));
  for (Eigen::Index outer = 0; outer < 3 * m + 10; ++outer) {
    const VectorXd w = A.transpose() * (rhs - A * y);
    Eigen::Index enter = -1;
    double largest = tolerance;
    for (Eigen::Index k = 0; k < m; ++k) {
      const auto i = static_cast<std::size_t>(k);
      if (!passive[i] && !barred[i] && w[k] > largest) largest = w[k], enter = k;
    }
    if (enter < 0) break;
    passive[static_cast<std::size_t>(enter)] = true;
    for (Eigen::Index inner = 0; inner <= m; ++inner) {
      const VectorXd s = solve_passive();
      if (inner == 0 && !(s[enter] > 0)) {
        passive[static_cast<std::size_t>(enter)] = false;
        barred[static_cast<std::size_t>(enter)] = true;
        break;
      }
      std::fill(barred.begin(), barred.end(), false);
      // the step towards s as far as every bounded passive component stays >= 0
      double alpha = 1;
      Eigen::Index blocking = -1;
      for (Eigen::Index k = 0; k < m; ++k) {
        const auto i = static_cast<std::size_t>(k);
        if (passive[i] && !free[i] && !(s[k] > 0)) {
          const double a = y[k] / (y[k] - s[k]);  // y_k > 0 >= s_k here: 0 <= a < 1
          if (a < alpha) alpha = a, blocking = k;
        }
      }
      y += alpha * (s - y);
      if (blocking < 0) break;
      for (Eigen::Index k = 0; k < m; ++k) {
        const auto i = static_cast<std::size_t>(k);
        if (passive[i] && !free[i] && (k == blocking || !(y[k] > 0))) passive[i] = false, y[k] = 0;
      }
    }
  }
  for (Eigen::Index k = 0; k < m; ++k) {
    if (!free[static_cast<std::size_t>(k)]) y[k] = std::max(y[k], 0.0);
  }
  return y + shift;
}

Optimality optimality(const std::string& why_not_convex, bool converged, double stationarity,
                      double relative_tolerance) {
  if (!why_not_convex.empty()) return {false, "not proven global: " + why_not_convex};
  const std::string convex =
      "the problem is convex in the counterweights' masses and mass moments (the reactions it "
      "reads are affine in them in a driven scene, each envelope is a cone, the added mass is "
      "linear)";
  if (!converged) {
    return {false, "not proven global: " + convex + ", but the solver did not converge"};
  }
  const double tolerance = stationarity_tolerance(relative_tolerance);
  if (!(stationarity <= tolerance)) {
    return {false, "not proven global: " + convex +
                       ", but the design meets the first-order conditions only to " +
                       text::digits(stationarity, 2) + " (tolerance " + text::digits(tolerance, 2) +
                       ")"};
  }
  return {true, "global: " + convex + ", and the design meets the first-order conditions to " +
                    text::digits(stationarity, 2) + " (tolerance " + text::digits(tolerance, 2) +
                    ")"};
}

}  // namespace bd::optimize::detail
