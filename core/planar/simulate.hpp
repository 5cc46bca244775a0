#pragma once
/// Scenes of a planar linkage: driven inputs at constant speeds (inverse dynamics per sample, no
/// integrator) and free motion under the loads and the drives' efforts (forward dynamics,
/// integrated by SUNDIALS with error control, samples from the integrator's dense output).
///
/// Free motion has two routes:
/// - reduced (the default): the ODE in the inputs z and their rates, the other coordinates
///   solved by Newton at every evaluation (coordinate partitioning: the constraints hold to
///   round-off, no drift). It stops where the inputs stop being coordinates (a limit position:
///   the determinant of the constraints and inputs, normalised by its rows, reaches
///   kLimitDeterminant, found by root finding);
/// - dae: every node coordinate and its rate, the accelerations and multipliers from the
///   constraints' saddle-point system with Baumgarte stabilisation, every output sample projected
///   onto the constraints. It passes through limit positions, as the mechanism does; it stops
///   only where the constraints themselves lose rank (a lock-up or bifurcation).
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/planar/dynamics.hpp"
#include "core/series.hpp"
#include "core/simulation.hpp"

namespace bd::core::planar {

/// Inputs driven at constant speeds from `start` (empty: the drawn values), over `revolutions`
/// turns of the first angle input (`samples` per turn, evenly spaced in time, periodic end
/// excluded), or, with duration > 0, over [0, duration] (`samples` in all, both ends included).
struct DrivenScene {
  std::vector<double> start;   // input values at t = 0 [rad or m]; empty: as drawn
  std::vector<double> speeds;  // per input [rad/s or m/s]
  int revolutions = 1;         // with duration == 0
  double duration = 0;         // [s]; > 0 for a linkage without angle inputs
  int samples = 360;
};

/// Free motion from `start` (empty: as drawn) with the inputs' rates `rates` (empty: at rest),
/// `samples` instants evenly spaced over [0, duration], both ends included.
struct FreeScene {
  std::vector<double> start;
  std::vector<double> rates;  // [rad/s or m/s]
  double duration{};          // [s], > 0
  int samples = 501;          // >= 2
};

enum class Route {
  kReduced,  // the ODE in the inputs (coordinate partitioning)
  kDae,      // every coordinate, saddle-point accelerations, Baumgarte, projected samples
};
/// "reduced", "dae".
const char* to_string(Route r);

struct SimulateOptions {
  Route route = Route::kReduced;
  Integrator integrator = Integrator::kCvodeAdams;  // any but kIda
  double tolerance = 1e-10;                         // relative
  double absolute_tolerance = 1e-12;                // on the coordinates and rates
  long max_steps = 1000000;
  double baumgarte = 10.0;  // the dae route's stabilisation rate α = β [1/s]
};

/// Where the reduced route stops: the determinant of the constraints and inputs divided by the
/// product of its rows' lengths (1 for orthogonal rows, 0 at a singular position).
inline constexpr double kLimitDeterminant = 1e-3;

/// The samples, as a table (columns()), and why the run stopped. On failure every sample before
/// the failure is kept.
struct Trajectory {
  Series table;
  SimulationStatus status = SimulationStatus::kNotRun;
  std::string message = "simulate was not called";
  long steps{}, rhs_evaluations{};
  /// Free runs: the integrator's steps taken up to each row of `table` (0 at the first); the
  /// peaks are looked for between rows where it stepped more than once (step_instants()).
  std::vector<long> steps_to;
  /// A free run that stopped short of its end: the instant its integration had reached (past
  /// its last sample, e.g. the limit position it stopped at), where its peaks are searched to;
  /// NaN for a run that completed, and for a driven run.
  double stop_time = std::numeric_limits<double>::quiet_NaN();
  /// The motion at stop_time where it could be evaluated there, as a row of columns(model) and
  /// the integrator's state (as `states`); both empty otherwise. Not a sample (the samples stay
  /// evenly spaced) but the end of the peaks' search (free_stop_state()).
  std::vector<double> stop_row, stop_state;
  /// A free run's integrator state at each sample, `state_size` numbers per row of `table`: the
  /// inputs and their rates (z, ż) on the reduced route, every node coordinate and its rate
  /// (q, q̇) on the dae route, as integrated (before the sample's projection). Empty for a driven
  /// run. Kept beside the table, not as columns (the files' columns do not change), so that the
  /// run can be continued from any sample exactly (free_state()): the table's inputs and their
  /// rates would restart the reduced route, but not the dae route, whose node velocities near a
  /// limit position the inputs' rates do not determine.
  std::vector<double> states;
  std::size_t state_size{};
  bool ok() const { return status == SimulationStatus::kCompleted; }
};

/// The columns of a planar linkage's samples:
///   t; per link theta_<link>, omega_<link>, alpha_<link> [rad, rad/s, rad/s^2]; per slider
///   s_<slider>, v_<slider>, a_<slider> [m, m/s, m/s^2] (along its guide); per moving node
///   x_<node>, y_<node> [m]; per ground node R<node>x, R<node>y and per frame guide
///   R<slider>x, R<slider>y, per balance shaft R<shaft>x, R<shaft>y, per spring anchored on the
///   frame R<node>_<spring>x, R<node>_<spring>y (its pull at that ground node), per slide drive
///   on a frame guide R<slider>_drivex, R<slider>_drivey [N] (forces on the frame: Fsh is
///   their sum); per joint F<joint>x, F<joint>y [N] (on
///   the joint's link); Fshx, Fshy [N], Msh [N m]; the drives' efforts: tau for a single input,
///   else tau_<input> [N m or N]; Fshx_inertial, Fshy_inertial [N], Msh_inertial [N m] (the
///   inertial part, -Σ m a and -dH/dt); Fshx_static, Fshy_static [N], Msh_static [N m] (the
///   weights and applied loads): Fsh = inertial + static.
std::vector<std::string> columns(const Model& model);
/// Appends `in` as a row of those columns.
void append_row(const Model& model, const Instant& in, Series& table);

/// @throws bd::InputError if the scene or options are invalid (speeds or rates of the wrong
///         count, samples < 1, no angle input and no duration, ...), or the linkage cannot be
///         assembled at the start or its inputs do not match its degrees of freedom (the message
///         says which constraint does not close, or how many inputs the mobility needs).
Trajectory simulate_driven(const Model& model, const DrivenScene& scene);
Trajectory simulate_free(const Model& model, const FreeScene& scene,
                         const SimulateOptions& options = {});

/// A free run's state at one instant: what its integration continues from.
struct FreeState {
  double t{};                 // [s]
  std::vector<double> y;      // the integrator's state (Trajectory::states)
  std::vector<double> angle;  // every link's angle, continuous in time [rad]
  std::vector<Vec2> x;        // every node's position [m] (the reduced route's first guess)
};

/// The state at sample i < run.table.rows() of the free run `run` (its states, and its row's
/// angles and positions); y is empty where the run kept no states.
FreeState free_state(const Model& model, const Trajectory& run, std::size_t i);
/// The state where the free run `run` stopped short of its end (Trajectory::stop_time), none
/// where it completed or its stop could not be evaluated.
std::optional<FreeState> free_stop_state(const Model& model, const Trajectory& run);

/// The free motion continued from `from` (a sample of a run, free_state(), or an instant computed
/// so) to t >= from.t by the route, integrator and tolerances of `options` (the run's own), in
/// one integration in the run's time (the drives' efforts depend on it) whose last step ends at
/// t; the instant there evaluated as the run evaluates its samples (the dae route's projected
/// onto the constraints) and appended to `row` as a row of columns(model). Exact to the
/// integration tolerance, as the run's samples are; the state at t is returned for a later
/// continuation. None where the state does not fit the route, the integration fails, or the
/// reduced route reaches a limit position. Used to locate a free run's peaks between its samples
/// (core/planar/metrics.hpp).
std::optional<FreeState> free_state_from(const Model& model, const SimulateOptions& options,
                                         const FreeState& from, double t, Series& row);

/// A free run with the first derivatives of its samples with respect to mass parameters.
struct FreeSensitivities {
  /// The run: the reduced route's equations, integrator and tolerances, with the sensitivities
  /// in the integrator's error test (so its steps, and its samples to within the integration's
  /// error, differ from simulate_free()'s).
  Trajectory trajectory;
  std::vector<int> parameters;  // indices into mass_parameters() (core/planar/model.hpp)
  /// derivative[j]: every number of trajectory.table differentiated with respect to
  /// parameters[j], in the table's layout (its columns, the t column 0), in their units per the
  /// parameter's unit. Empty where the run failed.
  std::vector<Series> derivative;
  /// The integrator's sensitivities at each sample (what a continuation from it starts from):
  /// for sample i and parameter j the trajectory.state_size numbers d(z, ż)/dπ_j from entry
  /// (i · parameters.size() + j) · state_size on. Empty where the run failed.
  std::vector<double> state;
};

/// A free run's row at one instant and its derivatives (free_derivatives_at()).
struct InstantDerivatives {
  std::vector<double> row;                      // the row at the instant (columns(model))
  std::vector<std::vector<double>> derivative;  // per parameter, the row differentiated
};

/// simulate_free() on the reduced route with forward sensitivities of the samples with respect
/// to the mass parameters `parameters` (indices into mass_parameters(model.linkage())).
///
/// The state y = (z, ż) of the reduced equation y' = f(y, π) has the sensitivities
/// s_j = dy/dπ_j, which obey s_j' = (df/dy) s_j + df/dπ_j, s_j(0) = 0. CVODES integrates them
/// with the state (staggered corrector, in the error test at the relative tolerance
/// max(options.tolerance, 1e-7)), forming their right-hand side by its own centred difference
/// quotient along (s_j, e_j): the right-hand side reads π from the array CVODES perturbs and
/// sets the model's mass matrix and weights from it (Model::set_mass_parameters()), so the
/// dynamics needs no derivative code of its own (as the four-bar's,
/// core/fourbar/sensitivity.hpp). Each sample's numbers are functions g(y, π); their total
/// derivative dg/dy · s_j + dg/dπ_j is the derivative of g along (s_j, e_j), a centred
/// difference of the sample's evaluation (no integration) with the step 1e-5 of the parameter's
/// scale (CVODES' pbar: per link its mass m, m L, m L, m L² with L its element length and m its
/// mass, or the linkage's total mass for a massless link; a point mass its mass). The
/// derivatives are good to ~1e-6 of their size (tests/core/planar/sensitivity_test.cpp).
/// @throws bd::InputError as simulate_free() does for an invalid scene or options; also, with
///         field "route" or "integrator", for the dae route or an ERK pair, and with field
///         "parameters" (index: the entry) for an index outside the layout or one listed twice.
FreeSensitivities simulate_free_sensitivities(const Model& model, const FreeScene& scene,
                                              const std::vector<int>& parameters,
                                              const SimulateOptions& options = {});

/// The derivatives with respect to run.parameters of the run's row at any instant t of its span,
/// not only at its samples (the run = simulate_free_sensitivities(model, …, options)): at a
/// sample's time that sample's; between samples the run continued with its sensitivities from
/// the latest sample before t by its own route, integrator and tolerances, in one integration
/// whose last step ends at t (as free_state_from() continues a plain run), the row and its
/// derivatives there computed as the run computes its samples'. None outside the run's span,
/// for a run without derivatives, or where the continuation or a difference fails.
std::optional<InstantDerivatives> free_derivatives_at(const Model& model,
                                                      const SimulateOptions& options,
                                                      const FreeSensitivities& run, double t);

}  // namespace bd::core::planar
