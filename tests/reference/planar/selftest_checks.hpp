#pragma once
// Checks for the referee's self-tests, written from the physics of a Sample (not from the
// referee's internals): power balance, Newton–Euler of every body with the reported forces,
// the inertial + static split of the shaking force and moment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/reference/planar/referee.hpp"
#include "tests/reference/planar/selftest_mechanisms.hpp"

namespace bd::referee::selftest {

inline Vec2 rotated(double angle, const Vec2& v) {
  return {std::cos(angle) * v.x() - std::sin(angle) * v.y(),
          std::sin(angle) * v.x() + std::cos(angle) * v.y()};
}

/// dT/dt = sum m v . a + I omega alpha.
inline double kinetic_energy_rate(const Mechanism& m, const Sample& s) {
  double out = 0;
  for (std::size_t i = 0; i < m.bodies.size(); ++i) {
    const MassProperties mp = merged(m.bodies[i]);
    const BodyState& b = s.bodies[i];
    out += mp.mass * b.velocity.dot(b.acceleration) + mp.inertia * b.omega * b.alpha;
  }
  return out;
}

inline double total_energy(const Sample& s) {
  return s.kinetic_energy + s.gravity_energy + s.spring_energy;
}

/// Current unit direction of slider k's line.
inline Vec2 line_direction(const Mechanism& m, const Sample& s, int k) {
  const PointOnLine& sl = m.sliders[static_cast<std::size_t>(k)];
  const double angle = sl.line_body == kGround ? 0.0 : s.bodies[sl.line_body].angle;
  return rotated(angle, (sl.line_to - sl.line_from).normalized());
}

/// Resultant force and moment (about the body's centre of mass) on every body, from gravity,
/// the applied loads and every force the sample reports; returns the largest relative
/// violation of m a = F, I alpha = M (relative to the largest term of each body's sums).
inline double newton_euler_violation(const Mechanism& m, const Sample& s) {
  const std::size_t nb = m.bodies.size();
  std::vector<Vec2> F(nb, Vec2(0, 0));
  std::vector<double> M(nb, 0), fscale(nb, 0), mscale(nb, 0);
  auto add = [&](int body, const Vec2& f, const Vec2& at, double torque) {
    if (body == kGround) return;
    const Vec2 arm = at - s.bodies[body].com;
    F[body] += f;
    M[body] += cross(arm, f) + torque;
    fscale[body] = std::max(fscale[body], f.norm());
    mscale[body] = std::max({mscale[body], std::abs(cross(arm, f)), std::abs(torque)});
  };
  for (std::size_t i = 0; i < nb; ++i)
    add(static_cast<int>(i), merged(m.bodies[i]).mass * m.gravity, s.bodies[i].com, 0);
  for (std::size_t k = 0; k < m.pins.size(); ++k) {
    const Pin& p = m.pins[k];
    const Vec2 at = point_motion(m, s, p.b == kGround ? p.a : p.b, p.point).p;
    add(p.b, s.pin_forces[k], at, 0);
    add(p.a, -s.pin_forces[k], at, 0);
  }
  for (std::size_t k = 0; k < m.sliders.size(); ++k) {
    add(m.sliders[k].point_body, s.slider_forces[k], s.slider_points[k], 0);
    add(m.sliders[k].line_body, -s.slider_forces[k], s.slider_points[k], 0);
  }
  for (std::size_t k = 0; k < m.gears.size(); ++k) {
    add(m.gears[k].b, s.gear_forces[k].force, s.gear_forces[k].point, 0);
    add(m.gears[k].a, -s.gear_forces[k].force, s.gear_forces[k].point, 0);
  }
  for (std::size_t k = 0; k < m.inputs.size(); ++k) {
    const double e = s.input_efforts[k];
    if (const auto* a = std::get_if<AngleInput>(&m.inputs[k])) {
      add(a->body, {0, 0}, {0, 0}, e);
    } else {
      const int sl = std::get<SlideInput>(m.inputs[k]).slider;
      const Vec2 f = e * line_direction(m, s, sl), at = s.slider_points[sl];
      add(m.sliders[sl].point_body, f, at, 0);
      add(m.sliders[sl].line_body, -f, at, 0);
    }
  }
  for (std::size_t k = 0; k < m.springs.size(); ++k) {
    const Spring& sp = m.springs[k];
    const Vec2 pa = point_motion(m, s, sp.a, sp.point_a).p,
               pb = point_motion(m, s, sp.b, sp.point_b).p;
    const Vec2 e = (pb - pa).normalized();
    add(sp.a, s.spring_tensions[k] * e, pa, 0);
    add(sp.b, -s.spring_tensions[k] * e, pb, 0);
  }
  for (const auto& f : m.forces)
    add(f.body, f.force(s.t), point_motion(m, s, f.body, f.point).p, 0);
  for (const auto& mo : m.moments) add(mo.body, {0, 0}, {0, 0}, mo.moment(s.t));
  double worst = 0;
  for (std::size_t i = 0; i < nb; ++i) {
    const MassProperties mp = merged(m.bodies[i]);
    const Vec2 ma = mp.mass * s.bodies[i].acceleration;
    const double Ia = mp.inertia * s.bodies[i].alpha;
    const double fs = std::max({fscale[i], ma.norm(), 1e-300});
    const double ms = std::max({mscale[i], std::abs(Ia), 1e-300});
    worst = std::max({worst, (F[i] - ma).norm() / fs, std::abs(M[i] - Ia) / ms});
  }
  return worst;
}

/// Power balance sum efforts * rates + P_applied + P_gravity + P_springs = dT/dt, relative to
/// the largest term.
inline double power_balance_violation(const Mechanism& m, const Sample& s) {
  const double dT = kinetic_energy_rate(m, s);
  const double lhs = s.input_power + s.applied_power + s.gravity_power + s.spring_power;
  const double scale = std::max({std::abs(dT), std::abs(s.input_power), std::abs(s.applied_power),
                                 std::abs(s.gravity_power), std::abs(s.spring_power), 1e-300});
  return std::abs(lhs - dT) / scale;
}

/// Shaking force = inertial force + applied forces + total weight; shaking moment likewise
/// about the origin. Relative to the largest term.
inline double shaking_split_violation(const Mechanism& m, const Sample& s) {
  Vec2 f = s.inertial_force;
  double mo = s.inertial_moment, fs = s.inertial_force.norm(), ms = std::abs(s.inertial_moment);
  for (std::size_t i = 0; i < m.bodies.size(); ++i) {
    const Vec2 w = merged(m.bodies[i]).mass * m.gravity;
    f += w;
    mo += cross(s.bodies[i].com, w);
    fs = std::max(fs, w.norm());
    ms = std::max(ms, std::abs(cross(s.bodies[i].com, w)));
  }
  for (const auto& pf : m.forces) {
    const Vec2 F = pf.force(s.t), at = point_motion(m, s, pf.body, pf.point).p;
    f += F;
    mo += cross(at, F);
    fs = std::max(fs, F.norm());
    ms = std::max(ms, std::abs(cross(at, F)));
  }
  for (const auto& bm : m.moments) {
    mo += bm.moment(s.t);
    ms = std::max(ms, std::abs(bm.moment(s.t)));
  }
  fs = std::max({fs, s.shaking_force.norm(), 1e-300});
  ms = std::max({ms, std::abs(s.shaking_moment), 1e-300});
  return std::max((s.shaking_force - f).norm() / fs, std::abs(s.shaking_moment - mo) / ms);
}

}  // namespace bd::referee::selftest
