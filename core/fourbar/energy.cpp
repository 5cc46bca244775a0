#include "core/fourbar/energy.hpp"

namespace bd::core {

namespace {

// ω_k of link k = 1, 2, 3 [rad/s]
double link_rate(const FourBarState& s, int k) {
  return k == 1 ? s.omega1 : k == 2 ? s.omega2 : s.omega3;
}

// θ_k of link k = 1, 2, 3 [rad]
double link_angle(const Pose& p, int k) { return k == 1 ? p.theta1 : k == 2 ? p.theta2 : p.theta3; }

}  // namespace

double kinetic_energy(const FourBar& model, const FourBarState& s) {
  // translation of each centre of mass plus rotation about it (König)
  double T = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const Link& l = link(model, k);
    const double omega = link_rate(s, k);
    T += 0.5 * l.mass * centre_of_mass_velocity(model, k, s).squaredNorm() +
         0.5 * l.inertia * omega * omega;
  }
  // counter-rotating discs spin at minus their link's rate about fixed shafts (zero when absent)
  const CounterRotations& discs = model.counter_rotations;
  T += 0.5 * discs.crank.inertia * s.omega1 * s.omega1 +
       0.5 * discs.rocker.inertia * s.omega3 * s.omega3;
  return T;
}

double load_potential(const FourBar& model, const Pose& pose) {
  // constant forces at the centres of mass (applied plus weight) and constant moments: their work
  // from a reference pose is -ΔV, so V = -Σ (F̄_k + m_k ḡ)·r̄_k - Σ M_k θ_k (θ_k continuous)
  double V = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const LinkLoad& load = link_load(model, k);
    const Vec2 force = load.force + link(model, k).mass * model.loads.gravity;
    V -= force.dot(centre_of_mass(model, k, pose)) + load.moment * link_angle(pose, k);
  }
  return V;
}

Vec2 linear_momentum(const FourBar& model, const FourBarState& s) {
  Vec2 p = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) p += link(model, k).mass * centre_of_mass_velocity(model, k, s);
  return p;
}

Vec2 system_centre_of_mass(const FourBar& model, const Pose& pose) {
  Vec2 first_moment = Vec2::Zero();
  for (int k = 1; k <= 3; ++k) first_moment += link(model, k).mass * centre_of_mass(model, k, pose);
  return first_moment / total_mass(model);
}

}  // namespace bd::core
