#include "core/fourbar/principal_vectors.hpp"

#include "core/detail/complex_vector.hpp"

namespace bd::core {

namespace {

using detail::Complex;
using detail::to_complex;
using detail::to_vec;

// s̄_k / l_k
ComplexCoefficient relative_com(const Link& l) { return Complex(l.e, l.f) / l.length; }

// d/dt and d²/dt² of ā = c·l̄ turning at rate w, acceleration a: i w ā and (i a - w²) ā
Vec2 rate(const Vec2& v, double w) { return w * perp(v); }
Vec2 accel(const Vec2& v, double w, double a) { return a * perp(v) - w * w * v; }

}  // namespace

EquivalentMasses equivalent_masses(const Link& l) {
  const ComplexMass q = l.mass * relative_com(l);
  return {l.mass - q, q, l.mass * (1 - l.e / l.length), l.mass * l.e / l.length,
          l.mass * l.f / l.length};
}

OpenedLoopFactors opened_loop_factors(const FourBar& m) {
  const double m1 = m.crank.mass, m2 = m.coupler.mass, m3 = m.rocker.mass, mt = m1 + m2 + m3;
  const ComplexCoefficient s1 = relative_com(m.crank), s2 = relative_com(m.coupler),
                           s3 = relative_com(m.rocker);
  // eq. 12
  OpenedLoopFactors f;
  f.a12 = (1.0 - s1) * m1 / mt;
  f.a21 = -(m3 + m2 * s2) / mt;
  f.a23 = (m1 + m2 * (1.0 - s2)) / mt;
  f.a32 = -s3 * m3 / mt;
  // eq. 13
  f.a14p = -(m2 + m3 + m1 * s1) / mt;
  f.a34p = (m1 + m2 + m3 * (1.0 - s3)) / mt;
  return f;
}

FrameFactors frame_factors(const FourBar& m) {
  const double m1 = m.crank.mass, m3 = m.rocker.mass, mt = total_mass(m);
  const EquivalentMasses e2 = equivalent_masses(m.coupler);
  const ComplexCoefficient s1 = relative_com(m.crank), s3 = relative_com(m.rocker);
  // eq. 30
  FrameFactors f;
  f.a14 = -(m1 * s1 + e2.mp) / mt;
  f.a41 = (e2.mq + m3) / mt;
  f.a43 = -(m1 + e2.mp) / mt;
  f.a34 = (e2.mq + m3 * (1.0 - s3)) / mt;
  // eq. 31
  f.a12p = (m1 * (1.0 - s1) + e2.mq + m3) / mt;
  f.a32p = -(m1 + e2.mp + m3 * s3) / mt;
  return f;
}

OpenedLoopVectors opened_loop_vectors(const FourBar& m, const Pose& p) {
  return opened_loop_vectors(m, link_vectors(m, p));
}

OpenedLoopVectors opened_loop_vectors(const FourBar& m, const LinkVectors& l) {
  const OpenedLoopFactors f = opened_loop_factors(m);
  const Complex l1 = to_complex(l.l1), l2 = to_complex(l.l2), l3 = to_complex(l.l3);
  return {to_vec(f.a12 * l1), to_vec(f.a21 * l2),  to_vec(f.a23 * l2),
          to_vec(f.a32 * l3), to_vec(f.a14p * l1), to_vec(f.a34p * l3)};
}

FrameVectors frame_vectors(const FourBar& m, const Pose& p) {
  return frame_vectors(m, link_vectors(m, p));
}

FrameVectors frame_vectors(const FourBar& m, const LinkVectors& l) {
  const FrameFactors f = frame_factors(m);
  const Complex l1 = to_complex(l.l1), l3 = to_complex(l.l3), l4(-m.frame_length, 0.0);
  return {to_vec(f.a14 * l1), to_vec(f.a41 * l4),  to_vec(f.a43 * l4),
          to_vec(f.a34 * l3), to_vec(f.a12p * l1), to_vec(f.a32p * l3)};
}

PrincipalPoints opened_loop_principal_points(const FourBar& m, const Pose& p) {
  const OpenedLoopVectors a = opened_loop_vectors(m, p);
  const Joints j = joint_positions(m, p);
  return {j.A0 - a.a14p, j.A1 - a.a21, j.A2 - a.a32};
}

FramePrincipalPoints frame_principal_points(const FourBar& m, const Pose& p) {
  const FrameVectors a = frame_vectors(m, p);
  const Joints j = joint_positions(m, p);
  return {j.A0 - a.a14, j.A3 - a.a34, j.A0 - a.a41};
}

PointKinematics centre_of_mass_opened_loop(const FourBar& m, const FourBarState& s) {
  return centre_of_mass_opened_loop(opened_loop_vectors(m, pose_of(s)), s);
}

PointKinematics centre_of_mass_opened_loop(const OpenedLoopVectors& a, const FourBarState& s) {
  // eq. 16 with r̄_A0 = 0: r̄_S = -ā14' - ā21 - ā32
  PointKinematics S;
  S.r = -a.a14p - a.a21 - a.a32;
  S.v = -rate(a.a14p, s.omega1) - rate(a.a21, s.omega2) - rate(a.a32, s.omega3);
  S.a = -accel(a.a14p, s.omega1, s.alpha1) - accel(a.a21, s.omega2, s.alpha2) -
        accel(a.a32, s.omega3, s.alpha3);
  return S;
}

PointKinematics centre_of_mass_frame(const FourBar& m, const FourBarState& s) {
  return centre_of_mass_frame(frame_vectors(m, pose_of(s)), s);
}

PointKinematics centre_of_mass_frame(const FrameVectors& a, const FourBarState& s) {
  // eq. 32: r̄_S = -ā14 - ā41 - ā34, with ā41 fixed in the frame
  PointKinematics S;
  S.r = -a.a14 - a.a41 - a.a34;
  S.v = -rate(a.a14, s.omega1) - rate(a.a34, s.omega3);
  S.a = -accel(a.a14, s.omega1, s.alpha1) - accel(a.a34, s.omega3, s.alpha3);
  return S;
}

}  // namespace bd::core
