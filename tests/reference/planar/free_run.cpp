// Free scenes: forward dynamics by coordinate partitioning.
//
// The independent coordinates are the inputs a (one per degree of freedom). The integrated
// state is y = (a, a', W_in, W_damp, W_app) (the last three: work quadratures). At every
// evaluation the dependent coordinates are recovered exactly:
//   positions      Newton on c(q) = 0 with the inputs held at a, to the rounding level, so
//                  there is no constraint drift at all; it starts from a second-order Taylor
//                  prediction from the previous evaluation in the same step, with simplified
//                  Newton iterations on that evaluation's factorized Jacobian (one LU per
//                  evaluation), so the branch is followed;
//   velocities     J q' = (0, a');
//   accelerations  J q'' = gamma + (0, a''), i.e. q'' = q''_0 + N a'' with q''_0 = J^-1 gamma
//                  and N = the input columns of J^-1 (J_m N = 0, J_in N = I);
//   dynamics       M q'' = Q + J_m^T lambda_m + J_in^T tau. Multiplying by N^T removes the
//                  constraint forces (N^T J_m^T = 0) and leaves (N^T J_in^T = I)
//                      (N^T M N) a'' = N^T (Q - M q''_0) + tau,
//                  a small ndof x ndof system; then lambda = J^-T (M q'' - Q), whose input
//                  rows reproduce tau.
// The ODE y' = (a', a'', P_in, P_damp, P_app) is smooth as long as the inputs are valid
// coordinates (J regular), and is integrated by GBS extrapolation (extrapolation.hpp) with the
// step landing exactly on every sample time. Error control: per component of (a, a'), the local
// error estimate <= tolerance * scale, with scale = 1 rad (angle input) or the characteristic
// length (slide input) for a -- fixed, since the mechanism's positions are what matter, not how
// many turns a crank has made -- and for a' the running maximum of |a'| over the run, at least
// the position scale divided by the duration. The whole ODE is solved in long double.
//
// Why this method: no drift and no stabilization parameters (the constraints hold to rounding
// at every evaluation), a smooth low-dimensional ODE (2 ndof + 3), and an integrator whose order
// rises to whatever the tolerance needs; the self-tests show the global error well below 1e-11
// relative at the default tolerance (1e-15) with halving and tenfold tightening of it, energy
// balances to ~1e-15 and agreement with closed forms and a fine RK4. Limitation: the inputs
// must stay valid coordinates (a slide input through a dead centre fails, with the time).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "tests/reference/planar/extrapolation.hpp"
#include "tests/reference/planar/solve.hpp"

namespace bd::referee {

using detail::Index;
using detail::MatX;
using detail::Real;
using detail::VecX;

namespace {

thread_local FreeRunStats g_stats;

std::string at_time(Real t) {
  std::ostringstream os;
  os << std::setprecision(12) << "free run at t = " << t << " s";
  return os.str();
}

// Where the next Newton solve starts: the last solution in the same step (positions,
// velocities, accelerations, time) and its factorized Jacobian, used for a second-order
// predictor and for simplified Newton iterations.
struct Guess {
  Real t = 0;
  VecX q, qd, qdd;
  std::optional<detail::Factorized> f;
};

class FreeSystem final : public detail::OdeSystem {
 public:
  FreeSystem(const detail::Model& model, const Mechanism& mech, VecX q0)
      : model_(model), mech_(mech), mass_(detail::mass_diagonal(model)) {
    base_.q = std::move(q0);
    base_.qd = base_.qdd = VecX::Zero(base_.q.size());
    work_ = base_;
  }

  void restart() override { work_ = base_; }
  VecX rhs(Real t, const VecX& y) override { return derivative(evaluate(t, y, work_, false)); }

  /// The full state at (t, y), Newton starting from the guess (updated to the solution). The
  /// constraint multipliers (not needed by the ODE) only when `multipliers`; otherwise lambda
  /// holds just the efforts.
  detail::State evaluate(Real t, const VecX& y, Guess& guess, bool multipliers) const;
  /// Evaluates at an accepted point and makes it the start of the next step.
  detail::State accept(Real t, const VecX& y) {
    Guess g = base_;
    detail::State s = evaluate(t, y, g, true);
    base_ = std::move(g);
    return s;
  }
  VecX derivative(const detail::State& s) const;

 private:
  VecX efforts(Real t) const {
    VecX tau = VecX::Zero(model_.ndof());
    for (std::size_t k = 0; k < mech_.input_efforts.size(); ++k)
      if (mech_.input_efforts[k])
        tau[static_cast<Index>(k)] = mech_.input_efforts[k](static_cast<double>(t));
    return tau;
  }

  const detail::Model& model_;
  const Mechanism& mech_;
  VecX mass_;
  Guess base_, work_;
};

detail::State FreeSystem::evaluate(Real t, const VecX& y, Guess& guess, bool multipliers) const {
  ++g_stats.evaluations;
  const Index n = model_.n(), nd = model_.ndof();
  const Real dt = t - guess.t;
  VecX q = guess.q + dt * guess.qd + (dt * dt / 2) * guess.qdd;
  const auto f =
      detail::close_loop(model_, y.head(nd), q, at_time(t), guess.f ? &*guess.f : nullptr);
  detail::State s;
  s.t = t;
  s.q = q;
  VecX rhs = VecX::Zero(n);
  rhs.tail(nd) = y.segment(nd, nd);
  s.qd = f.solve(rhs);
  MatX N(n, nd);
  for (Index k = 0; k < nd; ++k) N.col(k) = f.solve(VecX::Unit(n, model_.input_row(k)));
  const VecX qdd0 = f.solve(detail::gamma(model_, s.q, s.qd));
  const VecX Q = detail::applied_forces(model_, mech_, t, s.q, s.qd);
  const VecX tau = efforts(t);
  const MatX reduced_mass = N.transpose() * mass_.asDiagonal() * N;
  const Eigen::FullPivLU<MatX> lu(reduced_mass);
  if (!lu.isInvertible())
    throw std::domain_error("bd::referee: " + at_time(t) + ": the reduced mass is singular");
  const VecX add = lu.solve(N.transpose() * (Q - mass_.cwiseProduct(qdd0)) + tau);
  s.qdd = qdd0 + N * add;
  s.lambda = multipliers ? f.solve_transposed(mass_.cwiseProduct(s.qdd) - Q) : VecX::Zero(n);
  s.lambda.tail(nd) = tau;  // equal to rounding; report the given efforts exactly
  guess = Guess{t, s.q, s.qd, s.qdd, f};
  s.input_work = y[2 * nd];
  s.damper_work = y[2 * nd + 1];
  s.applied_work = y[2 * nd + 2];
  return s;
}

VecX FreeSystem::derivative(const detail::State& s) const {
  const Index nd = model_.ndof();
  const MatX J_in = detail::jacobian(model_, s.q).bottomRows(nd);
  const VecX rates = J_in * s.qd;
  VecX dy(2 * nd + 3);
  dy.head(nd) = rates;
  dy.segment(nd, nd) = J_in * s.qdd - detail::gamma(model_, s.q, s.qd).tail(nd);
  dy[2 * nd] = s.lambda.tail(nd).dot(rates);
  Real damp = 0, applied = 0;
  for (std::size_t k = 0; k < mech_.springs.size(); ++k) {
    const auto st = detail::spring_state(model_, mech_, k, s.q, s.qd);
    damp += mech_.springs[k].damping * st.rate * st.rate;
  }
  for (std::size_t k = 0; k < mech_.forces.size(); ++k)
    applied += detail::force_at(mech_.forces[k], s.t)
                   .dot(detail::velocity(s.q, s.qd, model_.force_points[k]));
  for (const auto& m : mech_.moments) applied += detail::moment_at(m, s.t) * s.qd[3 * m.body + 2];
  dy[2 * nd + 1] = damp;
  dy[2 * nd + 2] = applied;
  return dy;
}

// Steps the free system from sample time to sample time (see the top of this file).
class Integrator {
 public:
  Integrator(FreeSystem& sys, const detail::Model& model, const VecX& y0, Real duration, Real tol)
      : sys_(sys), nd_(model.ndof()), y_(y0), tol_(tol), duration_(duration) {
    scale_ = VecX::Zero(2 * nd_);
    for (Index k = 0; k < nd_; ++k) {
      scale_[k] = model.inputs[k].angle ? 1.0 : model.length;
      scale_[nd_ + k] = scale_[k] / duration;
    }
    state_ = sys_.accept(0, y_);
    f_ = sys_.derivative(state_);
    update_scale();
    H_ = std::min(duration / 100, branch_limit());
  }
  const detail::State& state() const { return state_; }
  void advance_to(Real target);

 private:
  // The first midpoint substep (H / 2) turns no body by more than 0.25 rad.
  Real branch_limit() const {
    Real w = 0;
    for (Index i = 2; i < state_.qd.size(); i += 3) w = std::max(w, std::abs(state_.qd[i]));
    return w > 0 ? 0.5 / w : duration_;
  }
  void update_scale() {
    scale_.tail(nd_) = scale_.tail(nd_).cwiseMax(y_.segment(nd_, nd_).cwiseAbs());
  }
  bool try_step(Real H, Real t_new, detail::StepOutcome& o, std::string& why);

  FreeSystem& sys_;
  Index nd_;
  VecX y_, f_, scale_;
  Real t_ = 0, H_ = 0, tol_, duration_;
  detail::State state_;
};

bool Integrator::try_step(Real H, Real t_new, detail::StepOutcome& o, std::string& why) {
  try {
    o = detail::gbs_step(sys_, t_, y_, f_, H, scale_, tol_);
    if (!o.converged) {
      why = "no convergence of the extrapolation";
      return false;
    }
    state_ = sys_.accept(t_new, o.y);
  } catch (const std::domain_error& e) {
    why = e.what();
    o.converged = false;
    o.error = 0;  // marks an exception: shrink by 4
    return false;
  }
  return true;
}

void Integrator::advance_to(Real target) {
  while (t_ < target) {
    const Real H = std::min({H_, target - t_, branch_limit()});
    const bool last = H == target - t_;
    const Real t_new = last ? target : t_ + H;
    detail::StepOutcome o;
    std::string why;
    if (!try_step(H, t_new, o, why)) {
      ++g_stats.rejected;
      const Real err_fac = 0.9L * std::pow(1 / o.error, 1.0L / (2 * detail::kMaxRow - 1));
      H_ = H * (o.error == 0 || !std::isfinite(err_fac) ? 0.25L : std::clamp(err_fac, 0.1L, 0.5L));
      if (!(H_ > 1e-13L * std::max(duration_, std::abs(t_))))
        throw std::domain_error("bd::referee: " + at_time(t_) +
                                ": step size underflow, the inputs may have stopped being valid "
                                "coordinates (last failure: " +
                                why + ")");
      continue;
    }
    ++g_stats.steps;
    t_ = t_new;
    y_ = o.y;
    f_ = sys_.derivative(state_);
    update_scale();
    Real fac = 0.9L * std::pow(1 / std::max(o.error, 1e-10L), 1.0L / (2 * o.row - 1));
    fac = std::clamp(fac, 0.2L, 4.0L);
    if (o.row >= detail::kMaxRow - 1) fac = std::min(fac, 0.7L);  // back to cheaper rows
    H_ = (H < H_ && fac >= 1) ? H_ : H * fac;
  }
}

}  // namespace

FreeRunStats last_free_run_stats() { return g_stats; }

std::vector<Sample> free_run(const Mechanism& mechanism, const std::vector<double>& initial_rates,
                             double duration, const std::vector<double>& times, double tolerance) {
  const detail::Model model = detail::compile(mechanism);
  const Index nd = model.ndof();
  if (static_cast<Index>(initial_rates.size()) != nd)
    throw std::domain_error("bd::referee: free_run needs one initial rate per input");
  if (!(duration > 0) || !(tolerance > 0 && tolerance < 1e-3))
    throw std::domain_error("bd::referee: free_run needs duration > 0, 0 < tolerance < 1e-3");
  for (std::size_t i = 0; i < times.size(); ++i)
    if (times[i] < 0 || times[i] > duration || (i > 0 && times[i] < times[i - 1]))
      throw std::domain_error("bd::referee: free_run: times must ascend within [0, duration]");
  g_stats = {};
  VecX q0 = detail::described_q(model);
  detail::close_loop(model, VecX::Zero(nd), q0, at_time(0));
  VecX y0 = VecX::Zero(2 * nd + 3);
  y0.segment(nd, nd) = Eigen::Map<const Eigen::VectorXd>(initial_rates.data(), nd).cast<Real>();
  FreeSystem sys(model, mechanism, q0);
  Integrator integrator(sys, model, y0, duration, tolerance);
  std::vector<Sample> out;
  for (double t : times) {
    integrator.advance_to(t);
    out.push_back(detail::make_sample(model, mechanism, integrator.state()));
  }
  return out;
}

}  // namespace bd::referee
