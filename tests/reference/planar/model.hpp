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

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

inline Vec2 perp(const Vec2& v) { return {-v.y(), v.x()}; }
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
inline Vec2 rotate(double phi, const Vec2& s) {
  const double c = std::cos(phi), sn = std::sin(phi);
  return {c * s.x() - sn * s.y(), sn * s.x() + c * s.y()};
}

/// A point attached to a body: local offset s from the merged centre of mass in the described
/// orientation; for the ground, s is the fixed global point.
struct Attach {
  int body = kGround;
  Vec2 s{0, 0};
};

struct LineRow {
  Attach p, from;  // the point on point_body; line_from on line_body
  int line_body = kGround;
  Vec2 u0{1, 0};  // unit direction in the described orientation
};
struct GearRow {
  int a = 0, b = 0;
  double ra = 0, rb = 0;
  Attach pa, pb;                                  // the pivots as points of a and b
  Vec2 oa{0, 0}, ob{0, 0}, t{0, 1}, pitch{0, 0};  // fixed pivots, t = perp(unit(ob - oa))
};
struct InputRow {
  bool angle = true;
  int body = 0;    // angle input
  int slider = 0;  // slide input
  double s0 = 0;   // slide input: (P - A) . u in the described configuration
};
struct SpringRow {
  Attach a, b;
};

struct Model {
  int nb = 0;
  std::vector<double> mass, inertia;
  std::vector<Vec2> com0;
  std::vector<std::pair<Attach, Attach>> pins;  // (a side, b side)
  std::vector<LineRow> lines;
  std::vector<GearRow> gears;
  std::vector<InputRow> inputs;
  std::vector<Attach> force_points;
  std::vector<SpringRow> springs;
  std::vector<std::string> row_names;  // for messages
  double length = 1;                   // characteristic length of the mechanism [m]

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
VectorXd described_q(const Model& model);

Vec2 position(const VectorXd& q, const Attach& p);
Vec2 velocity(const VectorXd& q, const VectorXd& qd, const Attach& p);
/// R(phi) s of the point (its offset from the centre of mass, current orientation); 0 for ground.
Vec2 arm(const VectorXd& q, const Attach& p);

/// Residuals of all n rows with the inputs held at `values`.
VectorXd residual(const Model& model, const VectorXd& q, const VectorXd& values);
/// The n x n constraint Jacobian (all rows).
MatrixXd jacobian(const Model& model, const VectorXd& q);
/// gamma = -(dJ/dt) q' for all rows.
VectorXd gamma(const Model& model, const VectorXd& q, const VectorXd& qd);
/// Current values of the input coordinates.
VectorXd input_values(const Model& model, const VectorXd& q);

/// Mass matrix diagonal (m, m, I per body).
VectorXd mass_diagonal(const Model& model);

/// Spring state: length, rate of length, tension, unit vector from a to b.
struct SpringState {
  double length = 0, rate = 0, tension = 0;
  Vec2 e{1, 0};
};
SpringState spring_state(const Model& model, const Mechanism& mech, std::size_t k,
                         const VectorXd& q, const VectorXd& qd);

/// Generalized applied forces at time t: gravity, point forces, moments, springs (not the
/// input efforts).
VectorXd applied_forces(const Model& model, const Mechanism& mech, double t, const VectorXd& q,
                        const VectorXd& qd);

/// Adds the generalized force of a force f acting at point p (of p.body) to Q.
void add_point_force(VectorXd& Q, const VectorXd& q, const Attach& p, const Vec2& f);

}  // namespace bd::referee::detail
