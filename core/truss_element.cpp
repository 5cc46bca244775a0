#include "core/truss_element.hpp"

namespace bd::core {

Mat4 element_mass_matrix(const ElementMass& link) {
  const double l = link.length, m = link.mass, e = link.e, f = link.f, I = link.inertia;
  const double Ip = I + m * (e * e + f * f);              // about p
  const double Iq = I + m * ((l - e) * (l - e) + f * f);  // about q
  const double Ired = I - m * e * (l - e) + m * f * f;    // reduced
  const double l2 = l * l, u = -Ired / l2, v = m * f / l;
  Mat4 M;
  M << Iq / l2, 0, u, -v,  //
      0, Iq / l2, v, u,    //
      u, v, Ip / l2, 0,    //
      -v, u, 0, Ip / l2;
  return M;
}

PointWeights point_weights(double xi, double eta) {
  PointWeights w;
  w.at_p << 1 - xi, eta, -eta, 1 - xi;
  w.at_q << xi, -eta, eta, xi;
  return w;
}

Vec2 link_coordinates(const Vec2& p, const Vec2& q, const Vec2& r) {
  const Vec2 d = q - p, a = r - p;
  const double n = d.squaredNorm();
  return {(a.x() * d.x() + a.y() * d.y()) / n, (a.y() * d.x() - a.x() * d.y()) / n};
}

Vec4 element_nodal_forces(const PointWeights& at, const Vec2& force, double moment, const Vec2& p,
                          const Vec2& q) {
  const Vec2 d = q - p;
  const Vec2 couple = moment / d.squaredNorm() * perp(d);
  Vec4 out;
  out.segment<2>(0) = at.at_p.transpose() * force - couple;
  out.segment<2>(2) = at.at_q.transpose() * force + couple;
  return out;
}

}  // namespace bd::core
