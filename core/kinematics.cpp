#include "core/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace bd::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// s̄_k turned into ground axes at link angle theta: R(theta)·(e, f) [m]
Vec2 com_offset(const Link& l, double theta) {
  const Vec2 u = unit(theta);
  return l.e * u + l.f * perp(u);
}

double link_angle(const FourBarState& s, int k) {
  return k == 1 ? s.theta1 : (k == 2 ? s.theta2 : s.theta3);
}
double link_rate(const FourBarState& s, int k) {
  return k == 1 ? s.omega1 : (k == 2 ? s.omega2 : s.omega3);
}
double link_acceleration(const FourBarState& s, int k) {
  return k == 1 ? s.alpha1 : (k == 2 ? s.alpha2 : s.alpha3);
}

}  // namespace

std::string AssemblyError::what() const {
  char buf[200];
  if (gap > 0) {
    std::snprintf(buf, sizeof buf,
                  "loop cannot close at theta1 = %.6g rad: |A1A3| exceeds l2 + l3 by %.3g m",
                  theta1, gap);
  } else if (gap < 0) {
    std::snprintf(buf, sizeof buf,
                  "loop cannot close at theta1 = %.6g rad: |A1A3| falls short of |l2 - l3| by "
                  "%.3g m",
                  theta1, -gap);
  } else {
    std::snprintf(buf, sizeof buf,
                  "loop cannot close at theta1 = %.6g rad: A1 coincides with A3, the coupler "
                  "direction is undefined",
                  theta1);
  }
  return buf;
}

LinkVectors link_vectors(const FourBar& m, const Pose& p) {
  return {m.crank.length * unit(p.theta1), m.coupler.length * unit(p.theta2),
          m.rocker.length * unit(p.theta3)};
}

Expected<ClosedLoop, AssemblyError> solve_loop(const FourBar& model, double theta1, Branch branch) {
  const double l1 = model.crank.length, l2 = model.coupler.length, l3 = model.rocker.length,
               l4 = model.frame_length;
  // l̄23 = l̄2 + l̄3 = -l̄1 - l̄4 = A3 - A1 (eq. 2)
  const Vec2 l1v = l1 * unit(theta1);
  const Vec2 l23v(l4 - l1v.x(), -l1v.y());
  const double l23 = l23v.norm();
  if (!(l23 > 0)) return Unexpected(AssemblyError{theta1, 0.0});

  // triangle l2, l3, l23: Kahan's stable Heron formula, sides sorted a >= b >= c;
  // the only factor that can turn negative is c - (a - b) (triangle inequality violated)
  double a = l2, b = l3, c = l23;
  if (a < b) std::swap(a, b);
  if (b < c) std::swap(b, c);
  if (a < b) std::swap(a, b);
  double slack = c - (a - b);
  if (slack < 0) {
    // within round-off of a flat triangle: accept as flat
    if (slack >= -8 * kEps * a) {
      slack = 0;
    } else {
      const double gap = (a == l23) ? l23 - (l2 + l3) : l23 - std::abs(l2 - l3);
      return Unexpected(AssemblyError{theta1, gap});
    }
  }
  const double area4 = std::sqrt((a + (b + c)) * slack * (c + (a - b)) * (a + (b - c)));
  // eq. 3: d23 along l̄23 from A1, h23 to its left (branch +1)
  const double d23 = (l23 * l23 + (l2 - l3) * (l2 + l3)) / (2 * l23);
  const double h23 = sign(branch) * area4 / (2 * l23);
  // eq. 4: l̄2 = (d23 + i h23) l̄23 / l23, l̄3 = l̄23 - l̄2
  const Vec2 u = l23v / l23;
  const Vec2 l2v = d23 * u + h23 * perp(u);
  const Vec2 l3v = l23v - l2v;
  return ClosedLoop{Pose{theta1, std::atan2(l2v.y(), l2v.x()), std::atan2(l3v.y(), l3v.x())},
                    LinkVectors{l1v, l2v, l3v}};
}

Expected<Pose, AssemblyError> solve_position(const FourBar& model, double theta1, Branch branch) {
  const auto loop = solve_loop(model, theta1, branch);
  if (!loop) return Unexpected(loop.error());
  return loop->pose;
}

Expected<Pose, AssemblyError> solve_position(const FourBar& model, double theta1) {
  return solve_position(model, theta1, model.branch);
}

TransferFunctions transfer_functions(const FourBar& model, const Pose& p) {
  return transfer_functions(link_vectors(model, p));
}

TransferFunctions transfer_functions(const LinkVectors& v) {
  // eq. 7 via cross products: l̄1 Θ1 + l̄2 Θ2 + l̄3 Θ3 = 0 (eq. 5), crossed with l̄3 and l̄2
  return {-cross(v.l3, v.l1) / cross(v.l3, v.l2), -cross(v.l2, v.l1) / cross(v.l2, v.l3)};
}

FourBarState solve_velocity(const FourBar& model, const Pose& pose, double omega1) {
  const TransferFunctions tf = transfer_functions(model, pose);
  FourBarState s;
  s.theta1 = pose.theta1;
  s.theta2 = pose.theta2;
  s.theta3 = pose.theta3;
  s.omega1 = omega1;
  s.omega2 = tf.Theta2 * omega1;
  s.omega3 = tf.Theta3 * omega1;
  return s;
}

AccelerationBias acceleration_bias(const FourBar& model, const FourBarState& s) {
  return acceleration_bias(link_vectors(model, pose_of(s)), s);
}

AccelerationBias acceleration_bias(const LinkVectors& v, const FourBarState& s) {
  // eq. 8: Σ l̄k α_k = -i b with b = Σ l̄k ω_k²; crossed with l̄3 and l̄2 (eqs. 9-10)
  const Vec2 b = v.l1 * (s.omega1 * s.omega1) + v.l2 * (s.omega2 * s.omega2) +
                 v.l3 * (s.omega3 * s.omega3);
  return {-v.l3.dot(b) / cross(v.l3, v.l2), -v.l2.dot(b) / cross(v.l2, v.l3)};
}

FourBarState solve_acceleration(const FourBar& model, FourBarState s, double alpha1) {
  const TransferFunctions tf = transfer_functions(model, pose_of(s));
  const AccelerationBias g = acceleration_bias(model, s);
  s.alpha1 = alpha1;
  s.alpha2 = tf.Theta2 * alpha1 + g.gamma2;
  s.alpha3 = tf.Theta3 * alpha1 + g.gamma3;
  return s;
}

Joints joint_positions(const FourBar& model, double theta1, double theta3) {
  const Vec2 A3(model.frame_length, 0.0);
  return {Vec2(0.0, 0.0), model.crank.length * unit(theta1), A3 - model.rocker.length * unit(theta3),
          A3};
}

Vec2 centre_of_mass(const FourBar& model, int k, const Pose& p) {
  const Joints j = joint_positions(model, p);
  const Vec2& first = k == 1 ? j.A0 : (k == 2 ? j.A1 : j.A2);
  const double theta = k == 1 ? p.theta1 : (k == 2 ? p.theta2 : p.theta3);
  return first + com_offset(link(model, k), theta);
}

Vec2 centre_of_mass_velocity(const FourBar& model, int k, const FourBarState& s) {
  const Vec2 l1v = model.crank.length * unit(s.theta1);
  const Vec2 l3v = model.rocker.length * unit(s.theta3);
  // velocity of the link's first joint: A0 fixed, A1 turns about A0, A2 about A3
  const Vec2 v_first = k == 1 ? Vec2(0, 0)
                              : (k == 2 ? Vec2(s.omega1 * perp(l1v)) : Vec2(-s.omega3 * perp(l3v)));
  const Vec2 rho = com_offset(link(model, k), link_angle(s, k));
  return v_first + link_rate(s, k) * perp(rho);
}

Vec2 centre_of_mass_acceleration(const FourBar& model, int k, const FourBarState& s) {
  const Vec2 l1v = model.crank.length * unit(s.theta1);
  const Vec2 l3v = model.rocker.length * unit(s.theta3);
  const Vec2 a_A1 = s.alpha1 * perp(l1v) - s.omega1 * s.omega1 * l1v;
  const Vec2 a_A2 = -(s.alpha3 * perp(l3v) - s.omega3 * s.omega3 * l3v);
  const Vec2 a_first = k == 1 ? Vec2(0, 0) : (k == 2 ? a_A1 : a_A2);
  const Vec2 rho = com_offset(link(model, k), link_angle(s, k));
  const double w = link_rate(s, k);
  return a_first + link_acceleration(s, k) * perp(rho) - w * w * rho;
}

double transmission_angle(const Pose& p) {
  // angle at A2 between A2->A1 (= -l̄2) and A2->A3 (= l̄3)
  const Vec2 a = -unit(p.theta2), b = unit(p.theta3);
  return std::atan2(std::abs(cross(a, b)), a.dot(b));
}

double closure_residual(const FourBar& model, const Pose& p) {
  const LinkVectors v = link_vectors(model, p);
  return (v.l1 + v.l2 + v.l3 + Vec2(-model.frame_length, 0.0)).norm();
}

}  // namespace bd::core
