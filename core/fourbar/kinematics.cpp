#include "core/fourbar/kinematics.hpp"

#include <fmt/printf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/fourbar/detail/loop_closure.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::close_loop;
using detail::LoopXy;
using detail::to_vec2;
using detail::xy;

namespace {

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
  std::string buf;
  if (gap > 0) {
    buf = fmt::sprintf("loop cannot close at theta1 = %.6g rad: |A1A3| exceeds l2 + l3 by %.3g m",
                       theta1, gap);
  } else if (gap < 0) {
    buf = fmt::sprintf(
        "loop cannot close at theta1 = %.6g rad: |A1A3| falls short of |l2 - l3| by "
        "%.3g m",
        theta1, -gap);
  } else {
    buf = fmt::sprintf(
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
  return solve_loop(model, theta1, model.crank.length * unit(theta1), branch);
}

Expected<ClosedLoop, AssemblyError> solve_loop(const FourBar& model, double theta1, const Vec2& l1,
                                               Branch branch) {
  LoopXy loop;
  if (const auto error = close_loop(model, theta1, xy(l1), branch, loop)) return Unexpected(*error);
  return ClosedLoop{Pose{theta1, link_angle(loop.l2), link_angle(loop.l3)},
                    LinkVectors{l1, to_vec2(loop.l2), to_vec2(loop.l3)}};
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
  return transfer_functions(v, 1.0 / cross(v.l2, v.l3));
}

FourBarState solve_velocity(const FourBar& model, const Pose& pose, double omega1) {
  const TransferFunctions tf = transfer_functions(model, pose);
  FourBarState s;
  s.theta1 = pose.theta1;
  s.theta2 = pose.theta2;
  s.theta3 = pose.theta3;
  s.omega1 = omega1;
  s.omega2 = tf.dtheta2_dtheta1 * omega1;
  s.omega3 = tf.dtheta3_dtheta1 * omega1;
  return s;
}

AccelerationBias acceleration_bias(const FourBar& model, const FourBarState& s) {
  return acceleration_bias(link_vectors(model, pose_of(s)), s);
}

AccelerationBias acceleration_bias(const LinkVectors& v, const FourBarState& s) {
  return acceleration_bias(v, s, 1.0 / cross(v.l2, v.l3));
}

FourBarState solve_acceleration(const FourBar& model, FourBarState s, double alpha1) {
  const TransferFunctions tf = transfer_functions(model, pose_of(s));
  const AccelerationBias g = acceleration_bias(model, s);
  s.alpha1 = alpha1;
  s.alpha2 = tf.dtheta2_dtheta1 * alpha1 + g.gamma2;
  s.alpha3 = tf.dtheta3_dtheta1 * alpha1 + g.gamma3;
  return s;
}

Joints joint_positions(const FourBar& model, double theta1, double theta3) {
  const Vec2 A3(model.frame_length, 0.0);
  return {Vec2(0.0, 0.0), model.crank.length * unit(theta1),
          A3 - model.rocker.length * unit(theta3), A3};
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
  const Vec2 v_first =
      k == 1 ? Vec2(0, 0) : (k == 2 ? Vec2(s.omega1 * perp(l1v)) : Vec2(-s.omega3 * perp(l3v)));
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
