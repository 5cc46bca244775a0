#include "core/fourbar/simulate.hpp"

#include <fmt/printf.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "core/fourbar/counter_rotation.hpp"
#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/detail/free_motion.hpp"
#include "core/fourbar/detail/instant_dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/opened_loop.hpp"
#include "core/fourbar/opened_loop_dae.hpp"
#include "core/input_error.hpp"
#include "core/integrators.hpp"
#include "core/number_text.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::close_instant;
using detail::ClosedInstant;
using detail::CrankInput;
using detail::CrankSweep;
using detail::derived_outputs_at;
using detail::dynamics_at;
using detail::dynamics_constants;
using detail::DynamicsConstants;
using detail::Failure;
using detail::integrator_stopped;
using detail::output_time;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Largest crank step [rad] over which a dependent angle is unwrapped in one go; longer steps
// between samples are walked through intermediate positions (see continue_angles).
constexpr double kMaxUnwrapStep = 0.2;

// |sin(theta3 - theta2)| at which a free motion is taken to have reached a limit (dead-centre)
// position of the crank, where coupler and rocker align. Near such a limit the crank angle is
// within x ~ sin² of it, the transfer functions grow like 1/sin and the crank ODE loses its
// Lipschitz continuity: the exact motion reaches the limit in finite time with omega1 ~ sqrt(x)
// -> 0, and (limit, 0) is a spurious equilibrium towards which the integrator, having lost the
// little kinetic energy left there to its absolute tolerance, creeps for ever, while the real
// linkage passes on to the other branch. So the run stops where |sin| falls to this level
// (located by CVODE's root finding), just before the dynamics itself refuses to answer
// (kSingularSin, below which its values could not be vouched for): the crank is then within
// ~1e-6 rad of its limit. The right-hand side refuses points deeper inside, so no step is
// taken there. The opened-loop DAE (Formulation::kOpenedLoop) passes such limits instead.
constexpr double kDeadCentreSin = 2 * kSingularSin;

// Upper bound on the number of samples of one run, so the size arithmetic cannot overflow.
constexpr long long kMaxSamples = 100'000'000;

// The representative of `wrapped` (mod 2π) nearest to `reference`.
double nearest_turn(double wrapped, double reference) {
  return wrapped + kTwoPi * std::round((reference - wrapped) / kTwoPi);
}

// Makes theta2, theta3 of `next` (in (-π, π] from the kinematics) continue those of `prev`.
// On its branch θ2 and θ3 are continuous functions of θ1, so their continuous values at
// next.theta1 follow from walking θ1 from prev.theta1 to next.theta1, whatever path θ1 took in
// time. Samples closer than kMaxUnwrapStep in θ1 (the usual case) need no extra work: θ2, θ3 then
// change by far less than π. Longer steps (few samples per revolution) are walked through
// intermediate positions. Allocates nothing.
void continue_angles(const FourBar& model, const FourBarState& prev, FourBarState& next) {
  double theta2 = prev.theta2, theta3 = prev.theta3;
  const double step = next.theta1 - prev.theta1;
  const int n = static_cast<int>(std::ceil(std::abs(step) / kMaxUnwrapStep));
  for (int i = 1; i < n; ++i) {
    const auto pose = solve_position(model, prev.theta1 + step * i / n);
    if (!pose) break;  // cannot happen on a path the motion went through; fall back to nearest
    theta2 = nearest_turn(pose->theta2, theta2);
    theta3 = nearest_turn(pose->theta3, theta3);
  }
  next.theta2 = nearest_turn(next.theta2, theta2);
  next.theta3 = nearest_turn(next.theta3, theta3);
}

// One line naming the condition, the time and the crank angle, e.g.
// "singular position at t = 1.234 s, theta1 = 2.345 rad: sin(theta3 - theta2) = 1e-17".
std::string failure_message(const DynamicsError& error, double t, double theta1) {
  const char* what = error.kind == DynamicsError::Kind::kAssembly   ? "loop cannot close"
                     : error.kind == DynamicsError::Kind::kSingular ? "singular position"
                                                                    : "non-finite dynamics";
  // an assembly error's detail repeats "loop cannot close at theta1 = ...: "; keep its reason
  std::string_view detail = error.detail;
  if (error.kind == DynamicsError::Kind::kAssembly) {
    if (const auto colon = detail.find(": "); colon != std::string_view::npos) {
      detail.remove_prefix(colon + 2);
    }
  }
  std::string message = what;
  message += " at t = " + text::digits(t, 10) + " s, theta1 = " + text::digits(theta1, 10) + " rad";
  if (!detail.empty()) {
    message += ": ";
    message += detail;
  }
  return message;
}

// The error for a crank at a limit position, coupler and rocker aligned to sin_mu.
DynamicsError dead_centre_error(double theta1, double sin_mu) {
  const std::string detail = fmt::sprintf(
      "sin(theta3 - theta2) = %.3g: coupler and rocker aligned, the crank has reached a "
      "limit position",
      sin_mu);
  return {DynamicsError::Kind::kSingular, theta1, detail};
}

// True, with the error, when the coupler and rocker of a sample are aligned to within `limit`.
bool at_dead_centre(const DynamicsSample& sample, double limit, DynamicsError& error) {
  const double sin_mu = std::sin(sample.state.theta3 - sample.state.theta2);
  if (std::abs(sin_mu) >= limit) return false;
  error = dead_centre_error(sample.state.theta1, sin_mu);
  return true;
}

void fail(Trajectory& out, const DynamicsError& error, double t, double theta1) {
  out.status = status_of(error.kind);
  out.message = failure_message(error, t, theta1);
}

// What the integrator's right-hand side needs, and what it saw when the dynamics failed.
struct FreeMotion {
  const FourBar* model{};
  DynamicsConstants constants;  // of *model
  Formulation formulation{};
  // with forward sensitivities: the links' parameters the right-hand side takes (CVODES
  // perturbs them in place), replacing those of *model
  const double* link_parameters{};
  long evaluations{};     // forward_dynamics calls (right-hand side and samples)
  bool rhs_failed{};      // a right-hand side failed since the last reset
  DynamicsError error;    // the latest failure of the dynamics
  double error_t{};       // its time [s]
  double error_theta1{};  // its crank angle [rad]
};

// y = (theta1, omega1), y' = (omega1, alpha1(theta1, omega1)). A failure of the dynamics is
// recoverable (1): CVODE then retries with a smaller step, and reports failure if it cannot;
// ERKStep (SUNDIALS 6.4) stops.
int free_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto& motion = *static_cast<FreeMotion*>(user_data);
  const double* x = N_VGetArrayPointer(y);
  const double theta1 = x[0], omega1 = x[1];
  ++motion.evaluations;
  auto sample = [&] {
    if (motion.link_parameters == nullptr) {
      return detail::forward_dynamics(*motion.model, motion.constants, theta1, omega1,
                                      motion.formulation);
    }
    const FourBar model = detail::with_link_parameters(*motion.model, motion.link_parameters);
    return forward_dynamics(model, theta1, omega1, motion.formulation);
  }();
  if (!sample || at_dead_centre(*sample, 0.1 * kDeadCentreSin, motion.error)) {
    motion.rhs_failed = true;
    if (!sample) motion.error = sample.error();
    motion.error_t = t;
    motion.error_theta1 = theta1;
    return 1;
  }
  double* d = N_VGetArrayPointer(ydot);
  d[0] = omega1;
  d[1] = sample->state.alpha1;
  return 0;
}

// g = |sin(theta3 - theta2)| - kDeadCentreSin: a root is the crank reaching a limit position.
int dead_centre_root(sunrealtype /*t*/, N_Vector y, sunrealtype* g, void* user_data) {
  const auto& motion = *static_cast<const FreeMotion*>(user_data);
  const auto pose = solve_position(*motion.model, N_VGetArrayPointer(y)[0]);
  g[0] = pose ? std::abs(std::sin(pose->theta3 - pose->theta2)) - kDeadCentreSin
              : -kDeadCentreSin;  // beyond the limit (only on an interpolated point)
  return 0;
}

// rejects the input: `field` is wrong as `message` says
[[noreturn]] void reject(std::string field, std::string message) {
  throw InputError(FieldError{std::move(field), -1, std::move(message)});
}

void validate(const FreeScene& scene, const SimulateOptions& options) {
  throw_if(options.validate());
  validate_scene(scene);
}

void validate(const DrivenScene& scene, const SimulateOptions& options) {
  throw_if(options.validate());
  if (!std::isfinite(scene.theta1)) {
    reject("scene.theta1", "must be finite, got " + text::digits(scene.theta1, 10));
  }
  if (!(scene.omega1 != 0.0) || !std::isfinite(scene.omega1)) {
    reject("scene.omega1", "must be finite and != 0 rad/s, got " + text::digits(scene.omega1, 10));
  }
  if (scene.revolutions < 1) {
    reject("scene.revolutions", "must be >= 1, got " + std::to_string(scene.revolutions));
  }
  if (scene.samples < 1) {
    reject("scene.samples", "must be >= 1, got " + std::to_string(scene.samples));
  }
  if (static_cast<long long>(scene.revolutions) * scene.samples > kMaxSamples) {
    // two fields together: the scene as a whole
    reject("", "scene.revolutions * scene.samples must be <= 1e8, got " +
                   std::to_string(static_cast<long long>(scene.revolutions) * scene.samples));
  }
}

}  // namespace

Problem SimulateOptions::validate() const {
  if (Problem problem = check_integration(tolerance, absolute_tolerance, max_steps)) {
    return problem;
  }
  switch (formulation) {
    case Formulation::kMassMatrix:
    case Formulation::kOpenedLoop:
    case Formulation::kComplexMasses:
      break;
    default:
      return FieldError{"formulation", -1,
                        std::to_string(static_cast<int>(formulation)) + " is unknown"};
  }
  switch (integrator) {
    case Integrator::kCvodeAdams:
    case Integrator::kCvodeBdf:
    case Integrator::kErk2:
    case Integrator::kErk3:
    case Integrator::kErk4:
    case Integrator::kErk5:
    case Integrator::kErk6:
    case Integrator::kErk8:
      break;
    case Integrator::kIda:
      if (formulation != Formulation::kOpenedLoop) {
        return FieldError{"integrator", -1,
                          std::string("ida needs formulation opened-loop, got ") +
                              to_string(formulation) +
                              ": IDA integrates the opened loop's DAE, while this formulation "
                              "is an ODE in theta1 (use cvode-adams, cvode-bdf or erk2 ... erk8)"};
      }
      break;
    default:
      return FieldError{"integrator", -1,
                        std::to_string(static_cast<int>(integrator)) + " is unknown"};
  }
  return std::nullopt;
}

SimulationStatus status_of(DynamicsError::Kind kind) {
  switch (kind) {
    case DynamicsError::Kind::kAssembly:
      return SimulationStatus::kAssemblyFailed;
    case DynamicsError::Kind::kSingular:
      return SimulationStatus::kSingular;
    case DynamicsError::Kind::kNonFinite:
      return SimulationStatus::kIntegratorFailed;
  }
  return SimulationStatus::kIntegratorFailed;
}

void validate_scene(const FreeScene& scene) {
  if (!std::isfinite(scene.theta1)) {
    reject("scene.theta1", "must be finite, got " + text::digits(scene.theta1, 10));
  }
  if (!std::isfinite(scene.omega1)) {
    reject("scene.omega1", "must be finite, got " + text::digits(scene.omega1, 10));
  }
  if (!(scene.duration > 0.0) || !std::isfinite(scene.duration)) {
    reject("scene.duration", "must be > 0 s, got " + text::digits(scene.duration, 10));
  }
  if (scene.samples < 2 || scene.samples > kMaxSamples) {
    reject("scene.samples", "must be >= 2 (and <= 1e8), got " + std::to_string(scene.samples));
  }
}

namespace {

// Formulation::kOpenedLoop: the opened loop's own form, the DAE in theta1..theta3, kept on the
// loop closure as the integrator allows (opened_loop_dae_options); it has no singularity at a
// crank limit position and passes through it.
// `from`: the state at t = 0 instead of the scene's theta1 and omega1 (free_sample_from()).
Trajectory simulate_free_opened_loop(const FourBar& model, const FreeScene& scene,
                                     const SimulateOptions& options,
                                     const FourBarState* from = nullptr) {
  const OpenedLoopDaeOptions dae = opened_loop_dae_options(options);
  auto run = [&](const FourBar& m) {
    return from ? simulate_opened_loop_dae(m, *from, scene, dae).trajectory
                : simulate_opened_loop_dae(m, scene, dae).trajectory;
  };
  if (!has_counter_rotations(model)) {
    Trajectory out = run(model);
    for (DynamicsSample& s : out.samples) set_derived_outputs(model, s);
    return out;
  }
  // discs: the motion from the equations with I_k + J_k, then each sample's reactions from the
  // bare linkage loaded by the mesh forces at the sample's own state
  // (core/fourbar/counter_rotation.hpp)
  Trajectory out = run(with_disc_inertia(model));
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    const FourBarState& s = out.samples[i].state;
    const MeshForces f = mesh_forces(model, s);
    const auto bare = forward_dynamics_opened_loop(with_mesh_loads(model, s, f), s);
    if (!bare) {  // cannot happen where the DAE itself evaluated; keep what came before
      fail(out, bare.error(), out.t[i], s.theta1);
      out.t.resize(i);
      out.samples.resize(i);
      break;
    }
    out.samples[i] = with_shaft_reactions(model, *bare, f);
  }
  for (DynamicsSample& s : out.samples) set_derived_outputs(model, s);
  return out;
}

// The integration of the reduced equation y = (theta1, omega1) from the scene's start.
//
// Method: options.integrator (docs/performance.md compares them). The crank equation is a
// smooth, non-stiff ODE of two states (its Jacobian has the eigenvalues of a slow oscillator,
// |lambda| ~ |omega1| + sqrt|d alpha1/d theta1|), solved at tight tolerances (1e-10): the
// default, variable-order Adams-Moulton (orders 1-12) with a fixed-point corrector, reaches
// them with few steps and no Jacobian; BDF (orders <= 5, Newton) and the explicit
// Runge-Kutta pairs are there to be compared. Every one of them locates a dead centre by
// root finding on |sin(theta3 - theta2)|, registered only where the coupler and rocker can
// align: in a crank-rocker or double crank |A1A3| stays strictly between |l2 - l3| and
// l2 + l3 at every crank angle, and there the root checks would only cost (an ERK pair's
// Hermite dense output evaluates the dynamics for each check).
integrators::Problem reduced_problem(const FourBar& model, const FreeScene& scene,
                                     const SimulateOptions& options, FreeMotion& motion) {
  integrators::Problem problem;
  problem.integrator = options.integrator;
  problem.y0 = {scene.theta1, scene.omega1};
  problem.absolute_tolerance = {options.absolute_tolerance,   // theta1 [rad]
                                options.absolute_tolerance};  // omega1 [rad/s]
  problem.tolerance = options.tolerance;
  problem.t_end = scene.duration;
  problem.max_steps = options.max_steps;
  problem.user_data = &motion;
  problem.rhs = free_rhs;
  const GrashofClass grashof = classify_grashof(model);
  if (grashof != GrashofClass::kCrankRocker && grashof != GrashofClass::kDoubleCrank) {
    problem.root = dead_centre_root;
  }
  return problem;
}

// A free run that stops short of its end: where the integration had reached (past the last
// sample), and the motion there where the dynamics still vouches for its values (down to
// kSingularSin, past the limit test's kDeadCentreSin): the end of its peaks' search.
void keep_stop(const FourBar& model, const SimulateOptions& options,
               const integrators::Integration& integration, Trajectory& out) {
  out.stop_time = integration.t();
  if (out.t.empty() || !(out.stop_time > out.t.back())) return;
  auto sample =
      forward_dynamics(model, integration.y()[0], integration.y()[1], options.formulation);
  DynamicsError error;
  if (!sample || at_dead_centre(*sample, kSingularSin, error)) return;
  continue_angles(model, out.samples.back().state, sample->state);
  out.stop = *sample;
}

// True, with the trajectory's status and message set, when the integration stopped before
// t_out: out of steps, failed, or at a limit position found by the root function; false when it
// reached t_out (the state there is the next sample's).
bool stopped_short(integrators::Integration::Outcome outcome,
                   const integrators::Integration& integration, const FreeMotion& motion,
                   const SimulateOptions& options, Trajectory& out) {
  using Outcome = integrators::Integration::Outcome;
  const double t_reached = integration.t();
  const double theta1 = integration.y()[0];
  switch (outcome) {
    case Outcome::kReached:
      return false;
    case Outcome::kMaxSteps:
      integrator_stopped(out, integration, outcome, options.max_steps);
      return true;
    case Outcome::kFailed:
      if (motion.rhs_failed && motion.error.kind != DynamicsError::Kind::kNonFinite) {
        // a trial step went into a dead centre or beyond it, where the loop cannot close, and
        // the integrator could not step around it (ERKStep cannot retry): in free motion from
        // an assembled start that is the crank reaching a limit position
        out.status = SimulationStatus::kSingular;
        out.message = "limit position reached after t = " + text::digits(t_reached, 10) +
                      " s, theta1 = " + text::digits(theta1, 10) +
                      " rad: the crank reaches a limit position within the integrator's next "
                      "step (a trial step found: " +
                      motion.error.what() + ")";
      } else if (motion.rhs_failed) {
        // the dynamics failed ahead of the last step and the integrator could not step around it
        fail(out, motion.error, motion.error_t, motion.error_theta1);
        out.message += "; integration stopped at t = " + text::digits(t_reached, 10) + " s";
      } else {
        integrator_stopped(out, integration, outcome, options.max_steps);
      }
      return true;
    case Outcome::kRoot: {
      // the crank reached a limit position before t_out: stop there
      const auto pose = solve_position(*motion.model, theta1);
      const double sin_mu = pose ? std::sin(pose->theta3 - pose->theta2) : 0.0;
      fail(out, dead_centre_error(theta1, sin_mu), t_reached, theta1);
      return true;
    }
  }
  return true;
}

}  // namespace

Trajectory simulate_free(const FourBar& model, const FreeScene& scene,
                         const SimulateOptions& options) {
  validate(scene, options);
  if (options.formulation == Formulation::kOpenedLoop) {
    return simulate_free_opened_loop(model, scene, options);
  }
  return detail::simulate_free_reduced(model, scene, options, nullptr);
}

std::optional<DynamicsSample> free_sample_from(const FourBar& model, const SimulateOptions& options,
                                               double t0, const DynamicsSample& from, double t) {
  if (t == t0) return from;
  if (!(t > t0)) return std::nullopt;
  FreeScene step;
  step.theta1 = from.state.theta1;
  step.omega1 = from.state.omega1;
  step.duration = t - t0;
  step.samples = 2;
  Trajectory to = options.formulation == Formulation::kOpenedLoop
                      ? simulate_free_opened_loop(model, step, options, &from.state)
                      : detail::simulate_free_reduced(model, step, options, nullptr);
  if (!to.ok() || to.samples.size() != 2) return std::nullopt;
  DynamicsSample s = to.samples.back();
  continue_angles(model, from.state, s.state);
  return s;
}

Trajectory detail::simulate_free_reduced(const FourBar& model, const FreeScene& scene,
                                         const SimulateOptions& options,
                                         StateSensitivities* sensitivities) {
  const auto samples = static_cast<std::size_t>(scene.samples);
  Trajectory out;
  out.t.reserve(samples);
  out.samples.reserve(samples);
  out.steps_to.reserve(samples);

  FreeMotion motion;
  motion.model = &model;
  motion.constants = dynamics_constants(model);
  motion.formulation = options.formulation;

  // the initial sample; a start outside the workspace or on a singular position stops here
  ++motion.evaluations;
  auto first = forward_dynamics(model, scene.theta1, scene.omega1, options.formulation);
  if (!first || at_dead_centre(*first, kDeadCentreSin, motion.error)) {
    fail(out, first ? motion.error : first.error(), 0.0, scene.theta1);
    out.rhs_evaluations = motion.evaluations;
    return out;
  }
  out.t.push_back(0.0);
  out.samples.push_back(*first);
  out.steps_to.push_back(0);

  // each output by the integrator's dense output, then the dynamics at that state
  integrators::Problem problem = reduced_problem(model, scene, options, motion);
  if (sensitivities != nullptr) {
    sensitivities->parameters = link_parameters(model);
    motion.link_parameters = sensitivities->parameters.data();
    problem.sensitivities = {sensitivities->parameters.data(),
                             sensitivities->which,
                             sensitivities->scales,
                             sensitivities->tolerance,
                             {}};
    std::vector<Vec2> s0 = sensitivities->initial;
    if (s0.empty()) s0.assign(sensitivities->which.size(), Vec2::Zero());
    for (const Vec2& s : sensitivities->initial) {
      problem.sensitivities.initial.push_back({s.x(), s.y()});
    }
    sensitivities->state.assign(1, s0);
  }
  integrators::Integration integration(problem);
  out.status = SimulationStatus::kCompleted;
  out.message = "completed";
  for (std::size_t j = 1; j < samples; ++j) {
    motion.rhs_failed = false;
    const auto outcome = integration.advance(output_time(scene, j));
    if (stopped_short(outcome, integration, motion, options, out)) {
      keep_stop(model, options, integration, out);
      break;
    }

    const double t_reached = integration.t();
    const double theta1 = integration.y()[0], omega1 = integration.y()[1];
    ++motion.evaluations;
    auto sample = forward_dynamics(model, theta1, omega1, options.formulation);
    if (!sample || at_dead_centre(*sample, kDeadCentreSin, motion.error)) {
      fail(out, sample ? motion.error : sample.error(), t_reached, theta1);
      keep_stop(model, options, integration, out);
      break;
    }
    continue_angles(model, out.samples.back().state, sample->state);
    out.t.push_back(t_reached);
    out.samples.push_back(*sample);
    out.steps_to.push_back(integration.steps());
    if (sensitivities != nullptr) {
      std::vector<Vec2>& s = sensitivities->state.emplace_back();
      for (std::size_t i = 0; i < sensitivities->which.size(); ++i) {
        const double* d = integration.sensitivity(static_cast<int>(i));
        s.emplace_back(d[0], d[1]);
      }
    }
  }

  out.steps = integration.steps();
  out.rhs_evaluations = motion.evaluations;
  return out;
}

namespace {

// x rounded to the nearest whole number by adding and subtracting 1.5·2^52, exact for
// |x| < 2^51 and a few instructions where std::round() is a library call. A tie goes to even
// where std::round() goes away from zero; in simulate_driven a tie would be a jump of exactly π
// in a link angle between samples, which the short steps there exclude.
double nearest_whole(double x) {
  constexpr double kRound = 6755399441055744.0;  // 1.5·2^52
  return (x + kRound) - kRound;
}

}  // namespace

Trajectory simulate_driven(const FourBar& model, const DrivenScene& scene,
                           const SimulateOptions& options) {
  validate(scene, options);
  const auto per_revolution = static_cast<std::size_t>(scene.samples);
  const auto samples = per_revolution * static_cast<std::size_t>(scene.revolutions);
  Trajectory out;
  out.t.reserve(samples);
  out.samples.reserve(samples);

  // t_j = j·T/samples with period T = 2π/|omega1|; theta1 advances by omega1·t, alpha1 = 0
  const double period = kTwoPi / std::abs(scene.omega1);
  out.status = SimulationStatus::kCompleted;
  out.message = "completed";
  // The model's constants once; the crank vector turned from sample to sample (CrankSweep); each
  // sample computed in its place in the trajectory by the inline kernels of
  // core/fourbar/detail/instant_dynamics.hpp (a model with counter-rotations takes the one-instant
  // route).
  const DynamicsConstants constants = dynamics_constants(model);
  CrankSweep crank(model.crank.length);
  // samples at most kMaxUnwrapStep apart in theta1 (the usual case) need no intermediate
  // positions to continue their angles (continue_angles)
  const bool short_steps =
      std::abs(scene.omega1) * period / static_cast<double>(per_revolution) <= kMaxUnwrapStep;
  double turns2 = 0.0, turns3 = 0.0;        // whole turns added to the wrapped angles
  double previous2 = 0.0, previous3 = 0.0;  // the previous sample's wrapped angles [rad]
  // The samples zeroed at once (the outputs a sample does not set, such as the counter-rotation
  // shafts' forces of a model without them, stay zero) rather than one by one as each is added,
  // and the closed instant, which close_instant() fills whole, kept from sample to sample: a
  // short block zeroed per sample cost more than any other step of the loop.
  out.samples.assign(samples, DynamicsSample{});
  ClosedInstant instant;
  for (std::size_t j = 0; j < samples; ++j) {
    const double t = period * static_cast<double>(j) / static_cast<double>(per_revolution);
    const double theta1 = scene.theta1 + scene.omega1 * t;
    ++out.rhs_evaluations;
    DynamicsSample& sample = out.samples[j];
    std::optional<DynamicsError> error;
    if (constants.counter_rotations) {
      const auto one = inverse_dynamics(model, theta1, scene.omega1, 0.0, options.formulation);
      if (one) {
        sample = *one;
      } else {
        error = one.error();
      }
    } else if (const std::optional<Failure> failure =
                   driven_instant_at(model, constants, theta1, crank.l1(theta1), scene.omega1,
                                     options.formulation, instant, sample)) {
      error = failure->error();
    }
    if (error) {
      out.samples.resize(j);
      fail(out, *error, t, theta1);
      break;
    }
    FourBarState& state = sample.state;
    const double wrapped2 = state.theta2, wrapped3 = state.theta3;
    if (j > 0 && short_steps) {
      // continue_angles() by the count of whole turns: continuing the previous sample's angle
      // adds the nearest whole turns of (previous - this)/2π, so the counts add up along the
      // sweep and each angle is wrapped + 2π·turns, the number continue_angles() gives, without
      // its serial chain through the previous continuous angle and its calls of std::round()
      turns2 += nearest_whole((previous2 - wrapped2) / kTwoPi);
      turns3 += nearest_whole((previous3 - wrapped3) / kTwoPi);
      state.theta2 = wrapped2 + kTwoPi * turns2;
      state.theta3 = wrapped3 + kTwoPi * turns3;
    } else if (j > 0) {
      continue_angles(model, out.samples[j - 1].state, state);
    }
    previous2 = wrapped2;
    previous3 = wrapped3;
    out.t.push_back(t);
  }
  return out;
}

}  // namespace bd::core
