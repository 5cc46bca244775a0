#include "core/opened_loop_dae.hpp"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <cvode/cvode_proj.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/energy.hpp"
#include "core/formulation_support.hpp"
#include "core/input_error.hpp"
#include "core/cvode_support.hpp"
#include "core/kinematics.hpp"
#include "core/opened_loop.hpp"

namespace bd::core {

namespace {

using Mat23 = Eigen::Matrix<double, 2, 3>;

constexpr int kStates = 6;  // theta1..3 [rad], omega1..3 [rad/s]
// Gauss-Newton iterations of one projection onto the closure; from an integrator step off the
// closure by ~tolerance, two or three reach round-off (quadratic convergence)
constexpr int kMaxProjectionIterations = 10;

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

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

// What the CVODE callbacks need, and what they saw when the dynamics failed.
struct DaeMotion {
  const FourBar* model{};
  Stabilisation stabilisation{};
  double alpha{}, beta{};  // Baumgarte [1/s]
  double length_scale{};   // l1 + l2 + l3 + l4 [m], for the projection's convergence test
  long evaluations{};
  long projections{};
  bool rhs_failed{};
  DynamicsError error;
  double error_t{};
  std::string cvode_text;
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
    // recoverable: CVODE retries with a smaller step
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

// CVODE's projection (CVodeSetProjFn, BDF only): returns in `corr` the change that takes ycur
// onto the closure manifold, c(θ) = 0 by Gauss-Newton least-norm steps, then ċ = G ω = 0 by an
// orthogonal projection of the rates; the error estimate is projected onto the tangent space
// (the part normal to it is removed by the projection and must not count in the error test).
// Euclidean norms: angles and rates carry the same absolute tolerance. eps_proj (CVODE's
// tolerance for an iterative projection) is not needed: the iteration runs to round-off.
int project(sunrealtype /*t*/, N_Vector ycur, N_Vector corr, sunrealtype /*eps_proj*/, N_Vector err,
            void* user_data) {
  auto& motion = *static_cast<DaeMotion*>(user_data);
  const FourBar& m = *motion.model;
  const double* y = N_VGetArrayPointer(ycur);
  Eigen::Vector3d theta(y[0], y[1], y[2]);
  Eigen::Vector3d omega(y[3], y[4], y[5]);
  ++motion.projections;

  // positions: θ <- θ - Gᵀ(GGᵀ)⁻¹ c(θ) until c is at round-off
  const double converged = 16 * std::numeric_limits<double>::epsilon() * motion.length_scale;
  Vec2 c = closure(m, theta);
  for (int i = 0; i < kMaxProjectionIterations && c.norm() > converged; ++i) {
    theta -= least_norm(closure_jacobian(m, theta), c);
    c = closure(m, theta);
  }
  if (!(c.norm() <= 1e3 * converged)) return 1;  // recoverable: CVODE retries a smaller step

  // rates: ω <- ω - Gᵀ(GGᵀ)⁻¹ G ω
  const Mat23 G = closure_jacobian(m, theta);
  omega -= least_norm(G, G * omega);

  double* dy = N_VGetArrayPointer(corr);
  for (int k = 0; k < 3; ++k) {
    dy[k] = theta(k) - y[k];
    dy[3 + k] = omega(k) - y[3 + k];
  }
  if (err != nullptr) {
    double* e = N_VGetArrayPointer(err);
    Eigen::Vector3d ep(e[0], e[1], e[2]), ev(e[3], e[4], e[5]);
    ep -= least_norm(G, G * ep);
    ev -= least_norm(G, G * ev);
    for (int k = 0; k < 3; ++k) {
      e[k] = ep(k);
      e[3 + k] = ev(k);
    }
  }
  return 0;
}

void fail(Trajectory& out, const DynamicsError& error, double t) {
  out.status = status_of(error.kind);
  out.message = error.what() + " (t = " + number(t) + " s)";
}

void validate(const FreeScene& scene, const OpenedLoopDaeOptions& options) {
  if (const std::string problem = options.validate(); !problem.empty()) throw InputError(problem);
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
  }
  return "?";
}

std::string OpenedLoopDaeOptions::validate() const {
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    return "tolerance must be > 0 and < 1, got " + number(tolerance);
  }
  if (!(absolute_tolerance > 0.0) || !std::isfinite(absolute_tolerance)) {
    return "absolute_tolerance must be > 0, got " + number(absolute_tolerance);
  }
  if (max_steps < 1) return "max_steps must be >= 1, got " + std::to_string(max_steps);
  if (!(baumgarte_alpha >= 0.0) || !std::isfinite(baumgarte_alpha)) {
    return "baumgarte_alpha must be >= 0 1/s, got " + number(baumgarte_alpha);
  }
  if (!(baumgarte_beta >= 0.0) || !std::isfinite(baumgarte_beta)) {
    return "baumgarte_beta must be >= 0 1/s, got " + number(baumgarte_beta);
  }
  switch (stabilisation) {
    case Stabilisation::kNone:
    case Stabilisation::kBaumgarte:
      break;
    case Stabilisation::kProjection:
      if (method == DaeMethod::kAdams) {
        return "stabilisation projection needs method bdf (or auto): CVODE projects only with "
               "BDF";
      }
      break;
    default:
      return "stabilisation " + std::to_string(static_cast<int>(stabilisation)) + " is unknown";
  }
  switch (method) {
    case DaeMethod::kAuto:
    case DaeMethod::kAdams:
    case DaeMethod::kBdf:
      break;
    default:
      return "method " + std::to_string(static_cast<int>(method)) + " is unknown";
  }
  return {};
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

OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options) {
  validate(scene, options);
  const auto samples = static_cast<std::size_t>(scene.samples);
  OpenedLoopDaeResult out;
  out.method = options.method != DaeMethod::kAuto                    ? options.method
               : options.stabilisation == Stabilisation::kProjection ? DaeMethod::kBdf
                                                                     : DaeMethod::kAdams;
  Trajectory& traj = out.trajectory;
  for (auto* v : {&out.position_residual, &out.velocity_residual, &out.energy}) {
    v->reserve(samples);
  }
  traj.t.reserve(samples);
  traj.samples.reserve(samples);
  out.branch.reserve(samples);

  DaeMotion motion;
  motion.model = &model;
  motion.stabilisation = options.stabilisation;
  motion.alpha = options.baumgarte_alpha;
  motion.beta = options.baumgarte_beta;
  motion.length_scale =
      model.crank.length + model.coupler.length + model.rocker.length + model.frame_length;

  // a consistent start: the closed pose on the model's branch and the rates it allows (the
  // dependent rates are undefined at a dead centre, so a start there is an error)
  const auto pose = nonsingular_pose(model, scene.theta1);
  if (!pose) {
    fail(traj, pose.error(), 0.0);
    return out;
  }
  const FourBarState start = solve_velocity(model, *pose, scene.omega1);
  ++motion.evaluations;
  const auto first = forward_dynamics_opened_loop(model, start, closure_bias(motion, start));
  if (!first) {
    fail(traj, first.error(), 0.0);
    traj.rhs_evaluations = motion.evaluations;
    return out;
  }
  record(out, model, 0.0, *first);

  // Method. kNone and kBaumgarte: the six-state ODE is non-stiff (the eigenvalues of a slow
  // oscillator, and with Baumgarte -α ± sqrt(α² - β²) ~ -10 1/s, far below 1/h at the tolerances
  // used), so Adams-Moulton with a fixed-point corrector, as in core/simulate.cpp. kProjection:
  // CVODE's projection interface (CVodeSetProjFn) exists for BDF only, which needs a Newton
  // corrector: dense 6x6 linear solver, difference-quotient Jacobian.
  const bool bdf = out.method == DaeMethod::kBdf;
  cvode::Session cv;
  cvode::check_setup(SUNContext_Create(nullptr, &cv.context), "SUNContext_Create");
  cv.y = N_VNew_Serial(kStates, cv.context);
  cv.atol = N_VNew_Serial(kStates, cv.context);
  if (cv.y == nullptr || cv.atol == nullptr) cvode::check_setup(CV_MEM_FAIL, "N_VNew_Serial");
  double* y = N_VGetArrayPointer(cv.y);
  y[0] = start.theta1;
  y[1] = start.theta2;
  y[2] = start.theta3;
  y[3] = start.omega1;
  y[4] = start.omega2;
  y[5] = start.omega3;
  N_VConst(options.absolute_tolerance, cv.atol);
  cv.memory = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, cv.context);
  if (cv.memory == nullptr) cvode::check_setup(CV_MEM_FAIL, "CVodeCreate");
  cvode::check_setup(CVodeSetErrHandlerFn(cv.memory, cvode::keep_error, &motion.cvode_text), "CVodeSetErrHandlerFn");
  cvode::check_setup(CVodeInit(cv.memory, dae_rhs, 0.0, cv.y), "CVodeInit");
  cvode::check_setup(CVodeSetUserData(cv.memory, &motion), "CVodeSetUserData");
  cvode::check_setup(CVodeSVtolerances(cv.memory, options.tolerance, cv.atol), "CVodeSVtolerances");
  if (bdf) {
    cv.matrix = SUNDenseMatrix(kStates, kStates, cv.context);
    if (cv.matrix == nullptr) cvode::check_setup(CV_MEM_FAIL, "SUNDenseMatrix");
    cv.linear = SUNLinSol_Dense(cv.y, cv.matrix, cv.context);
    if (cv.linear == nullptr) cvode::check_setup(CV_MEM_FAIL, "SUNLinSol_Dense");
    cvode::check_setup(CVodeSetLinearSolver(cv.memory, cv.linear, cv.matrix), "CVodeSetLinearSolver");
  } else {
    cv.nonlinear = SUNNonlinSol_FixedPoint(cv.y, 0, cv.context);
    if (cv.nonlinear == nullptr) cvode::check_setup(CV_MEM_FAIL, "SUNNonlinSol_FixedPoint");
    cvode::check_setup(CVodeSetNonlinearSolver(cv.memory, cv.nonlinear), "CVodeSetNonlinearSolver");
  }
  const bool projection = options.stabilisation == Stabilisation::kProjection;
  if (projection) cvode::check_setup(CVodeSetProjFn(cv.memory, project), "CVodeSetProjFn");
  cvode::check_setup(CVodeSetStopTime(cv.memory, scene.duration), "CVodeSetStopTime");

  traj.status = SimulationStatus::kCompleted;
  traj.message = "completed";
  const double last = static_cast<double>(samples - 1);
  for (std::size_t j = 1; j < samples; ++j) {
    const double t_out =
        j + 1 == samples ? scene.duration : scene.duration * static_cast<double>(j) / last;
    long steps = 0;
    CVodeGetNumSteps(cv.memory, &steps);
    if (steps >= options.max_steps) {
      traj.status = SimulationStatus::kIntegratorFailed;
      traj.message = "integrator stopped at t = " + number(traj.t.back()) +
                     " s: max_steps = " + std::to_string(options.max_steps) + " reached";
      break;
    }
    CVodeSetMaxNumSteps(cv.memory, options.max_steps - steps);
    // with projection, stop the steps at each output instant so that the sample is a projected
    // step end (CVODE's interpolant between projected steps is itself off the closure by the
    // local error)
    if (projection) CVodeSetStopTime(cv.memory, t_out);

    motion.rhs_failed = false;
    sunrealtype t_reached = 0.0;
    const int flag = CVode(cv.memory, t_out, cv.y, &t_reached, CV_NORMAL);
    if (flag < 0) {
      if (motion.rhs_failed) {
        fail(traj, motion.error, motion.error_t);
        traj.message += "; integration stopped at t = " + number(t_reached) + " s";
      } else {
        char* flag_name = CVodeGetReturnFlagName(flag);  // mallocs its result
        traj.status = SimulationStatus::kIntegratorFailed;
        traj.message = "integrator failed at t = " + number(t_reached) +
                       " s, theta1 = " + number(y[0]) + " rad: " + flag_name + ": " +
                       motion.cvode_text;
        std::free(flag_name);
      }
      break;
    }

    const FourBarState s = state_of(y);
    ++motion.evaluations;
    const auto sample = forward_dynamics_opened_loop(model, s, closure_bias(motion, s));
    if (!sample) {
      fail(traj, sample.error(), t_reached);
      break;
    }
    record(out, model, t_reached, *sample);
  }

  CVodeGetNumSteps(cv.memory, &traj.steps);
  traj.rhs_evaluations = motion.evaluations;
  out.projections = motion.projections;
  return out;
}

}  // namespace bd::core
