#pragma once
/// The opened kinematic loop with principal vectors (paper §3, eqs. 12-28): the mechanism freed
/// at A3, link angles theta1..theta3 as coordinates, R̄A3 as a multiplier. One 5x5 linear solve
/// per instant (eqs. 22 and 27) gives the three angular accelerations and R̄A3; R̄A0 follows from
/// the motion of the centre of mass (eq. 28).
#include "core/dynamics.hpp"
#include "core/model.hpp"

namespace bd::core {

/// Forward dynamics (tau = 0) by the opened loop.
Expected<DynamicsSample, DynamicsError> forward_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1);
/// Inverse dynamics by the opened loop.
Expected<DynamicsSample, DynamicsError> inverse_dynamics_opened_loop(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1);

}  // namespace bd::core
