#pragma once
/// The opened-loop equations (paper §3, eqs. 22 and 27) integrated over time as a DAE of index
/// one: the six states theta1..3, omega1..3 advance with the accelerations of the 5x5 solve
/// (core/opened_loop.hpp), and the loop closure (eq. 26) holds only as far as its second
/// derivative (eq. 27) is integrated, so it drifts. Three remedies: none, Baumgarte
/// stabilisation of eq. 27, or projection onto the closure and its rate form after every step.
///
/// Unlike the reduced equation in theta1 (core/simulate.hpp), this form has no singularity at a
/// limit (dead-centre) position of the crank, where coupler and rocker align: its 5x5 matrix is
/// regular as long as the three moving links are not all parallel. A non-Grashof linkage in free
/// motion is integrated straight through its limit positions: the crank reverses and the
/// assembly branch flips (A2 crosses the line A1A3), as the real linkage does.
#include <string>
#include <vector>

#include "core/dynamics.hpp"
#include "core/model.hpp"
#include "core/simulate.hpp"

namespace bd::core {

/// How the drift of the loop closure c = l̄1 + l̄2 + l̄3 + l̄4 (eq. 26) is held in check.
enum class Stabilisation {
  kNone,        // integrate eq. 27 as it stands: c and ċ drift with the integration error
  kBaumgarte,   // eq. 27 becomes c̈ = -2α ċ - β² c: the drift decays instead of accumulating
  kProjection,  // after every step, angles onto c = 0 (Gauss-Newton), rates onto ċ = 0
};
/// "none", "baumgarte", "projection".
const char* to_string(Stabilisation s);

/// The CVODE linear multistep family.
enum class DaeMethod {
  kAuto,   // Adams unless projection is asked for (CVODE projects only with BDF)
  kAdams,  // variable-order Adams-Moulton (1-12) with a fixed-point corrector: non-stiff
  kBdf,    // BDF (orders 1-5) with a Newton corrector and a dense difference-quotient Jacobian
};
/// "auto", "adams", "bdf".
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
  DaeMethod method = DaeMethod::kAuto;
  double tolerance = 1e-10;           // integrator relative tolerance
  double absolute_tolerance = 1e-12;  // on the angles [rad] and rates [rad/s]
  long max_steps = 10'000'000;        // integrator steps over the whole run
  /// Empty when valid, else the problem in words.
  std::string validate() const;
};

/// A DAE run: the trajectory (samples with the state, all three accelerations and the reactions
/// from the same 5x5 solve, tau = 0) and, per sample, the constraint drift, the energy and the
/// assembly branch.
struct OpenedLoopDaeResult {
  Trajectory trajectory;
  std::vector<double> position_residual;  // |l̄1 + l̄2 + l̄3 + l̄4| [m]
  std::vector<double> velocity_residual;  // |Σ i l̄k ωk| (rate of the closure) [m/s]
  /// Kinetic energy plus load potential (core/energy.hpp) [J]; conserved in free motion. For a
  /// state off the closure energy.hpp places the rocker from A3 (not from the open chain's A2),
  /// an O(residual) difference.
  std::vector<double> energy;
  /// Branch of the sample: kPlus when A2 lies left of A1->A3, cross(A3 - A1, A2 - A1) >= 0, with
  /// A2 = l̄1 + l̄2 reached along the open chain.
  std::vector<Branch> branch;
  DaeMethod method = DaeMethod::kAuto;  // the method actually used (never kAuto after a run)
  long projections{};                   // projection calls (kProjection)
};

/// Free motion (tau = 0) from theta1, omega1 on the model's branch, under the model's loads,
/// sampled at `scene.samples` instants evenly spaced over [0, scene.duration]. Samples come from
/// CVODE's interpolant (kNone, kBaumgarte) or, with projection, from steps stopped at each
/// instant (so each sample is a projected step end). Angles are continuous in time. A run that
/// cannot start (loop open or dead centre at theta1) or fails keeps the samples before it.
/// @throws bd::InputError if the scene or options are invalid.
OpenedLoopDaeResult simulate_opened_loop_dae(const FourBar& model, const FreeScene& scene,
                                             const OpenedLoopDaeOptions& options = {});

/// Loop-closure residual c = l̄1 + l̄2 + l̄3 + l̄4 [m] and its rate ċ = Σ i l̄k ωk [m/s] of a state
/// whose angles and rates are taken as independent.
Vec2 closure_position_residual(const FourBar& model, const FourBarState& s);
Vec2 closure_velocity_residual(const FourBar& model, const FourBarState& s);

/// The branch of a state (see OpenedLoopDaeResult::branch).
Branch branch_of(const FourBar& model, const FourBarState& s);

}  // namespace bd::core
