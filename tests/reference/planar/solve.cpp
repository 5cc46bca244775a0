// Position closure by Newton's method on the scaled, full-pivoting-LU-factorized Jacobian.
#include "tests/reference/planar/solve.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bd::referee::detail {

Factorized::Factorized(const Model& model, const MatrixXd& J)
    : dr_(VectorXd::Ones(model.n())), dc_(VectorXd::Ones(model.n())) {
  for (int i = 0; i < model.nb; ++i) dc_[3 * i + 2] = 1 / model.length;
  for (Index k = 0; k < model.ndof(); ++k)
    if (model.inputs[k].angle) dr_[model.input_row(k)] = model.length;
  scaled_ = dr_.asDiagonal() * J * dc_.asDiagonal();
  lu_.compute(scaled_);
}

double Factorized::rcond() const {
  const VectorXd pivots = lu_.matrixLU().diagonal().cwiseAbs();
  return std::min(lu_.rcond(), pivots.minCoeff() / pivots.maxCoeff());
}

VectorXd Factorized::solve(const VectorXd& b) const {
  const VectorXd scaled_b = dr_.cwiseProduct(b);
  return dc_.cwiseProduct(lu_.solve(scaled_b));
}

VectorXd Factorized::solve_transposed(const VectorXd& b) const {
  const VectorXd scaled_b = dc_.cwiseProduct(b);
  if (!lu_transposed_) lu_transposed_.emplace(scaled_.transpose());
  return dr_.cwiseProduct(lu_transposed_->solve(scaled_b));
}

namespace {

// Size of a position correction in metres (angles times the characteristic length).
double scaled_norm(const Model& model, const VectorXd& dq) {
  double out = 0;
  for (int i = 0; i < model.nb; ++i) {
    out = std::max({out, std::abs(dq[3 * i]), std::abs(dq[3 * i + 1]),
                    model.length * std::abs(dq[3 * i + 2])});
  }
  return out;
}

double scaled_residual(const Model& model, const VectorXd& c) {
  double out = 0;
  for (Index r = 0; r < model.n(); ++r) {
    const bool angle_row = r >= model.m() && model.inputs[r - model.m()].angle;
    out = std::max(out, std::abs(c[r]) * (angle_row ? model.length : 1.0));
  }
  return out;
}

[[noreturn]] void fail(const std::string& what, const std::string& why) {
  throw std::domain_error("bd::referee: " + what + ": " + why);
}

}  // namespace

Factorized close_loop(const Model& model, const VectorXd& values, VectorXd& q,
                      const std::string& what) {
  // Quadratic convergence: once a correction is below 1e-9 length the next one is at the
  // rounding level, so one more (polishing) iteration gives q to machine precision.
  const double small = 1e-9 * model.length;
  bool converged = false;
  for (int it = 0; it < 60 && !converged; ++it) {
    const Factorized f(model, jacobian(model, q));
    const VectorXd dq = f.solve(residual(model, q, values));
    if (!dq.allFinite()) break;
    q -= dq;
    if (scaled_norm(model, dq) <= small) {
      q -= f.solve(residual(model, q, values));
      converged = true;
    }
  }
  const double res = scaled_residual(model, residual(model, q, values));
  if (!converged || !(res <= 1e-11 * model.length)) {
    std::ostringstream os;
    os << "the loop cannot be closed (Newton residual " << res << " m)";
    fail(what, os.str());
  }
  Factorized f(model, jacobian(model, q));
  if (!(f.rcond() >= kSingularRcond)) {
    std::ostringstream os;
    os << "singular position (reciprocal condition " << f.rcond() << ")";
    fail(what, os.str());
  }
  return f;
}

Factorized continue_loop(const Model& model, const VectorXd& from, const VectorXd& to, VectorXd& q,
                         const std::string& what) {
  double steps = 1;
  for (Index k = 0; k < model.ndof(); ++k) {
    const double unit = model.inputs[k].angle ? 0.1 : 0.05 * model.length;
    steps = std::max(steps, std::ceil(std::abs(to[k] - from[k]) / unit));
  }
  const int count = static_cast<int>(std::min(steps, 1e6));
  for (int i = 1; i < count; ++i) {
    const double s = static_cast<double>(i) / count;
    const VectorXd values = (1 - s) * from + s * to;
    close_loop(model, values, q, what);
  }
  return close_loop(model, to, q, what);
}

}  // namespace bd::referee::detail
