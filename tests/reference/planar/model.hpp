#pragma once
// Internal: the Mechanism compiled to body-local data, the constraint functions with their
// Jacobian and acceleration right-hand side, and the applied generalized forces.
//
// Coordinates: q = (x_0, y_0, phi_0, x_1, y_1, phi_1, ...), (x_i, y_i) the merged centre of mass
// of body i and phi_i its rotation from the described configuration. A point of body i with
// local offset s (= described global point - described centre of mass) is at P = r_i + R(phi_i) s,
// so dP/dphi_i = perp(R s), perp(v) = (-v.y, v.x), and P'' = r_i'' + alpha_i perp(R s)
// - omega_i^2 R s.
//
// Constraint rows, in this order (m mechanism rows, then one row per input; m + inputs = n):
//   pin k (2 rows)   c = P_b - P_a                       multiplier = force of a ON b
//   slider k         c = (P - A) . n,  n = perp(u)        multiplier l: force l n ON point body
//   gear k           see model.cpp                        multiplier l: force l t ON body a
//   angle input      c = phi_body - value                 multiplier = torque ON body
//   slide input      c = (P - A) . u - s0 - value         multiplier l: force l u ON point body
// (u = R(phi_line) u0 the line's unit direction, A the line_from point of the line body.)
// The equations of motion are M q'' = Q + J^T lambda, and the acceleration level of c = 0 is
// J q'' = gamma + (second derivative of the input values), gamma = -(dJ/dt) q'.
#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "tests/reference/planar/referee.hpp"

namespace bd::referee::detail {

// All internal arithmetic is in long double (64-bit mantissa on x86-64): the constraint
// Jacobians have condition numbers of 1e2..1e3, so in double the velocities, accelerations and
// forces would carry ~1e-14 relative noise; in long double they are exact to double precision
// and the free-run integrator is no longer limited by noisy right-hand sides.
using Real = long double;
using Eigen::Index;
using VecX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
using MatX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using V2 = Eigen::Matrix<Real, 2, 1>;
inline V2 ext(const Vec2& v) { return v.cast<Real>(); }
inline Vec2 dbl(const V2& v) { return v.cast<double>(); }
// The user's load functions take and return double.
inline V2 force_at(const PointForce& f, Real t) { return ext(f.force(static_cast<double>(t))); }
inline Real moment_at(const BodyMoment& m, Real t) { return m.moment(static_cast<double>(t)); }

inline V2 perp(const V2& v) { return {-v.y(), v.x()}; }
inline Real cross(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }
inline V2 rotate(Real phi, const V2& s) {
  const Real c = std::cos(phi), sn = std::sin(phi);
  return {c * s.x() - sn * s.y(), sn * s.x() + c * s.y()};
}

/// A point attached to a body: local offset s from the merged centre of mass in the described
/// orientation; for the ground, s is the fixed global point.
struct Attach {
  int body = kGround;
  V2 s{0, 0};
};

struct LineRow {
  Attach p, from;  // the point on point_body; line_from on line_body
  int line_body = kGround;
  V2 u0{1, 0};  // unit direction in the described orientation
};
struct GearRow {
  int a = 0, b = 0;
  Real ra = 0, rb = 0;
  Attach pa, pb;                                // the pivots as points of a and b
  V2 oa{0, 0}, ob{0, 0}, t{0, 1}, pitch{0, 0};  // fixed pivots, t = perp(unit(ob - oa))
};
struct InputRow {
  bool angle = true;
  int body = 0;    // angle input
  int slider = 0;  // slide input
  Real s0 = 0;     // slide input: (P - A) . u in the described configuration
};
struct SpringRow {
  Attach a, b;
};

struct Model {
  int nb = 0;
  std::vector<Real> mass, inertia;
  std::vector<V2> com0;
  std::vector<std::pair<Attach, Attach>> pins;  // (a side, b side)
  std::vector<LineRow> lines;
  std::vector<GearRow> gears;
  std::vector<InputRow> inputs;
  std::vector<Attach> force_points;
  std::vector<SpringRow> springs;
  std::vector<std::string> row_names;  // for messages
  Real length = 1;                     // characteristic length of the mechanism [m]

  Index n() const { return 3 * nb; }
  Index ndof() const { return static_cast<Index>(inputs.size()); }
  Index m() const { return n() - ndof(); }
  Index gear_row(std::size_t k) const {
    return static_cast<Index>(2 * pins.size() + lines.size() + k);
  }
  Index input_row(Index k) const { return m() + k; }
};

/// Validates the mechanism and compiles it. @throws std::domain_error on invalid input.
Model compile(const Mechanism& mechanism);

/// q of the described configuration.
VecX described_q(const Model& model);

V2 position(const VecX& q, const Attach& p);
V2 velocity(const VecX& q, const VecX& qd, const Attach& p);
/// R(phi) s of the point (its offset from the centre of mass, current orientation); 0 for ground.
V2 arm(const VecX& q, const Attach& p);

/// Residuals of all n rows with the inputs held at `values`.
VecX residual(const Model& model, const VecX& q, const VecX& values);
/// The n x n constraint Jacobian (all rows).
MatX jacobian(const Model& model, const VecX& q);
/// gamma = -(dJ/dt) q' for all rows.
VecX gamma(const Model& model, const VecX& q, const VecX& qd);
/// Current values of the input coordinates.
VecX input_values(const Model& model, const VecX& q);

/// Mass matrix diagonal (m, m, I per body).
VecX mass_diagonal(const Model& model);

/// Spring state: length, rate of length, tension, unit vector from a to b.
struct SpringState {
  Real length = 0, rate = 0, tension = 0;
  V2 e{1, 0};
};
SpringState spring_state(const Model& model, const Mechanism& mech, std::size_t k, const VecX& q,
                         const VecX& qd);

/// Generalized applied forces at time t: gravity, point forces, moments, springs (not the
/// input efforts).
VecX applied_forces(const Model& model, const Mechanism& mech, Real t, const VecX& q,
                    const VecX& qd);

/// Adds the generalized force of a force f acting at point p (of p.body) to Q.
void add_point_force(VecX& Q, const VecX& q, const Attach& p, const V2& f);

}  // namespace bd::referee::detail
