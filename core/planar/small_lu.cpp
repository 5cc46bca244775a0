#include "core/planar/small_lu.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

namespace bd::core::planar::detail {

namespace {

// Each kernel works on a column-major n x n array a (a[i + n j]); N > 0 is n at compile time (the
// loops unrolled), N = 0 takes n at run time.

// PA = LU in place, the row swaps in perm; returns how many swaps were not the identity
template <int N>
int factorise(double* a, int* perm, int n_run) {
  const int n = N > 0 ? N : n_run;
  int swaps = 0;
  for (int k = 0; k < n; ++k) {
    int p = k;
    double biggest = std::abs(a[k + n * k]);
    for (int i = k + 1; i < n; ++i) {
      const double v = std::abs(a[i + n * k]);
      if (v > biggest) biggest = v, p = i;
    }
    perm[k] = p;
    if (p != k) {
      ++swaps;
      for (int j = 0; j < n; ++j) std::swap(a[k + n * j], a[p + n * j]);
    }
    const double pivot = a[k + n * k];
    if (pivot != 0.0) {
      for (int i = k + 1; i < n; ++i) a[i + n * k] /= pivot;
    }
    for (int j = k + 1; j < n; ++j) {
      const double akj = a[k + n * j];
      for (int i = k + 1; i < n; ++i) a[i + n * j] -= a[i + n * k] * akj;
    }
  }
  return swaps;
}

// b = (PA)⁻¹ P b = A⁻¹ b in place: the swaps, L (unit diagonal) by columns, then U by columns
template <int N>
void solve_vector(const double* a, const int* perm, double* b, int n_run) {
  const int n = N > 0 ? N : n_run;
  for (int k = 0; k < n; ++k) std::swap(b[k], b[perm[k]]);
  for (int k = 0; k < n; ++k) {
    const double bk = b[k];
    for (int i = k + 1; i < n; ++i) b[i] -= a[i + n * k] * bk;
  }
  for (int k = n - 1; k >= 0; --k) {
    b[k] /= a[k + n * k];
    const double bk = b[k];
    for (int i = 0; i < k; ++i) b[i] -= a[i + n * k] * bk;
  }
}

// b = A⁻ᵀ b in place, with A = P⁻¹ L U: Uᵀ, then Lᵀ, then the swaps in reverse order
template <int N>
void solve_transpose_vector(const double* a, const int* perm, double* b, int n_run) {
  const int n = N > 0 ? N : n_run;
  for (int i = 0; i < n; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= a[k + n * i] * b[k];
    b[i] = s / a[i + n * i];
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < n; ++k) s -= a[k + n * i] * b[k];
    b[i] = s;
  }
  for (int k = n - 1; k >= 0; --k) std::swap(b[k], b[perm[k]]);
}

// f(std::integral_constant<int, N>) with N = n for n up to kFixedSize, else N = 0 (n = 0 here)
template <class F>
decltype(auto) by_size(int n, F&& f) {
  switch (n) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    case 8: return f(std::integral_constant<int, 8>{});
    default: return f(std::integral_constant<int, 0>{});
  }
}
static_assert(SmallLu::kFixedSize == 8, "by_size dispatches sizes up to 8");

}  // namespace

void SmallLu::compute(const Eigen::MatrixXd& a) {
  n_ = static_cast<int>(a.rows());
  if (n_ > kFixedSize) {
    dynamic_.compute(a);
    return;
  }
  by_size(n_, [&](auto size) {
    constexpr int N = decltype(size)::value;
    const int n = N > 0 ? N : n_;
    std::copy_n(a.data(), n * n, a_);  // for rcond(): the 1-norm, only when asked
    std::copy_n(a.data(), n * n, lu_);
    solve_kernel_ = &solve_vector<N>;
    transpose_kernel_ = &solve_transpose_vector<N>;
    swaps_ = factorise<N>(lu_, perm_, n);
    double smallest = std::numeric_limits<double>::infinity(), largest = 0;
    for (int k = 0; k < n; ++k) {
      const double p = std::abs(lu_[k + n * k]);
      smallest = std::min(smallest, p);
      largest = std::max(largest, p);
    }
    pivot_ratio_ = smallest / largest;
  });
}

void SmallLu::solve_in_place(double* b) const {
  if (n_ == 0) return;  // nothing to solve (and no kernel chosen if never factorised)
  solve_kernel_(lu_, perm_, b, n_);
}

void SmallLu::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (n_ > kFixedSize) {
    x.noalias() = dynamic_.solve(b);
    return;
  }
  if (&x != &b) {  // a plain copy: Eigen's assignment costs more than the 4 x 4 solve's half
    x.resize(n_);
    std::copy_n(b.data(), n_, x.data());
  }
  solve_in_place(x.data());
}

void SmallLu::solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const {
  if (n_ > kFixedSize) {
    x.noalias() = dynamic_.solve(b);
    return;
  }
  if (&x != &b) x = b;
  for (Eigen::Index j = 0; j < x.cols(); ++j) solve_in_place(x.col(j).data());
}

void SmallLu::solve_transpose(Eigen::VectorXd& b) const {
  if (n_ <= kFixedSize) {
    if (n_ > 0) transpose_kernel_(lu_, perm_, b.data(), n_);
    return;
  }
  // A = P⁻¹ L U: Uᵀ, then Lᵀ, then the permutation
  dynamic_.matrixLU().triangularView<Eigen::Upper>().transpose().solveInPlace(b);
  dynamic_.matrixLU().triangularView<Eigen::UnitLower>().transpose().solveInPlace(b);
  b = dynamic_.permutationP().transpose() * b;
}

double SmallLu::determinant() const {
  if (n_ > kFixedSize) return dynamic_.determinant();
  double d = swaps_ % 2 ? -1.0 : 1.0;
  for (int k = 0; k < n_; ++k) d *= lu_[k + n_ * k];
  return d;
}

double SmallLu::pivot_ratio() const {
  if (n_ <= kFixedSize) return pivot_ratio_;
  const auto d = dynamic_.matrixLU().diagonal().cwiseAbs();
  return d.minCoeff() / d.maxCoeff();
}

// ||A⁻¹||₁ estimated as Eigen's rcond_invmatrix_L1_norm_estimate (Higham, Algorithms 4.1 and
// 5.1): at most 10 solves
double SmallLu::inverse_norm_estimate() const {
  const int n = n_;
  v_.setConstant(n, 1.0 / n);
  solve_in_place(v_.data());
  double lower_bound = v_.lpNorm<1>();
  if (n == 1) return lower_bound;
  double old_lower_bound = lower_bound;
  Eigen::Index v_max = -1, old_v_max = -1;
  for (int k = 0; k < 4; ++k) {
    sign_ = (v_.array() < 0.0).select(-Eigen::VectorXd::Ones(n), Eigen::VectorXd::Ones(n));
    if (k > 0 && sign_ == old_sign_) break;
    v_ = sign_;
    solve_transpose(v_);
    v_.cwiseAbs().maxCoeff(&v_max);
    if (v_max == old_v_max) break;
    v_.setZero(n);
    v_[v_max] = 1.0;
    solve_in_place(v_.data());
    lower_bound = v_.lpNorm<1>();
    if (lower_bound <= old_lower_bound) break;
    old_sign_ = sign_;
    old_v_max = v_max;
    old_lower_bound = lower_bound;
  }
  double alternating = 1.0;
  for (int i = 0; i < n; ++i) {
    v_[i] = alternating * (1.0 + static_cast<double>(i) / (n - 1));
    alternating = -alternating;
  }
  solve_in_place(v_.data());
  return std::max(lower_bound, 2 * v_.lpNorm<1>() / (3.0 * n));
}

double SmallLu::rcond() const {
  if (n_ > kFixedSize) return dynamic_.rcond();
  if (n_ == 0) return std::numeric_limits<double>::infinity();
  double l1_norm = 0;  // as Eigen's: the largest column sum of |a|
  for (int j = 0; j < n_; ++j) {
    double column = 0;
    for (int i = 0; i < n_; ++i) column += std::abs(a_[i + n_ * j]);
    l1_norm = std::max(l1_norm, column);
  }
  if (l1_norm == 0.0) return 0.0;
  if (n_ == 1) return 1.0;
  const double inverse_norm = inverse_norm_estimate();
  return inverse_norm == 0.0 ? 0.0 : (1.0 / inverse_norm) / l1_norm;
}

}  // namespace bd::core::planar::detail
