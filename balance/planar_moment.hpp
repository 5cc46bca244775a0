#pragma once
/// Counter-rotations for the shaking-moment balance of a force-balanced planar linkage (paper
/// §5.2, Berkof 1973, generalised): with its linear momentum zero in every configuration, a
/// linkage's angular momentum H is the same about every point, and a disc on a frame shaft geared
/// to a link L that turns about a ground node, ratio k and inertia J, adds k J ω_L. Full moment
/// balance is
///   h_j(config) + Σ_c k_c J_c ω_{L_c, j}(config) = 0
/// for every input j in every configuration (h_j the angular momentum per unit rate of input j,
/// ω_{L, j} the link's rate per unit rate of input j): constant coefficients c = k J that cancel H
/// wherever the linkage goes. For a four-bar with a Berkof coupler they are Berkof's reduced
/// inertias (tests/balance/planar_moment_test.cpp); in general the floating links' angular
/// momentum is not a constant combination of the grounded links' rates, and the counter-rotations
/// that leave the least RMS inertial shaking moment over the motion are the answer, with a message
/// naming what cannot be cancelled.
#include <optional>
#include <string>
#include <vector>

#include "balance/planar.hpp"

namespace bd::balance::planar {

/// One on every link that turns about exactly one ground node, shafts at their defaults.
std::vector<CounterRotationRequest> default_counter_rotations(const cp::Linkage& linkage);

/// Where a request's shaft sits [m].
Vec2 shaft_position(const cp::Linkage& linkage, const CounterRotationRequest& request);

/// Checks the requests against the linkage without balancing anything.
/// @throws bd::InputError with field "counter_rotations.<link>": a link that does not turn
///         about exactly one ground node, two requests on one link, a shaft position that is not
///         finite, or a shaft name (counter_<link>) that a node, slider or shaft has already.
void check_counter_rotations(const cp::Linkage& linkage,
                             const std::vector<CounterRotationRequest>& requests);

/// The result of moment balancing.
struct MomentBalance {
  cp::Linkage linkage;     // the input with the counter-rotation shafts added (counter_<link>)
  std::vector<int> added;  // their indices in linkage.shafts (a link already balanced gets none)
  bool full{};             // full moment balance reached (H ≡ 0 to round-off)
  /// Empty when full; else one line naming the link whose angular momentum is the largest part
  /// of what the counter-rotations allowed cannot cancel, and what the least-squares design
  /// leaves.
  std::string message;
  /// |H| over |H0| at the design, per unit input rate over the configurations.
  double angular_momentum_left{};
  /// RMS of the inertial shaking moment over the samples, before and after [N m].
  double Msh_rms_before{}, Msh_rms_after{};
  double added_inertia{};  // Σ the discs' inertias [kg m^2]
};

/// Counter-rotating discs (massless off their axes: they add no force) on the requested links
/// that make the force-balanced `linkage` moment balanced over the configurations of `k`; where
/// that cannot be reached, the discs that minimise the RMS of the inertial shaking moment over
/// k's samples, with `full` false and the message saying why; among several such (a link that
/// turns at constant speed in k's motion, whose disc changes nothing there), those that leave the
/// least angular momentum over k's configurations, for the motions whose speed varies. A disc whose
/// coefficient k J comes out negative counter-rotates (ratio -1, J = -c); one that comes out
/// positive turns with its link (ratio 1: a flywheel that adds to the link's own angular momentum).
/// @throws bd::InputError as check_counter_rotations(), or (no field) when `linkage` is not
///         force balanced over k to round-off: a moment balance starts from full force balance.
MomentBalance moment_balance(const cp::Linkage& linkage, const Kinematics& k,
                             const std::vector<CounterRotationRequest>& requests);

/// The force balance `design` completed by the counter-rotations of `moment`: its linkage
/// becomes theirs, their inertias join the added inertia and the message says what they do.
void add_counter_rotations(ForceBalance& design, const MomentBalance& moment);

}  // namespace bd::balance::planar
