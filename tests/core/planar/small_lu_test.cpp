// The planar engine's small LU (core/planar/small_lu.hpp) against Eigen's PartialPivLU, an
// independent implementation of the same factorisation, on random systems of every size with
// its own kernels (1 to 8) and beyond (Eigen's own route): the one-vector, many-column and
// transposed solves and the determinant. Residuals are measured against the matrix itself, so
// the test does not lean on the reference's round-off either.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/planar/small_lu.hpp"

namespace bd::core::planar::detail {
namespace {

// a random n x n matrix with entries in [-1, 1] and a diagonal of random sign dominant by a
// margin of at least 1 (so ||A⁻¹||∞ <= 1 and cond∞(A) <= 2n + 2), its rows shuffled so that
// partial pivoting has swaps to do
Eigen::MatrixXd random_system(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) a(i, j) = u(rng);
  for (int i = 0; i < n; ++i) a(i, i) += (u(rng) < 0 ? -1.0 : 1.0) * (n + 1);
  Eigen::PermutationMatrix<Eigen::Dynamic> p(n);
  p.setIdentity();
  std::shuffle(p.indices().data(), p.indices().data() + n, rng);
  return p * a;
}

TEST(SmallLu, SolvesAgreeWithEigensPartialPivLuAtEverySize) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 1; n <= 12; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      SCOPED_TRACE(testing::Message() << "n = " << n << ", trial " << trial);
      const Eigen::MatrixXd a = random_system(n, rng);
      const Eigen::PartialPivLU<Eigen::MatrixXd> reference(a);
      SmallLu lu;
      lu.compute(a);
      ASSERT_EQ(lu.size(), n);
      // a backward-stable solve errs by about n ε cond(A) |x| <= 12 · 1.1e-16 · 26 · 1 ≈ 3.5e-14
      const double tol = 1e-13;
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) b[i] = u(rng);
      Eigen::VectorXd x;
      lu.solve(b, x);
      EXPECT_LE((x - reference.solve(b)).cwiseAbs().maxCoeff(), tol);
      EXPECT_LE((a * x - b).cwiseAbs().maxCoeff(), tol);
      // in place
      Eigen::VectorXd y = b;
      lu.solve(y, y);
      EXPECT_EQ(y, x);
      // transposed: Aᵀ z = b
      Eigen::VectorXd z = b;
      lu.solve_transpose(z);
      const Eigen::PartialPivLU<Eigen::MatrixXd> transposed(a.transpose());
      EXPECT_LE((z - transposed.solve(b)).cwiseAbs().maxCoeff(), tol);
      EXPECT_LE((a.transpose() * z - b).cwiseAbs().maxCoeff(), tol);
      // three columns at once, each as its own solve
      Eigen::MatrixXd B(n, 3), X;
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < n; ++i) B(i, j) = u(rng);
      lu.solve(B, X);
      EXPECT_LE((a * X - B).cwiseAbs().maxCoeff(), tol);
      for (int j = 0; j < 3; ++j) {
        Eigen::VectorXd column;
        lu.solve(Eigen::VectorXd(B.col(j)), column);
        EXPECT_LE((X.col(j) - column).cwiseAbs().maxCoeff(), tol);
      }
      // the determinant, sign included (the sign tells a driven scene's assembly branch)
      EXPECT_NEAR(lu.determinant(), reference.determinant(),
                  1e-13 * std::abs(reference.determinant()));
      EXPECT_GT(lu.pivot_ratio(), 0.0);
      EXPECT_LE(lu.pivot_ratio(), 1.0);
    }
  }
}

// A system without unknowns (a linkage with no moving node) solves to nothing, factorised or
// not, and its determinant is the empty product.
TEST(SmallLu, EmptySystems) {
  SmallLu lu;
  Eigen::VectorXd b(0), x;
  lu.solve(b, x);
  EXPECT_EQ(x.size(), 0);
  lu.solve_transpose(b);
  lu.compute(Eigen::MatrixXd(0, 0));
  lu.solve(b, x);
  EXPECT_EQ(x.size(), 0);
  EXPECT_EQ(lu.determinant(), 1.0);
}

}  // namespace
}  // namespace bd::core::planar::detail
