#pragma once
/// The four-bar as a planar linkage (method `truss`, and the cross-checks of the general engine
/// against the dedicated four-bar formulations): nodes A0 (ground, origin), A1, A2, A3 (ground,
/// (l4, 0)); links crank A0->A1, coupler A1->A2, rocker A2->A3 with the four-bar's mass data
/// (the rocker's centre of mass measured from A2, as in the four-bar); the links' loads at their
/// centres of mass; the crank's angle as the input.
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/model.hpp"
#include "core/planar/simulate.hpp"

namespace bd::core::planar {

/// The linkage drawn at crank angle theta1 on the four-bar's branch.
/// Counter-rotating discs become balance shafts C1 (on the crank) and C3 (on the rocker) with
/// ratio -1, so that their reactions are the four-bar's RC1 and RC3.
/// @throws bd::InputError if the loop cannot close at theta1.
Linkage linkage_of(const FourBar& fourbar, double theta1);

/// The general engine's samples of that linkage as the four-bar's (its crank, coupler and rocker
/// angles as theta1..3, the reactions at A0 and A3, the shaking force and moment, the drive
/// torque), with the same status and message, and where a stopped run stopped.
core::Trajectory fourbar_trajectory(const Trajectory& planar);

/// One row of such a table (`table`'s columns, e.g. a driven run's row between its samples,
/// DrivenRows::at()) as the four-bar's sample.
DynamicsSample fourbar_sample(const Series& table, std::span<const double> row);

}  // namespace bd::core::planar
