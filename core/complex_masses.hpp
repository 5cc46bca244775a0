#pragma once
/// The closed loop with complex equivalent masses (paper §4.1, eqs. 29-40): the coupler's mass
/// is carried by complex masses at A1 and A2, the link angles are coordinates, and the loop
/// constraint forces are eliminated by the transfer functions Θ2, Θ3 into one equation in theta1.
/// Reactions follow from virtual displacements of the centre of mass S and a rotation about S.
#include "core/dynamics.hpp"
#include "core/model.hpp"

namespace bd::core {

/// Forward dynamics (tau = 0) by the complex equivalent masses.
Expected<DynamicsSample, DynamicsError> forward_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1);
/// Inverse dynamics by the complex equivalent masses.
Expected<DynamicsSample, DynamicsError> inverse_dynamics_complex_masses(const FourBar& model,
                                                                        double theta1,
                                                                        double omega1,
                                                                        double alpha1);

}  // namespace bd::core
