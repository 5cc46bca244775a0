#pragma once
/// An LU factorisation with partial pivoting for the planar engine's small square systems (the
/// constraints and inputs, 4 coordinates for a four-bar; the dae route's saddle-point system, 7
/// for a four-bar): PA = LU as Eigen::PartialPivLU computes it, bit for bit. Up to kFixedSize
/// the factorisation and the solves for one right-hand side run kernels compiled for each size
/// (complete unrolling, the same operations in the same order as Eigen's); larger systems are
/// Eigen::PartialPivLU's. Eigen's dynamic-size LU and triangular solves spend most of their
/// instructions on block and loop overhead at these sizes (docs/performance.md, "The general
/// planar engine"). The many-column solve runs the one-vector kernel per column; the transposed
/// solve has its own kernel (Uᵀ, Lᵀ by rows, then the swaps), whose sums run in another order
/// than Eigen's: its results agree with Eigen's to round-off, not bit for bit.
///
/// Sized once (compute() allocates only when the size changes), so an evaluation allocates
/// nothing.
#include <Eigen/Core>
#include <Eigen/LU>

namespace bd::core::planar::detail {

class SmallLu {
 public:
  /// Sizes up to this one have their own compiled kernels.
  static constexpr int kFixedSize = 8;

  /// Factorises the square matrix a.
  void compute(const Eigen::MatrixXd& a);
  int size() const { return n_; }
  /// x = A⁻¹ b (x may be b).
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  /// Every column of b, X = A⁻¹ B (X may be B).
  void solve(const Eigen::MatrixXd& b, Eigen::MatrixXd& x) const;
  /// b = A⁻ᵀ b, in place.
  void solve_transpose(Eigen::VectorXd& b) const;
  double determinant() const;
  /// The smallest pivot's magnitude over the largest's.
  double pivot_ratio() const;
  /// The estimate of the reciprocal condition number in the 1-norm of
  /// Eigen::PartialPivLU::rcond() (Higham's algorithm).
  double rcond() const;

 private:
  void solve_in_place(double* b) const;
  double inverse_norm_estimate() const;

  using Kernel = void (*)(const double* lu, const int* perm, double* b, int n);
  Kernel solve_kernel_ = nullptr;      // b = A⁻¹ b for this size (set by compute())
  Kernel transpose_kernel_ = nullptr;  // b = A⁻ᵀ b
  int n_ = 0;
  int swaps_ = 0;
  double pivot_ratio_ = 0;  // up to kFixedSize, found by compute()
  // up to kFixedSize, column-major n x n in fixed arrays (no Eigen assignment, whose size checks
  // cost as much as copying a 4 x 4)
  double a_[kFixedSize * kFixedSize]{};   // the matrix factorised, for rcond()
  double lu_[kFixedSize * kFixedSize]{};  // L below the diagonal (unit diagonal implied), U on
                                          // and above
  int perm_[kFixedSize]{};                // P, the row swaps in order
  Eigen::PartialPivLU<Eigen::MatrixXd> dynamic_;  // above kFixedSize
  mutable Eigen::VectorXd v_, sign_, old_sign_;  // rcond's scratch
};

}  // namespace bd::core::planar::detail
