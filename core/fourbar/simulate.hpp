#pragma once
/// Scenes: free motion (forward dynamics integrated by a SUNDIALS integrator with error control,
/// output at the requested instants by the integrator's dense output) and driven motion (constant
/// crank speed, inverse dynamics per sample, no integration).
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/input_error.hpp"
#include "core/simulation.hpp"

namespace bd::core {

/// Free motion from theta1, omega1 under the loads, sampled at `samples` instants evenly spaced
/// over [0, duration], both ends included.
struct FreeScene {
  double theta1{};    // initial crank angle [rad]
  double omega1{};    // initial crank rate [rad/s]
  double duration{};  // [s], > 0
  int samples{501};   // >= 2
};

/// Crank driven at the constant rate omega1 over whole revolutions, `samples` per revolution,
/// evenly spaced in time, periodic end excluded. t runs over the revolutions.
struct DrivenScene {
  double theta1{};     // crank angle at t = 0 [rad]
  double omega1{};     // constant crank rate [rad/s], != 0
  int revolutions{1};  // >= 1
  int samples{360};    // per revolution, >= 1
};

/// The time [s] of sample j of a driven scene, t_j = j T / samples with T = 2π / |omega1|,
/// operation for operation as simulate_driven() takes it (so that an optimiser's instants are
/// the run's, bit for bit); j = samples · revolutions is the motion's periodic end.
inline double driven_sample_time(const DrivenScene& scene, long long j) {
  const double period = 2.0 * std::numbers::pi / std::abs(scene.omega1);
  return period * static_cast<double>(j) / static_cast<double>(scene.samples);
}

/// How to simulate (Ceres-style options: defaults in place, validate() says what is wrong).
struct SimulateOptions {
  Formulation formulation = Formulation::kMassMatrix;
  Integrator integrator = Integrator::kCvodeAdams;  // free scenes; kIda needs kOpenedLoop
  double tolerance = 1e-10;                         // integrator relative tolerance (free scenes)
  double absolute_tolerance = 1e-12;                // on theta1 [rad] and omega1 [rad/s]
  long max_steps = 1000000;                         // integrator steps over the whole run
  /// Empty when valid, else the first problem; its field is "tolerance",
  /// "absolute_tolerance", "max_steps", "formulation" or "integrator" (e.g. "integrator ida
  /// needs formulation opened-loop, got mass-matrix: ...").
  Problem validate() const;
};

/// The status a run stops with when the dynamics fails with `kind`.
SimulationStatus status_of(DynamicsError::Kind kind);

/// Checks a free scene (what both free-motion integrators need).
/// @throws bd::InputError if theta1 or omega1 is not finite, duration is not > 0, or samples is
///         outside [2, 1e8]; the message names the key, its unit and the value. Its field is
///         "scene.theta1", "scene.omega1", "scene.duration" or "scene.samples".
void validate_scene(const FreeScene& scene);

/// The samples computed, in time order, and why the run stopped. On failure every sample
/// before the failure is kept.
struct Trajectory {
  std::vector<double> t;                // [s]
  std::vector<DynamicsSample> samples;  // one per t; angles continuous in time
  SimulationStatus status = SimulationStatus::kNotRun;
  std::string message = "simulate was not called";  // one line; names time and crank angle
  long steps{};                                     // integrator steps (free scenes)
  /// Free scenes: the integrator's steps taken up to each sample (0 at the first), as t; the
  /// peaks are looked for between samples where it stepped more than once (step_instants()).
  std::vector<long> steps_to;
  /// A free run that stopped short of its end: the instant its integration had reached (past
  /// its last sample, e.g. the limit position it stopped at), where its peaks are searched to;
  /// NaN for a run that completed, and for a driven run.
  double stop_time = std::numeric_limits<double>::quiet_NaN();
  /// The motion at stop_time where it could be evaluated there (the crank at its limit
  /// position, before the dynamics stops vouching for its values), else none: not a sample (the
  /// samples stay evenly spaced), but the end of the peaks' search.
  std::optional<DynamicsSample> stop;
  long rhs_evaluations{};                           // dynamics evaluations
  bool ok() const { return status == SimulationStatus::kCompleted; }
};

/// With Formulation::kMassMatrix or kComplexMasses the reduced equation in theta1 is integrated
/// by options.integrator (any but kIda); it stops (kSingular) where the crank reaches a limit
/// position, located by root finding (or, for an ERK pair, where a trial step goes beyond it).
/// With kOpenedLoop the opened loop's DAE in theta1..theta3 is integrated, kept on the loop
/// closure by the means the integrator allows (core/fourbar/opened_loop_dae.hpp,
/// opened_loop_dae_options(): Baumgarte for Adams and the ERK pairs, projection for BDF, the
/// GGL form for IDA), every sample projected onto it; it passes through limit positions (the
/// crank reverses, the branch flips), so a linkage whose crank cannot turn fully moves on
/// physically.
/// @throws bd::InputError if the scene or options are invalid (duration <= 0, samples < 2, ...),
///         with the field of SimulateOptions::validate() or validate_scene().
Trajectory simulate_free(const FourBar& model, const FreeScene& scene,
                         const SimulateOptions& options = {});
/// The sample at time t of a free run of simulate_free(model, scene, options), from a given
/// sample `from` at time t0 <= t (a sample of the run, or an instant computed so): integrated by
/// the same formulation and integrator in one run whose last step ends at t, and its dynamics
/// evaluated there; exact to the integration tolerance, as the run's own samples are. The reduced
/// formulations continue from the sample's theta1 and omega1 on the model's branch; the opened
/// loop from its whole state (the branch it has reached). None for t < t0 or where the
/// integration fails. Used to locate a free run's peaks between its samples
/// (core/fourbar/metrics.hpp).
std::optional<DynamicsSample> free_sample_from(const FourBar& model, const SimulateOptions& options,
                                               double t0, const DynamicsSample& from, double t);
/// @throws bd::InputError if the scene or options are invalid (omega1 == 0, revolutions < 1, ...),
///         with the field of SimulateOptions::validate() or "scene.theta1", "scene.omega1",
///         "scene.revolutions", "scene.samples"; none for revolutions * samples above 1e8.
Trajectory simulate_driven(const FourBar& model, const DrivenScene& scene,
                           const SimulateOptions& options = {});

}  // namespace bd::core
