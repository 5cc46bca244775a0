#pragma once
/// Counter-rotation synthesis for full shaking-moment balance of a force-balanced inline design
/// (Berkof 1973, paper §5.2).
#include <string>

#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::balance {

/// The design with counter-rotating inertias equal to Berkof's reduced inertias.
struct MomentBalancedDesign {
  core::FourBar model;      // the input with model.counter_rotations set
  double crank_inertia{};   // J1 [kg m^2]
  double rocker_inertia{};  // J3 [kg m^2]
};

/// Adds counter-rotations (discs on frame shafts at crank_at and rocker_at [m], geared to the
/// crank and the rocker with ratio -1) that cancel the angular momentum of a force-balanced inline
/// design, so shaking force and shaking moment both vanish for every motion without applied loads.
/// @throws bd::InputError if the model is not force balanced, or its coupler is not a Berkof
///         coupler (f2 = 0 and I2 = m2 e2 (l2 - e2), i.e. dynamically two point masses at A1 and
///         A2), checked to a relative 1e-9 (force_balance's output meets them to 1e-12); or a
///         shaft sits on its link's pivot (crank_at = A0, rocker_at = A3) where J > 0. The
///         message gives the values and what they must be; its field is empty (the design as a
///         whole) except for make_fourbar's own ("counter_rotations.crank" for a shaft on A0).
/// Any counter-rotations of the input are replaced.
MomentBalancedDesign moment_balance(const core::FourBar& force_balanced, Vec2 crank_at,
                                    Vec2 rocker_at);

}  // namespace bd::balance
