#include "core/fourbar/opened_loop_dae.hpp"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/detail/free_motion.hpp"
#include "core/fourbar/energy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/opened_loop.hpp"
#include "core/input_error.hpp"
#include "core/integrators.hpp"
#include "core/number_text.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::integrator_stopped;
using detail::nonsingular_pose;
using detail::output_time;

namespace {

using Mat23 = Eigen::Matrix<double, 2, 3>;

// GGL: the six states, then lambda = RA3 [N] and the multiplier mu of the closure [1/(m s)]
constexpr int kGglStates = 10;
// Gauss-Newton iterations of one projection onto the closure; from an integrator step off the
// closure by ~tolerance, two or three reach round-off (quadratic convergence)
constexpr int kMaxProjectionIterations = 10;

// the state of the CVODE vector y = (theta1, theta2, theta3, omega1, omega2, omega3)
FourBarState state_of(const double* y) {
  FourBarState s;
  s.theta1 = y[0];
  s.theta2 = y[1];
  s.theta3 = y[2];
  s.omega1 = y[3];
  s.omega2 = y[4];
  s.omega3 = y[5];
  return s;
}

// G = ∂c/∂θ = [i l̄1, i l̄2, i l̄3] (the transpose of D of eq. 24) [m]
Mat23 closure_jacobian(const FourBar& m, const Eigen::Vector3d& theta) {
  Mat23 G;
  G.col(0) = perp(m.crank.length * unit(theta(0)));
  G.col(1) = perp(m.coupler.length * unit(theta(1)));
  G.col(2) = perp(m.rocker.length * unit(theta(2)));
  return G;
}

Vec2 closure(const FourBar& m, const Eigen::Vector3d& theta) {
  return m.crank.length * unit(theta(0)) + m.coupler.length * unit(theta(1)) +
         m.rocker.length * unit(theta(2)) - Vec2(m.frame_length, 0.0);
}

// Gᵀ (G Gᵀ)⁻¹ v: the least-norm θ-change with G δθ = v. G Gᵀ is regular unless all three links
// are parallel (the same condition as the 5x5 solve).
Eigen::Vector3d least_norm(const Mat23& G, const Vec2& v) {
  const Mat2 GGt = G * G.transpose();
  return G.transpose() * GGt.inverse() * v;
}

// What the integrator's callbacks need, and what they saw when the dynamics failed.
struct DaeMotion {
  const FourBar* model{};
  Stabilisation stabilisation{};
  double alpha{}, beta{};  // Baumgarte [1/s]
  double length_scale{};   // l1 + l2 + l3 + l4 [m], for the projection's convergence test
  long evaluations{};      // right-hand sides or residuals, and samples
  long projections{};
  bool rhs_failed{};
  DynamicsError error;
  double error_t{};
};

// closure_bias of eq. 27 for the chosen stabilisation [m/s^2]
Vec2 closure_bias(const DaeMotion& motion, const FourBarState& s) {
  if (motion.stabilisation != Stabilisation::kBaumgarte) return Vec2::Zero();
  return -2.0 * motion.alpha * closure_velocity_residual(*motion.model, s) -
         motion.beta * motion.beta * closure_position_residual(*motion.model, s);
}

int dae_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto& motion = *static_cast<DaeMotion*>(user_data);
  const FourBarState s = state_of(N_VGetArrayPointer(y));
  ++motion.evaluations;
  const auto sample = forward_dynamics_opened_loop(*motion.model, s, closure_bias(motion, s));
  if (!sample) {
    // recoverable: CVODE retries with a smaller step (ERKStep stops)
    motion.rhs_failed = true;
    motion.error = sample.error();
    motion.error_t = t;
    return 1;
  }
  double* d = N_VGetArrayPointer(ydot);
  d[0] = s.omega1;
  d[1] = s.omega2;
  d[2] = s.omega3;
  d[3] = sample->state.alpha1;
  d[4] = sample->state.alpha2;
  d[5] = sample->state.alpha3;
  return 0;
}

// Takes angles and rates onto the closure manifold: c(θ) = 0 by Gauss-Newton least-norm steps
// to round-off, then ċ = G ω = 0 by an orthogonal projection of the rates. Returns G at the
// projected angles, or nothing when the iteration does not converge. Euclidean norms: angles
// and rates carry the same absolute tolerance.
std::optional<Mat23> project_onto_closure(const FourBar& m, double length_scale,
                                          Eigen::Vector3d& theta, Eigen::Vector3d& omega) {
  // positions: θ <- θ - Gᵀ(GGᵀ)⁻¹ c(θ) until c is at round-off
  const double converged = 16 * std::numeric_limits<double>::epsilon() * length_scale;
  Vec2 c = closure(m, theta);
  for (int i = 0; i < kMaxProjectionIterations && c.norm() > converged; ++i) {
    theta -= least_norm(closure_jacobian(m, theta), c);
    c = closure(m, theta);
  }
  if (!(c.norm() <= 1e3 * converged)) return std::nullopt;
  // rates: ω <- ω - Gᵀ(GGᵀ)⁻¹ G ω
  const Mat23 G = closure_jacobian(m, theta);
  omega -= least_norm(G, G * omega);
  return G;
}

// CVODE's projection (CVodeSetProjFn, BDF only): returns in `corr` the change that takes ycur
// onto the closure manifold (project_onto_closure); the error estimate is projected onto the
// tangent space (the part normal to it is removed by the projection and must not count in the
// error test). eps_proj (CVODE's tolerance for an iterative projection) is not needed: the
// iteration runs to round-off.
int project(sunrealtype /*t*/, N_Vector ycur, N_Vector corr, sunrealtype /*eps_proj*/, N_Vector err,
            void* user_data) {
  auto& motion = *static_cast<DaeMotion*>(user_data);
  const double* y = N_VGetArrayPointer(ycur);
  Eigen::Vector3d theta(y[0], y[1], y[2]);
  Eigen::Vector3d omega(y[3], y[4], y[5]);
  ++motion.projections;
  const auto G = project_onto_closure(*motion.model, motion.length_scale, theta, omega);
  if (!G) return 1;  // recoverable: CVODE retries a smaller step

  double* dy = N_VGetArrayPointer(corr);
  for (int k = 0; k < 3; ++k) {
    dy[k] = theta(k) - y[k];
    dy[3 + k] = omega(k) - y[3 + k];
  }
  if (err != nullptr) {
    double* e = N_VGetArrayPointer(err);
    Eigen::Vector3d ep(e[0], e[1], e[2]), ev(e[3], e[4], e[5]);
    ep -= least_norm(*G, *G * ep);
    ev -= least_norm(*G, *G * ev);
    for (int k = 0; k < 3; ++k) {
      e[k] = ep(k);
      e[3 + k] = ev(k);
    }
  }
  return 0;
}

// The GGL residual (Stabilisation::kGgl) for IDA, y = (θ, ω, λ, μ):
//   θ' - ω - Gᵀμ = 0,   M ω' + C ω² + Gᵀλ - Q = 0 (eq. 22, λ = R̄A3),   c(θ) = 0,   G ω = 0,
// with M, C, D = Gᵀ, Q of the opened loop at the angles θ (closed or not). A non-finite value
// is a recoverable failure, as in dae_rhs.
int ggl_residual(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, void* user_data) {
  auto& motion = *static_cast<DaeMotion*>(user_data);
  const FourBar& m = *motion.model;
  const double* y = N_VGetArrayPointer(yy);
  const double* dy = N_VGetArrayPointer(yp);
  double* r = N_VGetArrayPointer(rr);
  const Eigen::Vector3d theta(y[0], y[1], y[2]), omega(y[3], y[4], y[5]);
  const Vec2 lambda(y[6], y[7]), mu(y[8], y[9]);
  const Eigen::Vector3d theta_dot(dy[0], dy[1], dy[2]), omega_dot(dy[3], dy[4], dy[5]);
  ++motion.evaluations;
  const OpenedLoopTerms terms = opened_loop_terms(m, Pose{theta(0), theta(1), theta(2)});
  const Mat23 G = terms.D.transpose();
  const Eigen::Vector3d kinematic = theta_dot - omega - G.transpose() * mu;
  const Eigen::Vector3d dynamic =
      terms.M * omega_dot + terms.C * omega.cwiseAbs2() + terms.D * lambda - terms.Q;
  const Vec2 position = closure(m, theta);
  const Vec2 velocity = G * omega;
  for (int k = 0; k < 3; ++k) {
    r[k] = kinematic(k);
    r[3 + k] = dynamic(k);
  }
  r[6] = position.x();
  r[7] = position.y();
  r[8] = velocity.x();
  r[9] = velocity.y();
  for (int k = 0; k < kGglStates; ++k) {
    if (!std::isfinite(r[k])) {
      motion.rhs_failed = true;
      motion.error = {DynamicsError::Kind::kNonFinite, y[0],
                      "non-finite residual of the opened loop's DAE"};
      motion.error_t = t;
      return 1;
    }
  }
  return 0;
}

void fail(Trajectory& out, const DynamicsError& error, double t) {
  out.status = status_of(error.kind);
  out.message = error.what() + " (t = " + text::digits(t, 10) + " s)";
}

void validate(const FreeScene& scene, const OpenedLoopDaeOptions& options) {
  throw_if(options.validate());
  validate_scene(scene);
}

// appends a sample with its drift, energy and branch
void record(OpenedLoopDaeResult& out, const FourBar& model, double t,
            const DynamicsSample& sample) {
  const FourBarState& s = sample.state;
  out.trajectory.t.push_back(t);
  out.trajectory.samples.push_back(sample);
  out.position_residual.push_back(closure_position_residual(model, s).norm());
  out.velocity_residual.push_back(closure_velocity_residual(model, s).norm());
  out.energy.push_back(kinetic_energy(model, s) + load_potential(model, pose_of(s)));
  out.branch.push_back(branch_of(model, s));
}

}  // namespace

const char* to_string(Stabilisation s) {
  switch (s) {
    case Stabilisation::kNone:
      return "none";
    case Stabilisation::kBaumgarte:
      return "baumgarte";
    case Stabilisation::kProjection:
      return "projection";
    case Stabilisation::kGgl:
      return "ggl";
  }
  return "?";
}

const char* to_string(DaeMethod m) {
  switch (m) {
    case DaeMethod::kAuto:
      return "auto";
    case DaeMethod::kAdams:
      return "adams";
    case DaeMethod::kBdf:
      return "bdf";
    case DaeMethod::kErk2:
      return "erk2";
    case DaeMethod::kErk3:
      return "erk3";
    case DaeMethod::kErk4:
      return "erk4";
    case DaeMethod::kErk5:
      return "erk5";
    case DaeMethod::kErk6:
      return "erk6";
    case DaeMethod::kErk8:
      return "erk8";
    case DaeMethod::kIda:
      return "ida";
  }
  return "?";
}

Problem OpenedLoopDaeOptions::validate() const {
  if (Problem problem = check_integration(tolerance, absolute_tolerance, max_steps)) {
    return problem;
  }
  if (!(baumgarte_alpha >= 0.0) || !std::isfinite(baumgarte_alpha)) {
    return FieldError{"baumgarte_alpha", -1,
                      "must be >= 0 1/s, got " + text::digits(baumgarte_alpha, 10)};
  }
  if (!(baumgarte_beta >= 0.0) || !std::isfinite(baumgarte_beta)) {
    return FieldError{"baumgarte_beta", -1,
                      "must be >= 0 1/s, got " + text::digits(baumgarte_beta, 10)};
  }
  switch (method) {
    case DaeMethod::kAuto:
    case DaeMethod::kAdams:
    case DaeMethod::kBdf:
    case DaeMethod::kErk2:
    case DaeMethod::kErk3:
    case DaeMethod::kErk4:
    case DaeMethod::kErk5:
    case DaeMethod::kErk6:
    case DaeMethod::kErk8:
    case DaeMethod::kIda:
      break;
    default:
      return FieldError{"method", -1, std::to_string(static_cast<int>(method)) + " is unknown"};
  }
  switch (stabilisation) {
    case Stabilisation::kNone:
    case Stabilisation::kBaumgarte:
      if (method == DaeMethod::kIda) {
        return FieldError{"method", -1,
                          std::string("ida needs stabilisation ggl, got ") +
                              to_string(stabilisation) +
                              ": IDA integrates the DAE in its stabilised index-2 form"};
      }
      break;
    case Stabilisation::kProjection:
      if (method != DaeMethod::kAuto && method != DaeMethod::kBdf) {
        return FieldError{"stabilisation", -1,
                          std::string("projection needs method bdf (or auto), got ") +
                              to_string(method) + ": CVODE projects only with BDF"};
      }
      break;
    case Stabilisation::kGgl:
      if (method != DaeMethod::kAuto && method != DaeMethod::kIda) {
        return FieldError{"stabilisation", -1,
                          std::string("ggl needs method ida (or auto), got ") + to_string(method) +
                              ": the GGL form is a DAE with algebraic equations"};
      }
      break;
    default:
      return FieldError{"stabilisation", -1,
                        std::to_string(static_cast<int>(stabilisation)) + " is unknown"};
  }
  return std::nullopt;
}

OpenedLoopDaeOptions opened_loop_dae_options(const SimulateOptions& options) {
  OpenedLoopDaeOptions dae;
  dae.tolerance = options.tolerance;
  dae.absolute_tolerance = options.absolute_tolerance;
  dae.max_steps = options.max_steps;
  dae.project_samples = true;
  switch (options.integrator) {
    case Integrator::kCvodeAdams:
      dae.method = DaeMethod::kAdams;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kCvodeBdf:
      dae.method = DaeMethod::kBdf;
      dae.stabilisation = Stabilisation::kProjection;
      break;
    case Integrator::kErk2:
      dae.method = DaeMethod::kErk2;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kErk3:
      dae.method = DaeMethod::kErk3;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kErk4:
      dae.method = DaeMethod::kErk4;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kErk5:
      dae.method = DaeMethod::kErk5;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kErk6:
      dae.method = DaeMethod::kErk6;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kErk8:
      dae.method = DaeMethod::kErk8;
      dae.stabilisation = Stabilisation::kBaumgarte;
      break;
    case Integrator::kIda:
      dae.method = DaeMethod::kIda;
      dae.stabilisation = Stabilisation::kGgl;
      break;
  }
  return dae;
}

Vec2 closure_position_residual(const FourBar& model, const FourBarState& s) {
  return closure(model, {s.theta1, s.theta2, s.theta3});
}

Vec2 closure_velocity_residual(const FourBar& model, const FourBarState& s) {
  return closure_jacobian(model, {s.theta1, s.theta2, s.theta3}) *
         Eigen::Vector3d(s.omega1, s.omega2, s.omega3);
}

Branch branch_of(const FourBar& model, const FourBarState& s) {
  const Vec2 A1 = model.crank.length * unit(s.theta1);
  const Vec2 A2 = A1 + model.coupler.length * unit(s.theta2);
  const Vec2 A3(model.frame_length, 0.0);
  return cross(A3 - A1, A2 - A1) >= 0.0 ? Branch::kPlus : Branch::kMinus;
}

namespace {

// the core::Integrator that runs a method (kAuto resolved before)
Integrator integrator_of(DaeMethod method) {
  switch (method) {
    case DaeMethod::kAuto:
    case DaeMethod::kAdams:
      return Integrator::kCvodeAdams;
    case DaeMethod::kBdf:
      return Integrator::kCvodeBdf;
    case DaeMethod::kErk2:
      return Integrator::kErk2;
    case DaeMethod::kErk3:
      return Integrator::kErk3;
    case DaeMethod::kErk4:
      return Integrator::kErk4;
    case DaeMethod::kErk5:
      return Integrator::kErk5;
    case DaeMethod::kErk6:
      return Integrator::kErk6;
    case DaeMethod::kErk8:
      return Integrator::kErk8;
    case DaeMethod::kIda:
      return Integrator::kIda;
  }
  return Integrator::kCvodeAdams;
}

// The method a run uses: the options' own, or for kAuto the one its stabilisation needs.
DaeMethod resolved_method(const OpenedLoopDaeOptions& options) {
  return options.method != DaeMethod::kAuto                    ? options.method
         : options.stabilisation == Stabilisation::kProjection ? DaeMethod::kBdf
         : options.stabilisation == Stabilisation::kGgl        ? DaeMethod::kIda
                                                               : DaeMethod::kAdams;
}

// room for `samples` samples and their drift, energy and branch
void reserve(OpenedLoopDaeResult& out, std::size_t samples) {
  for (auto* v : {&out.position_residual, &out.velocity_residual, &out.energy}) {
    v->reserve(samples);
  }
  out.trajectory.t.reserve(samples);
  out.trajectory.samples.reserve(samples);
  out.trajectory.steps_to.reserve(samples);
  out.branch.reserve(samples);
}

// What every integration of a run shares: its length, tolerance and step budget, and the
// callbacks' data.
integrators::Problem run_problem(const FreeScene& scene, const OpenedLoopDaeOptions& options,
                                 DaeMotion& motion) {
  integrators::Problem problem;
  problem.tolerance = options.tolerance;
  problem.t_end = scene.duration;
  problem.max_steps = options.max_steps;
  problem.user_data = &motion;
  return problem;
}

// The integration of the six states θ, ω (kNone, kBaumgarte, kProjection) from the consistent
// start: the closed pose and the rates it allows.
//
// Method. kNone and kBaumgarte: the six-state ODE is non-stiff (the eigenvalues of a slow
// oscillator, and with Baumgarte -α ± sqrt(α² - β²) ~ -10 1/s, far below 1/h at the tolerances
// used), so Adams-Moulton with a fixed-point corrector, as in core/fourbar/simulate.cpp, or an
// explicit Runge-Kutta pair. kProjection: CVODE's projection interface (CVodeSetProjFn) exists
// for BDF only, which needs a Newton corrector: dense 6x6 linear solver, difference-quotient
// Jacobian. kGgl: see ggl_problem().
integrators::Problem dae_problem(const FourBarState& start, const FreeScene& scene,
                                 const OpenedLoopDaeOptions& options, DaeMethod method,
                                 DaeMotion& motion) {
  integrators::Problem problem = run_problem(scene, options, motion);
  problem.integrator = integrator_of(method);
  problem.y0 = {start.theta1, start.theta2, start.theta3, start.omega1, start.omega2, start.omega3};
  problem.rhs = dae_rhs;
  if (options.stabilisation == Stabilisation::kProjection) problem.projection = project;
  // angles [rad], rates [rad/s]
  problem.absolute_tolerance.assign(problem.y0.size(), options.absolute_tolerance);
  return problem;
}

// kGgl: IDA (the GGL form's one method) on the ten unknowns, started from `start` and the
// consistent values of the 5x5 solve there, `first` (θ' = ω, ω' = α, λ = R̄A3, μ = 0); λ and μ
// are algebraic and take no part in the error test.
integrators::Problem ggl_problem(const FourBarState& start, const DynamicsSample& first,
                                 const FreeScene& scene, const OpenedLoopDaeOptions& options,
                                 DaeMotion& motion) {
  const FourBarState& s = first.state;
  integrators::Problem problem = run_problem(scene, options, motion);
  problem.integrator = Integrator::kIda;
  problem.y0 = {start.theta1, start.theta2,  start.theta3,  start.omega1, start.omega2,
                start.omega3, first.RA3.x(), first.RA3.y(), 0.0,          0.0};
  problem.yp0 = {s.omega1, s.omega2, s.omega3, s.alpha1, s.alpha2, s.alpha3, 0, 0, 0, 0};
  problem.differential = {true, true, true, true, true, true, false, false, false, false};
  problem.residual = ggl_residual;
  // IDA's own first step keeps |h y'| at the tolerance level (h ~ 1e-12 s at 1e-10 when the
  // linkage moves), where the Newton iteration on the index-2 system fails: the multipliers'
  // round-off grows like 1/h, and no first step is found at tight tolerances with omega1 != 0.
  // The first step of the order-1 BDF has the local error h² |θ̈| / 2: take the h that puts
  // it at the tolerance, at most 1 % of the run.
  double angle = 1.0, acceleration = 0.0;
  for (double a : {s.theta1, s.theta2, s.theta3}) angle = std::max(angle, std::abs(a));
  for (double a : {s.alpha1, s.alpha2, s.alpha3})
    acceleration = std::max(acceleration, std::abs(a));
  const double error = options.tolerance * angle + options.absolute_tolerance;
  problem.initial_step = acceleration > 0
                             ? std::min(std::sqrt(2 * error / acceleration), 0.01 * scene.duration)
                             : 0.01 * scene.duration;
  // angles [rad], rates [rad/s]
  problem.absolute_tolerance.assign(problem.y0.size(), options.absolute_tolerance);
  // The multipliers take no part in the error test; their tolerances decide when the Newton
  // iteration may stop. Their round-off grows like 1/h (μ ≈ -(α/h)(G Gᵀ)⁻¹ c at the
  // predictor; λ likewise from G ω = 0) and with the size of the angles (sin and cos of a
  // crank that has turned 100 times), so tolerances near the angles' make the iteration fail,
  // which IDA answers by smaller steps still until it gives up. λ to 1e-5 of its size (at least
  // 1 N) and μ to 1 1/(m s) let it stop in every case tried (the paper example from rest and
  // moving, the triple rocker through its limits, a double crank; tolerances 1e-3 ... 1e-12),
  // at the price of more steps than a tighter λ takes where that works.
  const double force_scale = std::max(1.0, first.RA3.norm());
  problem.absolute_tolerance[6] = problem.absolute_tolerance[7] = 1e-5 * force_scale;
  problem.absolute_tolerance[8] = problem.absolute_tolerance[9] = 1.0;
  return problem;
}

// True, with the trajectory's status and message set, when the integration stopped before
// t_out (out of steps, or failed: where the dynamics itself failed, with its error); false when
// it reached t_out.
bool stopped_short(integrators::Integration::Outcome outcome,
                   const integrators::Integration& integration, const DaeMotion& motion,
                   const OpenedLoopDaeOptions& options, Trajectory& traj) {
  using Outcome = integrators::Integration::Outcome;
  if (outcome == Outcome::kReached) return false;
  if (outcome != Outcome::kMaxSteps && motion.rhs_failed) {  // kFailed (no root function here)
    fail(traj, motion.error, motion.error_t);
    traj.message += "; integration stopped at t = " + text::digits(integration.t(), 10) + " s";
  } else {
    integrator_stopped(traj, integration, outcome, options.max_steps);
  }
  return true;
}

// The state of a sample on the closure (projected as kProjection does after every step); the
// integration goes on from its own state. The unprojected state if the projection fails (it
// cannot this close to the closure).
FourBarState on_closure(FourBarState s, DaeMotion& motion) {
  Eigen::Vector3d theta(s.theta1, s.theta2, s.theta3), omega(s.omega1, s.omega2, s.omega3);
  if (project_onto_closure(*motion.model, motion.length_scale, theta, omega)) {
    s.theta1 = theta(0);
    s.theta2 = theta(1);
    s.theta3 = theta(2);
    s.omega1 = omega(0);
    s.omega2 = omega(1);
    s.omega3 = omega(2);
    ++motion.projections;
  }
  return s;
}

}  // namespace

OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options) {
  validate(scene, options);
  // a consistent start: the closed pose on the model's branch and the rates it allows (the
  // dependent rates are undefined at a dead centre, so a start there is an error)
  const auto pose = nonsingular_pose(model, scene.theta1);
  if (!pose) {
    OpenedLoopDaeResult out;
    out.method = resolved_method(options);
    fail(out.trajectory, pose.error(), 0.0);
    return out;
  }
  return simulate_opened_loop_dae(model, solve_velocity(model, *pose, scene.omega1), scene,
                                  options);
}

OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FourBarState& start,
                                             const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options) {
  validate(scene, options);
  const auto samples = static_cast<std::size_t>(scene.samples);
  OpenedLoopDaeResult out;
  out.method = resolved_method(options);
  Trajectory& traj = out.trajectory;
  reserve(out, samples);

  DaeMotion motion;
  motion.model = &model;
  motion.stabilisation = options.stabilisation;
  motion.alpha = options.baumgarte_alpha;
  motion.beta = options.baumgarte_beta;
  motion.length_scale =
      model.crank.length + model.coupler.length + model.rocker.length + model.frame_length;
  ++motion.evaluations;
  const auto first = forward_dynamics_opened_loop(model, start, closure_bias(motion, start));
  if (!first) {
    fail(traj, first.error(), 0.0);
    traj.rhs_evaluations = motion.evaluations;
    return out;
  }
  record(out, model, 0.0, *first);
  traj.steps_to.push_back(0);

  const bool projection = options.stabilisation == Stabilisation::kProjection;
  integrators::Integration integration(
      options.stabilisation == Stabilisation::kGgl
          ? ggl_problem(start, *first, scene, options, motion)
          : dae_problem(start, scene, options, out.method, motion));
  traj.status = SimulationStatus::kCompleted;
  traj.message = "completed";
  for (std::size_t j = 1; j < samples; ++j) {
    motion.rhs_failed = false;
    // with projection, stop the steps at each output instant so that the sample is a projected
    // step end (CVODE's interpolant between projected steps is itself off the closure by the
    // local error)
    const auto outcome = integration.advance(output_time(scene, j), projection);
    if (stopped_short(outcome, integration, motion, options, traj)) break;

    const double t_reached = integration.t();
    const FourBarState s = options.project_samples && !projection
                               ? on_closure(state_of(integration.y()), motion)
                               : state_of(integration.y());
    ++motion.evaluations;
    const auto sample = forward_dynamics_opened_loop(model, s, closure_bias(motion, s));
    if (!sample) {
      fail(traj, sample.error(), t_reached);
      break;
    }
    record(out, model, t_reached, *sample);
    traj.steps_to.push_back(integration.steps());
  }

  traj.steps = integration.steps();
  traj.rhs_evaluations = motion.evaluations;
  out.projections = motion.projections;
  return out;
}

}  // namespace bd::core
