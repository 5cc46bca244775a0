// The constraint functions c(q), their Jacobian J = dc/dq and gamma = -(dJ/dt) q'.
//
// Derivations (d = P - A, u = R(phi_L) u0, n = perp(u); du/dphi_L = n, dn/dphi_L = -u;
// u' = omega_L n, n' = -omega_L u):
//
// Pin: c = P_b - P_a. c'' = J q'' - omega_b^2 R_b s_b + omega_a^2 R_a s_a, so
//   gamma = omega_b^2 R_b s_b - omega_a^2 R_a s_a.
// Slider: c = d . n. dc/dr_p = n, dc/dphi_p = n . perp(R_p s_p), dc/dr_L = -n,
//   dc/dphi_L = -n . perp(R_L s_A) - d . u.
//   c'' = d'' . n + 2 d' . n' + d . n'' with n'' = -alpha_L u - omega_L^2 n gives
//   gamma = omega_p^2 (R_p s_p) . n - omega_L^2 (R_L s_A) . n + 2 omega_L d' . u
//           + omega_L^2 d . n.
// Slide input: c = d . u - s0 - value. dc/dr_p = u, dc/dphi_p = u . perp(R_p s_p), dc/dr_L = -u,
//   dc/dphi_L = -u . perp(R_L s_A) + d . n; with u'' = alpha_L n - omega_L^2 u:
//   gamma = omega_p^2 (R_p s_p) . u - omega_L^2 (R_L s_A) . u - 2 omega_L d' . n
//           + omega_L^2 d . u.
// Gear (external mesh, pivots O_a, O_b fixed, t = perp(unit(O_b - O_a)), pitch point M):
//   c = r_a phi_a + r_b phi_b + t . (P_a(pivot) - O_a) - t . (P_b(pivot) - O_b).
//   Where the pivot pins hold, this is the rolling condition r_a omega_a + r_b omega_b = 0
//   (the added terms are combinations of the pivot pins' constraints), and its gradient is
//   [t, (M - r_a) x t] for body a and [-t, -(M - r_b) x t] for body b: exactly the gradient
//   of t . (velocity of a's material point at M - velocity of b's). So its multiplier l is
//   the tangential mesh force: l t ON a at M and -l t ON b at M (not a pure torque; the pivot
//   pins then carry the correct bearing forces).
//   gamma = omega_a^2 t . (R_a s_pa) - omega_b^2 t . (R_b s_pb).
// Angle input: c = phi - value, gamma = 0.
#include "tests/reference/planar/model.hpp"

namespace bd::referee::detail {

namespace {

Real angle_of(const VecX& q, int body) { return body == kGround ? 0.0 : q[3 * body + 2]; }
Real omega_of(const VecX& qd, int body) { return body == kGround ? 0.0 : qd[3 * body + 2]; }
V2 line_dir(const VecX& q, const LineRow& l) { return rotate(angle_of(q, l.line_body), l.u0); }

// Adds sign * gradient of w . P(q) for a point p to row `row` of J (w held fixed).
void add_point_gradient(MatX& J, Index row, const VecX& q, const Attach& p, const V2& w,
                        Real sign) {
  if (p.body == kGround) return;
  const Index c = 3 * p.body;
  J(row, c) += sign * w.x();
  J(row, c + 1) += sign * w.y();
  J(row, c + 2) += sign * w.dot(perp(arm(q, p)));
}

}  // namespace

V2 arm(const VecX& q, const Attach& p) {
  return p.body == kGround ? V2(0, 0) : rotate(q[3 * p.body + 2], p.s);
}
V2 position(const VecX& q, const Attach& p) {
  if (p.body == kGround) return p.s;
  return V2(q.segment<2>(3 * p.body)) + rotate(q[3 * p.body + 2], p.s);
}
V2 velocity(const VecX& q, const VecX& qd, const Attach& p) {
  if (p.body == kGround) return {0, 0};
  return V2(qd.segment<2>(3 * p.body)) + qd[3 * p.body + 2] * perp(arm(q, p));
}

VecX input_values(const Model& model, const VecX& q) {
  VecX v(model.ndof());
  for (Index k = 0; k < model.ndof(); ++k) {
    const InputRow& in = model.inputs[k];
    if (in.angle) {
      v[k] = q[3 * in.body + 2];
    } else {
      const LineRow& l = model.lines[in.slider];
      v[k] = (position(q, l.p) - position(q, l.from)).dot(line_dir(q, l)) - in.s0;
    }
  }
  return v;
}

VecX residual(const Model& model, const VecX& q, const VecX& values) {
  VecX c(model.n());
  Index r = 0;
  for (const auto& [a, b] : model.pins) {
    c.segment<2>(r) = position(q, b) - position(q, a);
    r += 2;
  }
  for (const auto& l : model.lines) {
    c[r++] = (position(q, l.p) - position(q, l.from)).dot(perp(line_dir(q, l)));
  }
  for (const auto& g : model.gears) {
    c[r++] = g.ra * q[3 * g.a + 2] + g.rb * q[3 * g.b + 2] + g.t.dot(position(q, g.pa) - g.oa) -
             g.t.dot(position(q, g.pb) - g.ob);
  }
  c.tail(model.ndof()) = input_values(model, q) - values;
  return c;
}

MatX jacobian(const Model& model, const VecX& q) {
  MatX J = MatX::Zero(model.n(), model.n());
  Index r = 0;
  for (const auto& [a, b] : model.pins) {
    for (int axis = 0; axis < 2; ++axis, ++r) {
      const V2 w = axis == 0 ? V2(1, 0) : V2(0, 1);
      add_point_gradient(J, r, q, b, w, 1);
      add_point_gradient(J, r, q, a, w, -1);
    }
  }
  auto line_row = [&](const LineRow& l, const V2& w, Real extra) {
    add_point_gradient(J, r, q, l.p, w, 1);
    add_point_gradient(J, r, q, l.from, w, -1);
    if (l.line_body != kGround) J(r, 3 * l.line_body + 2) += extra;
    ++r;
  };
  for (const auto& l : model.lines) {
    const V2 u = line_dir(q, l), d = position(q, l.p) - position(q, l.from);
    line_row(l, perp(u), -d.dot(u));
  }
  for (const auto& g : model.gears) {
    J(r, 3 * g.a + 2) += g.ra;
    J(r, 3 * g.b + 2) += g.rb;
    add_point_gradient(J, r, q, g.pa, g.t, 1);
    add_point_gradient(J, r, q, g.pb, g.t, -1);
    ++r;
  }
  for (const auto& in : model.inputs) {
    if (in.angle) {
      J(r++, 3 * in.body + 2) = 1;
    } else {
      const LineRow& l = model.lines[in.slider];
      const V2 u = line_dir(q, l), d = position(q, l.p) - position(q, l.from);
      line_row(l, u, d.dot(perp(u)));
    }
  }
  return J;
}

namespace {

// gamma of a slider row (normal: direction n) or of a slide-input row (direction u).
Real line_gamma(const VecX& q, const VecX& qd, const LineRow& l, bool normal) {
  const V2 u = line_dir(q, l), n = perp(u);
  const V2 d = position(q, l.p) - position(q, l.from);
  const V2 dd = velocity(q, qd, l.p) - velocity(q, qd, l.from);
  const Real wp = omega_of(qd, l.p.body), wl = omega_of(qd, l.line_body);
  const V2 w = normal ? n : u;
  const Real base =
      wp * wp * arm(q, l.p).dot(w) - wl * wl * arm(q, l.from).dot(w) + wl * wl * d.dot(w);
  return normal ? base + 2 * wl * dd.dot(u) : base - 2 * wl * dd.dot(n);
}

}  // namespace

VecX gamma(const Model& model, const VecX& q, const VecX& qd) {
  VecX g = VecX::Zero(model.n());
  Index r = 0;
  for (const auto& [a, b] : model.pins) {
    const Real wa = omega_of(qd, a.body), wb = omega_of(qd, b.body);
    g.segment<2>(r) = wb * wb * arm(q, b) - wa * wa * arm(q, a);
    r += 2;
  }
  for (const auto& l : model.lines) g[r++] = line_gamma(q, qd, l, true);
  for (const auto& gr : model.gears) {
    const Real wa = qd[3 * gr.a + 2], wb = qd[3 * gr.b + 2];
    g[r++] = wa * wa * gr.t.dot(arm(q, gr.pa)) - wb * wb * gr.t.dot(arm(q, gr.pb));
  }
  for (const auto& in : model.inputs) {
    g[r++] = in.angle ? 0.0 : line_gamma(q, qd, model.lines[in.slider], false);
  }
  return g;
}

}  // namespace bd::referee::detail
