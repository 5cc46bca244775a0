// The bounded least squares behind the first-order certificate's multipliers
// (optimize/first_order.hpp, bounded_least_squares(): Lawson and Hanson's active-set method with
// free components), checked by two independent routes: the Karush-Kuhn-Tucker conditions of the
// convex quadratic, which characterise its minimum, and on small problems the least value over
// every choice of the components held at their bound, each solved as plain least squares.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "optimize/first_order.hpp"

namespace {

using bd::optimize::detail::bounded_least_squares;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kInf = std::numeric_limits<double>::infinity();

// The largest violation of the KKT conditions of min ½|Az - b|², z_k >= lower_k: g = Aᵀ(Az - b)
// vanishes on free and inactive components and is >= 0 at a bound. Relative to the size of the
// terms g is computed from, |A|·(|b| + |A|·|z|₁), which its round-off scales with (nearly
// dependent columns against a free one give multipliers up to 1e9 below).
double kkt_violation(const MatrixXd& a, const VectorXd& b, const VectorXd& lower,
                     const VectorXd& z) {
  const VectorXd g = a.transpose() * (a * z - b);
  const double size = a.cwiseAbs().maxCoeff();
  const double scale = size * std::max(b.cwiseAbs().maxCoeff() + size * z.lpNorm<1>(), 1e-300);
  double worst = 0;
  for (Eigen::Index k = 0; k < z.size(); ++k) {
    if (std::isfinite(lower[k])) {
      worst = std::max(worst, (lower[k] - z[k]) / std::max(std::abs(lower[k]), 1.0));
      // at the bound the gradient may point inwards only; off it, it vanishes
      const bool at_bound = z[k] - lower[k] <= 1e-12 * std::max(std::abs(lower[k]), 1.0);
      worst = std::max(worst, (at_bound ? -g[k] : std::abs(g[k])) / scale);
    } else {
      worst = std::max(worst, std::abs(g[k]) / scale);
    }
  }
  return worst;
}

// The least ½|Az - b|² over every subset of the bounded components held at their bound, the
// rest solved by plain least squares and kept where they stay within their bounds.
double brute_force_minimum(const MatrixXd& a, const VectorXd& b, const VectorXd& lower) {
  const auto m = static_cast<int>(a.cols());
  double best = kInf;
  for (int held = 0; held < (1 << m); ++held) {
    bool skip = false;
    for (int k = 0; k < m; ++k) {
      if ((held >> k & 1) && !std::isfinite(lower[k])) skip = true;
    }
    if (skip) continue;
    VectorXd z = VectorXd::Zero(m), rhs = b;
    std::vector<int> loose;
    for (int k = 0; k < m; ++k) {
      if (held >> k & 1) {
        z[k] = lower[k];
        rhs -= a.col(k) * lower[k];
      } else {
        loose.push_back(k);
      }
    }
    if (!loose.empty()) {
      MatrixXd al(a.rows(), static_cast<Eigen::Index>(loose.size()));
      for (std::size_t i = 0; i < loose.size(); ++i)
        al.col(static_cast<Eigen::Index>(i)) = a.col(loose[i]);
      const VectorXd zl = al.completeOrthogonalDecomposition().solve(rhs);
      bool within = true;
      for (std::size_t i = 0; i < loose.size(); ++i) {
        z[loose[i]] = zl[static_cast<Eigen::Index>(i)];
        if (std::isfinite(lower[loose[i]]) && z[loose[i]] < lower[loose[i]]) within = false;
      }
      if (!within) continue;
    }
    best = std::min(best, 0.5 * (a * z - b).squaredNorm());
  }
  return best;
}

TEST(BoundedLeastSquares, SmallProblemsReachTheLeastValueOverEveryActiveSet) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 4, m = 3 + trial % 6;
    MatrixXd a(n, m);
    for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = normal(rng);
    if (trial % 3 == 0) a.col(1) = 2.5 * a.col(0);  // dependent columns
    VectorXd b(n), lower(m);
    for (int i = 0; i < n; ++i) b[i] = 3 * normal(rng);
    for (int k = 0; k < m; ++k) lower[k] = (k + trial) % 4 == 0 ? -kInf : (k % 2 ? 0 : normal(rng));
    const VectorXd z = bounded_least_squares(a, b, lower);
    SCOPED_TRACE(trial);
    ASSERT_TRUE(z.allFinite());
    EXPECT_LT(kkt_violation(a, b, lower, z), 1e-13);
    const double value = 0.5 * (a * z - b).squaredNorm(), best = brute_force_minimum(a, b, lower);
    EXPECT_NEAR(value, best, 1e-11 * std::max(b.squaredNorm(), 1.0));
  }
}

// The case the certificate meets at a force-balanced design under a peak objective: hundreds of
// active rows whose gradients are nearly parallel (one per sample of a revolution), a handful of
// variables, bounds and an equality. The general-purpose solve this replaced took seconds here.
TEST(BoundedLeastSquares, HundredsOfNearlyParallelColumnsMeetTheConditions) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 5, m = 365;
    MatrixXd a(n, m);
    const VectorXd base = VectorXd::Random(n);
    for (int k = 0; k < 360; ++k) {
      const double phi = 2 * std::numbers::pi * k / 360;
      a.col(k) = base;
      a(0, k) += 1e-3 * std::cos(phi);
      a(1, k) += 1e-3 * std::sin(phi);
      a(2, k) += 1e-9 * normal(rng);
    }
    for (int k = 360; k < m; ++k) a.col(k) = VectorXd::Unit(n, k - 360);  // bound rows
    VectorXd lower = VectorXd::Zero(m);
    lower[0] = -kInf;  // an equality
    VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = normal(rng);
    if (trial % 2) b = -b;
    const VectorXd z = bounded_least_squares(a, b, lower);
    SCOPED_TRACE(trial);
    ASSERT_TRUE(z.allFinite());
    EXPECT_LT(kkt_violation(a, b, lower, z), 1e-13);
  }
}

}  // namespace
