#pragma once
/// Scenes: free motion (forward dynamics integrated by a SUNDIALS integrator with error control,
/// output at the requested instants by the integrator's dense output) and driven motion (constant
/// crank speed, inverse dynamics per sample, no integration).
#include <string>
#include <vector>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"

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

/// The SUNDIALS integrator of a free scene (docs/performance.md compares them). Each controls
/// the local error of every step to the options' relative and absolute tolerances. ERK pairs
/// advance with the higher order (local extrapolation); the lower-order embedding estimates the
/// error. Samples come from the integrator's dense output, except with kErk6 and kErk8, whose
/// steps end at every sample instead (ARKODE's Hermite interpolant, of degree <= 5, is far less
/// accurate than their long steps). With the opened loop each integrator comes with the
/// constraint handling it allows (opened_loop_dae_options() in core/opened_loop_dae.hpp).
enum class Integrator {
  kCvodeAdams,  // CVODE, variable-order Adams-Moulton (orders 1-12), fixed-point iteration
  kCvodeBdf,    // CVODE, BDF (orders 1-5), Newton iteration with a dense DQ Jacobian
  kErk2,        // ARKODE ERKStep, Heun-Euler 2(1), ARKODE_HEUN_EULER_2_1_2
  kErk3,        // ARKODE ERKStep, Bogacki-Shampine 3(2), ARKODE_BOGACKI_SHAMPINE_4_2_3
  kErk4,        // ARKODE ERKStep, Zonneveld 4(3), ARKODE_ZONNEVELD_5_3_4
  kErk5,        // ARKODE ERKStep, Dormand-Prince 5(4), ARKODE_DORMAND_PRINCE_7_4_5
  kErk6,        // ARKODE ERKStep, Verner 6(5), ARKODE_VERNER_8_5_6
  kErk8,        // ARKODE ERKStep, Fehlberg 8(7), ARKODE_FEHLBERG_13_7_8
  kIda,         // IDA on the opened loop's DAE in stabilised index-2 form (kOpenedLoop only)
};
/// "cvode-adams", "cvode-bdf", "erk2", "erk3", "erk4", "erk5", "erk6", "erk8", "ida".
const char* to_string(Integrator integrator);
/// Every integrator, in the order the docs list them.
inline constexpr Integrator kIntegrators[] = {
    Integrator::kCvodeAdams, Integrator::kCvodeBdf, Integrator::kErk2,
    Integrator::kErk3,       Integrator::kErk4,     Integrator::kErk5,
    Integrator::kErk6,       Integrator::kErk8,     Integrator::kIda};

/// How to simulate (Ceres-style options: defaults in place, validate() says what is wrong).
struct SimulateOptions {
  Formulation formulation = Formulation::kMassMatrix;
  Integrator integrator = Integrator::kCvodeAdams;  // free scenes; kIda needs kOpenedLoop
  double tolerance = 1e-10;                         // integrator relative tolerance (free scenes)
  double absolute_tolerance = 1e-12;                // on theta1 [rad] and omega1 [rad/s]
  long max_steps = 1000000;                         // integrator steps over the whole run
  /// Empty when valid, else the problem in words (e.g. kIda with a reduced formulation).
  std::string validate() const;
};

enum class SimulationStatus {
  kNotRun,
  kCompleted,
  kAssemblyFailed,    // the loop cannot close at the crank angle reached
  kSingular,          // a singular position was reached
  kIntegratorFailed,  // the integrator gave up (step-size underflow, max_steps reached, ...)
};
const char* to_string(SimulationStatus s);
/// The status a run stops with when the dynamics fails with `kind`.
SimulationStatus status_of(DynamicsError::Kind kind);

/// Checks a free scene (what both free-motion integrators need).
/// @throws bd::InputError if theta1 or omega1 is not finite, duration is not > 0, or samples is
///         outside [2, 1e8]; the message names the key, its unit and the value.
void validate_scene(const FreeScene& scene);

/// The samples computed, in time order, and why the run stopped. On failure every sample
/// before the failure is kept.
struct Trajectory {
  std::vector<double> t;                // [s]
  std::vector<DynamicsSample> samples;  // one per t; angles continuous in time
  SimulationStatus status = SimulationStatus::kNotRun;
  std::string message = "simulate was not called";  // one line; names time and crank angle
  long steps{};                                     // integrator steps (free scenes)
  long rhs_evaluations{};                           // dynamics evaluations
  bool ok() const { return status == SimulationStatus::kCompleted; }
};

/// With Formulation::kMassMatrix or kComplexMasses the reduced equation in theta1 is integrated
/// by options.integrator (any but kIda); it stops (kSingular) where the crank reaches a limit
/// position, located by root finding (or, for an ERK pair, where a trial step goes beyond it).
/// With kOpenedLoop the opened loop's DAE in theta1..theta3 is integrated, kept on the loop
/// closure by the means the integrator allows (core/opened_loop_dae.hpp,
/// opened_loop_dae_options(): Baumgarte for Adams and the ERK pairs, projection for BDF, the
/// GGL form for IDA), every sample projected onto it; it passes through limit positions (the
/// crank reverses, the branch flips), so a linkage whose crank cannot turn fully moves on
/// physically.
/// @throws bd::InputError if the scene or options are invalid (duration <= 0, samples < 2, ...).
Trajectory simulate_free(const FourBar& model, const FreeScene& scene,
                         const SimulateOptions& options = {});
/// @throws bd::InputError if the scene or options are invalid (omega1 == 0, revolutions < 1, ...).
Trajectory simulate_driven(const FourBar& model, const DrivenScene& scene,
                           const SimulateOptions& options = {});

}  // namespace bd::core
