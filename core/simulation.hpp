#pragma once
/// What the simulation of any linkage shares, whatever its equations: the SUNDIALS integrator of
/// free motion and the status a run ends with. The four-bar's scenes, options and trajectories
/// (core/fourbar/simulate.hpp) build on these.
#include "core/input_error.hpp"

namespace bd::core {

/// The SUNDIALS integrator of a free scene (docs/performance.md compares them). Each controls
/// the local error of every step to the options' relative and absolute tolerances. ERK pairs
/// advance with the higher order (local extrapolation); the lower-order embedding estimates the
/// error. Samples come from the integrator's dense output, except with kErk6 and kErk8, whose
/// steps end at every sample instead (ARKODE's Hermite interpolant, of degree <= 5, is far less
/// accurate than their long steps). With the four-bar's opened loop each integrator comes with
/// the constraint handling it allows (opened_loop_dae_options() in
/// core/fourbar/opened_loop_dae.hpp).
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

/// The checks every integration's options share: tolerance (relative) in (0, 1),
/// absolute_tolerance > 0 and finite, max_steps >= 1. The problem's field is "tolerance",
/// "absolute_tolerance" or "max_steps", e.g. "tolerance must be > 0 and < 1, got 0".
Problem check_integration(double tolerance, double absolute_tolerance, long max_steps);

/// How a run ended.
enum class SimulationStatus {
  kNotRun,
  kCompleted,
  kAssemblyFailed,    // the loop cannot close at the crank angle reached
  kSingular,          // a singular position was reached
  kIntegratorFailed,  // the integrator gave up (step-size underflow, max_steps reached, ...)
};
/// "not-run", "completed", "assembly-failed", "singular", "integrator-failed".
const char* to_string(SimulationStatus s);

}  // namespace bd::core
