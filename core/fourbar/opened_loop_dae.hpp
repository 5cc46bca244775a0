#pragma once
/// The opened-loop equations (paper §3, eqs. 22 and 27) integrated over time as a DAE of index
/// one: the six states theta1..3, omega1..3 advance with the accelerations of the 5x5 solve
/// (core/fourbar/opened_loop.hpp), and the loop closure (eq. 26) holds only as far as its second
/// derivative (eq. 27) is integrated, so it drifts. Three remedies: none, Baumgarte
/// stabilisation of eq. 27, or projection onto the closure and its rate form after every step.
/// A fourth form keeps the closure itself as an equation: the DAE in the stabilised index-2
/// form of Gear, Gupta and Leimkuhler (GGL), integrated by IDA.
///
/// Unlike the reduced equation in theta1 (core/fourbar/simulate.hpp), this form has no singularity
/// at a limit (dead-centre) position of the crank, where coupler and rocker align: its 5x5 matrix
/// is regular as long as the three moving links are not all parallel. A non-Grashof linkage in free
/// motion is integrated straight through its limit positions: the crank reverses and the
/// assembly branch flips (A2 crosses the line A1A3), as the real linkage does.
#include <string>
#include <vector>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/input_error.hpp"

namespace bd::core {

/// How the drift of the loop closure c = l̄1 + l̄2 + l̄3 + l̄4 (eq. 26) is held in check.
enum class Stabilisation {
  kNone,        // integrate eq. 27 as it stands: c and ċ drift with the integration error
  kBaumgarte,   // eq. 27 becomes c̈ = -2α ċ - β² c: the drift decays instead of accumulating
  kProjection,  // after every step, angles onto c = 0 (Gauss-Newton), rates onto ċ = 0
  /// GGL: y = (θ, ω, λ, μ) with the residuals θ' - ω - Gᵀμ, M ω' + C ω² + Gᵀλ - Q, c(θ) and
  /// G ω (G = ∂c/∂θ = Dᵀ, eq. 24): the closure and its rate form hold at every step to the
  /// Newton tolerance; λ = R̄A3, and μ (zero for the exact motion) absorbs the integration
  /// error of θ' = ω that would otherwise leave the closure.
  kGgl,
};
/// "none", "baumgarte", "projection", "ggl".
const char* to_string(Stabilisation s);

/// The integrator (SUNDIALS): CVODE's linear multistep methods, ARKODE's explicit Runge-Kutta
/// pairs (as core::Integrator's kErk2 ... kErk8), or IDA.
enum class DaeMethod {
  kAuto,   // Adams unless projection (-> BDF) or GGL (-> IDA) is asked for
  kAdams,  // variable-order Adams-Moulton (1-12) with a fixed-point corrector: non-stiff
  kBdf,    // BDF (orders 1-5) with a Newton corrector and a dense difference-quotient Jacobian
  kErk2,   // ARKODE ERKStep, Heun-Euler 2(1)
  kErk3,   // ARKODE ERKStep, Bogacki-Shampine 3(2)
  kErk4,   // ARKODE ERKStep, Zonneveld 4(3)
  kErk5,   // ARKODE ERKStep, Dormand-Prince 5(4)
  kErk6,   // ARKODE ERKStep, Verner 6(5)
  kErk8,   // ARKODE ERKStep, Fehlberg 8(7)
  kIda,    // IDA (variable-order BDF 1-5 for DAEs), GGL form only; dense DQ Jacobian
};
/// "auto", "adams", "bdf", "erk2", "erk3", "erk4", "erk5", "erk6", "erk8", "ida".
const char* to_string(DaeMethod m);

/// Options of the DAE integration (Ceres style: defaults in place, validate() says what is wrong).
struct OpenedLoopDaeOptions {
  Stabilisation stabilisation = Stabilisation::kNone;
  /// Baumgarte: c̈ + 2α ċ + β² c = 0, critically damped for α = β. The defaults make the drift
  /// decay within ~0.1-0.5 s, well below the motion's own time scale (paper example: periods of
  /// seconds), yet keep β·h small for the step sizes that a 1e-10 tolerance takes (h ~ 1e-3 s),
  /// so the stabilising terms add no stiffness for the Adams method.
  double baumgarte_alpha = 10.0;  // α [1/s], >= 0
  double baumgarte_beta = 10.0;   // β [1/s], >= 0
  /// Combinations: projection needs kBdf (CVODE projects only with BDF); kGgl needs kIda and
  /// kIda needs kGgl; kNone and kBaumgarte take kAdams, kBdf or an ERK pair.
  DaeMethod method = DaeMethod::kAuto;
  double tolerance = 1e-10;           // integrator relative tolerance
  double absolute_tolerance = 1e-12;  // on the angles [rad] and rates [rad/s]
  long max_steps = 10'000'000;        // integrator steps over the whole run
  /// Each sample's angles and rates projected onto the closure and its rate form (as
  /// kProjection does after every step) before the sample's accelerations and reactions are
  /// evaluated; the integration goes on from its own, unprojected state. Off the closure by
  /// the integration error (~tolerance), a force-balanced design would show a shaking force of
  /// that size; projected, it vanishes to round-off as on the exact motion.
  bool project_samples = false;
  /// Empty when valid, else the first problem; its field is "tolerance", "absolute_tolerance",
  /// "max_steps", "baumgarte_alpha", "baumgarte_beta", "method" or "stabilisation".
  Problem validate() const;
};

/// A DAE run: the trajectory (samples with the state, all three accelerations and the reactions
/// from the same 5x5 solve, tau = 0) and, per sample, the constraint drift, the energy and the
/// assembly branch.
struct OpenedLoopDaeResult {
  Trajectory trajectory;
  std::vector<double> position_residual;  // |l̄1 + l̄2 + l̄3 + l̄4| [m]
  std::vector<double> velocity_residual;  // |Σ i l̄k ωk| (rate of the closure) [m/s]
  /// Kinetic energy plus load potential (core/fourbar/energy.hpp) [J]; conserved in free motion.
  /// For a state off the closure energy.hpp places the rocker from A3 (not from the open chain's
  /// A2), an O(residual) difference.
  std::vector<double> energy;
  /// Branch of the sample: kPlus when A2 lies left of A1->A3, cross(A3 - A1, A2 - A1) >= 0, with
  /// A2 = l̄1 + l̄2 reached along the open chain.
  std::vector<Branch> branch;
  DaeMethod method = DaeMethod::kAuto;  // the method actually used (never kAuto after a run)
  long projections{};                   // projections (kProjection steps, projected samples)
};

/// Free motion (tau = 0) from theta1, omega1 on the model's branch, under the model's loads,
/// sampled at `scene.samples` instants evenly spaced over [0, scene.duration]. Samples come from
/// the integrator's dense output (kNone, kBaumgarte, kGgl) or, with projection, from steps
/// stopped at each instant (so each sample is a projected step end); each sample's
/// accelerations and reactions are those of the 5x5 solve at its angles and rates. Angles are
/// continuous in time. A run that cannot start (loop open or dead centre at theta1) or fails
/// keeps the samples before it.
/// @throws bd::InputError if the scene or options are invalid.
OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options = {});

/// The same from a given state (its angles and rates; the accelerations are not read), at t = 0,
/// instead of scene.theta1 and scene.omega1: a run continued from a sample of another
/// (core::free_sample_from()). The state is taken as it is: off the closure by a sample's
/// integration error, the stabilisation (or the projection) keeps it there.
OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FourBarState& start,
                                             const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options = {});

/// How simulate_free() integrates Formulation::kOpenedLoop with each core::Integrator (the
/// options' tolerances and max_steps carried over, samples projected onto the closure):
/// - kCvodeAdams: Adams with Baumgarte stabilisation (CVODE cannot project an Adams run);
/// - kCvodeBdf: BDF with projection after every step;
/// - kErk2 ... kErk8: the ERK pair with Baumgarte stabilisation (an explicit method needs no
///   more: the stabilising eigenvalues, -10 1/s, lie far inside its stability region at the
///   step sizes of these tolerances);
/// - kIda: IDA on the GGL form.
OpenedLoopDaeOptions opened_loop_dae_options(const SimulateOptions& options);

/// Loop-closure residual c = l̄1 + l̄2 + l̄3 + l̄4 [m] and its rate ċ = Σ i l̄k ωk [m/s] of a state
/// whose angles and rates are taken as independent.
Vec2 closure_position_residual(const FourBar& model, const FourBarState& s);
Vec2 closure_velocity_residual(const FourBar& model, const FourBarState& s);

/// The branch of a state (see OpenedLoopDaeResult::branch).
Branch branch_of(const FourBar& model, const FourBarState& s);

}  // namespace bd::core
