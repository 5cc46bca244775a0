#pragma once
/// Energy and momentum of the moving links (and counter-rotating discs), used by invariants and
/// tests.
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// Kinetic energy Σ ½ m_k |v_k|² + ½ I_k ω_k² + ½ J_1 ω_1² + ½ J_3 ω_3² [J], the last two terms
/// from the counter-rotating discs on the crank and the rocker (each spins at minus its link's
/// rate; zero when absent); needs the velocity stage.
double kinetic_energy(const FourBar& model, const FourBarState& s);

/// Potential of the model's (constant) loads: V = -Σ (F̄_k + m_k ḡ)·r̄_k - Σ M_k θ_k [J], with
/// continuous (unwrapped) angles; T + V is conserved in free motion.
double load_potential(const FourBar& model, const Pose& pose);

/// Total linear momentum Σ m_k v̄_k [kg m/s] (counter-rotating discs do not translate).
Vec2 linear_momentum(const FourBar& model, const FourBarState& s);

/// Centre of mass of the moving links [m].
Vec2 system_centre_of_mass(const FourBar& model, const Pose& pose);

}  // namespace bd::core
