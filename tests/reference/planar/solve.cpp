// Position closure by Newton's method on the scaled, full-pivoting-LU-factorized Jacobian.
#include "tests/reference/planar/solve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace bd::referee::detail {

Factorized::Factorized(const Model& model, const MatX& J)
    : dr_(VecX::Ones(model.n())), dc_(VecX::Ones(model.n())) {
  for (int i = 0; i < model.nb; ++i) dc_[3 * i + 2] = 1 / model.length;
  for (Index k = 0; k < model.ndof(); ++k)
    if (model.inputs[k].angle) dr_[model.input_row(k)] = model.length;
  scaled_ = dr_.asDiagonal() * J * dc_.asDiagonal();
  lu_.compute(scaled_);
}

Real Factorized::rcond() const {
  const VecX pivots = lu_.matrixLU().diagonal().cwiseAbs();
  return std::min(lu_.rcond(), pivots.minCoeff() / pivots.maxCoeff());
}

VecX Factorized::solve(const VecX& b) const {
  const VecX scaled_b = dr_.cwiseProduct(b);
  return dc_.cwiseProduct(lu_.solve(scaled_b));
}

VecX Factorized::solve_transposed(const VecX& b) const {
  const VecX scaled_b = dc_.cwiseProduct(b);
  if (!lu_transposed_) lu_transposed_.emplace(scaled_.transpose());
  return dr_.cwiseProduct(lu_transposed_->solve(scaled_b));
}

namespace {

// Size of a position correction in metres (angles times the characteristic length).
Real scaled_norm(const Model& model, const VecX& dq) {
  Real out = 0;
  for (int i = 0; i < model.nb; ++i) {
    out = std::max({out, std::abs(dq[3 * i]), std::abs(dq[3 * i + 1]),
                    model.length * std::abs(dq[3 * i + 2])});
  }
  return out;
}

Real scaled_residual(const Model& model, const VecX& c) {
  Real out = 0;
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

namespace {

// Simplified Newton with a Jacobian factorized near q: cheap triangular solves only, iterated to
// the rounding level (the velocities use the Jacobian at the final q, which must therefore be
// exact to rounding). Returns true when the corrections fell below 1e-18 length, or stalled at
// the rounding level below 1e-13 length; otherwise restores q and returns false.
bool chord_iterations(const Model& model, const Factorized& chord, const VecX& values, VecX& q) {
  const VecX start = q;
  Real last = std::numeric_limits<Real>::infinity();
  for (int it = 0; it < 80; ++it) {
    const VecX dq = chord.solve(residual(model, q, values));
    const Real size = scaled_norm(model, dq);
    if (!dq.allFinite()) break;
    if (size > 0.5L * last) {
      if (last <= 1e-13L * model.length) return true;  // stalled at rounding
      break;
    }
    q -= dq;
    if (size <= 1e-18L * model.length) return true;
    last = size;
  }
  q = start;
  return false;
}

}  // namespace

Factorized close_loop(const Model& model, const VecX& values, VecX& q, const std::string& what,
                      const Factorized* chord) {
  // From a nearby solution, simplified Newton with its factorization converges linearly and
  // cheaply; otherwise Newton until a correction is below 1e-10 length (quadratic convergence),
  // then simplified Newton with the last Jacobian to the rounding level.
  bool converged = chord != nullptr && chord_iterations(model, *chord, values, q);
  for (int it = 0; it < 60 && !converged; ++it) {
    const Factorized f(model, jacobian(model, q));
    const VecX dq = f.solve(residual(model, q, values));
    if (!dq.allFinite()) break;
    q -= dq;
    if (scaled_norm(model, dq) <= 1e-10L * model.length)
      converged = chord_iterations(model, f, values, q);
  }
  // a singular Jacobian (also what stalls Newton at a double root) is reported as such
  Factorized f(model, jacobian(model, q));
  if (q.allFinite() && !(f.rcond() >= kSingularRcond)) {
    std::ostringstream os;
    os << "singular position (reciprocal condition " << f.rcond() << ")";
    fail(what, os.str());
  }
  const Real res = scaled_residual(model, residual(model, q, values));
  if (!converged || !(res <= 1e-11L * model.length)) {
    std::ostringstream os;
    os << "the loop cannot be closed (Newton residual " << res << " m)";
    fail(what, os.str());
  }
  return f;
}

Factorized continue_loop(const Model& model, const VecX& from, const VecX& to, VecX& q,
                         const std::string& what) {
  Real steps = 1;
  for (Index k = 0; k < model.ndof(); ++k) {
    const Real unit = model.inputs[k].angle ? 0.1 : 0.05 * model.length;
    steps = std::max(steps, std::ceil(std::abs(to[k] - from[k]) / unit));
  }
  const int count = static_cast<int>(std::min(steps, Real(1e6)));
  for (int i = 1; i < count; ++i) {
    const Real s = static_cast<Real>(i) / count;
    const VecX values = (1 - s) * from + s * to;
    close_loop(model, values, q, what);
  }
  return close_loop(model, to, q, what);
}

}  // namespace bd::referee::detail
