#pragma once
/// Energy and momentum of the moving links, used by invariants and tests.
#include "core/kinematics.hpp"
#include "core/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// Kinetic energy Σ ½ m_k |v_k|² + ½ I_k ω_k² [J]; needs the velocity stage.
double kinetic_energy(const FourBar& model, const FourBarState& s);

/// Potential of the model's (constant) loads: V = -Σ (F̄_k + m_k ḡ)·r̄_k - Σ M_k θ_k [J], with
/// continuous (unwrapped) angles; T + V is conserved in free motion.
double load_potential(const FourBar& model, const Pose& pose);

/// Total linear momentum Σ m_k v̄_k [kg m/s].
Vec2 linear_momentum(const FourBar& model, const FourBarState& s);

/// Centre of mass of the moving links [m].
Vec2 system_centre_of_mass(const FourBar& model, const Pose& pose);

}  // namespace bd::core
