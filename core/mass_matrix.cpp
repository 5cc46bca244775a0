#include "core/mass_matrix.hpp"

#include <cmath>

#include <Eigen/QR>

#include "core/formulation_support.hpp"

namespace bd::core {

namespace {

using Mat8 = Eigen::Matrix<double, 8, 8>;
using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat43 = Eigen::Matrix<double, 4, 3>;

// joints in one vector [A0x, A0y, A1x, A1y, A2x, A2y, A3x, A3y]; link k joins joints k-1 and k,
// so its four coordinates are the contiguous segment starting at 2(k-1)

Mat8 assembled_mass_matrix(const FourBar& model) {
  Mat8 M = Mat8::Zero();
  for (int k = 1; k <= 3; ++k) M.block<4, 4>(2 * (k - 1), 2 * (k - 1)) += link_mass_matrix(link(model, k));
  return M;
}

// nodal forces of the applied loads (forces incl. gravity, moments) on all four joints [N]
Vec8 assembled_nodal_forces(const FourBar& model, const Joints& j, const Pose& pose) {
  const Vec2* nodes[4] = {&j.A0, &j.A1, &j.A2, &j.A3};
  const double thetas[3] = {pose.theta1, pose.theta2, pose.theta3};
  Vec8 F = Vec8::Zero();
  for (int k = 1; k <= 3; ++k) {
    const Link& l = link(model, k);
    const LinkLoad& load = link_load(model, k);
    // eq. 46 needs the joint positions; for link 2 use its own angle so that the nodal
    // moment terms are exact whatever the loop-closure round-off
    const Vec2& p = *nodes[k - 1];
    const Vec2 q = p + l.length * unit(thetas[k - 1]);
    F.segment<4>(2 * (k - 1)) +=
        link_nodal_forces(l, load.force + l.mass * model.loads.gravity, load.moment, p, q);
  }
  return F;
}

// Solves the mass-matrix formulation at one instant. Forward when `alpha1` is empty (tau = 0),
// inverse otherwise.
Expected<DynamicsSample, DynamicsError> solve(const FourBar& model, double theta1, double omega1,
                                              const double* alpha1_given) {
  // position stage
  const auto pose = nonsingular_pose(model, theta1);
  if (!pose) return Unexpected(pose.error());
  const double l1 = model.crank.length, l3 = model.rocker.length;
  const Vec2 e1 = unit(pose->theta1), e2 = unit(pose->theta2), e3 = unit(pose->theta3);
  const Joints j = joint_positions(model, *pose);

  // velocity stage and the velocity-product accelerations
  FourBarState s = solve_velocity(model, *pose, omega1);
  const AccelerationBias bias = acceleration_bias(model, s);
  const TransferFunctions tf = transfer_functions(model, *pose);

  // joint accelerations r̈ = J·alpha1 + c (eqs. 50-51); A0 and A3 do not move
  Vec8 J = Vec8::Zero(), c = Vec8::Zero();
  J.segment<2>(2) = l1 * perp(e1);
  J.segment<2>(4) = -tf.Theta3 * l3 * perp(e3);
  c.segment<2>(2) = -omega1 * omega1 * l1 * e1;
  c.segment<2>(4) = -(bias.gamma3 * l3 * perp(e3) - s.omega3 * s.omega3 * l3 * e3);

  const Mat8 M = assembled_mass_matrix(model);
  const Vec8 F = assembled_nodal_forces(model, j, *pose);
  // nodal forces of a unit drive moment on the crank (eq. 46 with M1 = 1): Jᵀ n = 1
  Vec8 n = Vec8::Zero();
  n.segment<4>(0) = link_nodal_forces(model.crank, Vec2(0, 0), 1.0, j.A0, j.A1);

  // reduced equation (eq. 47 with the virtual displacements of eq. 50): Jᵀ(M r̈ - F) = tau
  double alpha1 = 0, tau = 0;
  if (alpha1_given == nullptr) {
    alpha1 = J.dot(F - M * c) / J.dot(M * J);
  } else {
    alpha1 = *alpha1_given;
    tau = J.dot(M * (J * alpha1 + c) - F);
  }
  s = solve_acceleration(model, s, alpha1);

  // residual of every joint: r = M r̈ - F - tau n. At the moving joints it is carried by the
  // axial forces λ of the three links (the truss elements' length constraints g_k = |l̄k|):
  // r_free = G_freeᵀ λ. At the supports r = (Gᵀλ) - R̄ (R̄ acts ON the ground).
  const Vec8 r = M * (J * alpha1 + c) - F - tau * n;
  Mat43 Gt = Mat43::Zero();
  Gt.block<2, 1>(0, 0) = e1;   // ∂g1/∂A1
  Gt.block<2, 1>(0, 1) = -e2;  // ∂g2/∂A1
  Gt.block<2, 1>(2, 1) = e2;   // ∂g2/∂A2
  Gt.block<2, 1>(2, 2) = -e3;  // ∂g3/∂A2
  const Eigen::Vector3d lambda = Gt.householderQr().solve(r.segment<4>(2));

  DynamicsSample out;
  out.state = s;
  out.tau = tau;
  out.RA0 = -lambda(0) * e1 - r.segment<2>(0);  // ∂g1/∂A0 = -e1
  out.RA3 = lambda(2) * e3 - r.segment<2>(6);   // ∂g3/∂A3 = +e3
  return completed_sample(model, out);
}

}  // namespace

Mat4 link_mass_matrix(const Link& link) {
  // eq. 45 (García de Jalón's constant mass matrix in natural coordinates)
  const double l = link.length, m = link.mass, e = link.e, f = link.f, I = link.inertia;
  const double Ip = I + m * (e * e + f * f);                // about joint p
  const double Iq = I + m * ((l - e) * (l - e) + f * f);    // about joint q
  const double Ired = I - m * e * (l - e) + m * f * f;      // reduced
  const double l2 = l * l, mf = m * f / l;
  Mat4 Me;
  Me << Iq / l2, 0, -Ired / l2, -mf,  //
      0, Iq / l2, mf, -Ired / l2,     //
      -Ired / l2, mf, Ip / l2, 0,     //
      -mf, -Ired / l2, 0, Ip / l2;
  return Me;
}

Vec4 link_nodal_forces(const Link& link, const Vec2& force, double moment, const Vec2& p,
                       const Vec2& q) {
  // eq. 46: F at the centre of mass split by the complex weights (1 - s̄/l) and s̄/l; the
  // moment as a couple perpendicular to the link, M/l² · i(r_q - r_p) at q and its opposite at p
  const double l = link.length, xi = link.e / l, eta = link.f / l;
  const Vec2 couple = moment / (l * l) * perp(q - p);
  Vec4 out;
  out.segment<2>(0) = Vec2((1 - xi) * force.x() - eta * force.y(),
                           (1 - xi) * force.y() + eta * force.x()) -
                      couple;
  out.segment<2>(2) = Vec2(xi * force.x() + eta * force.y(), xi * force.y() - eta * force.x()) +
                      couple;
  return out;
}

SystemMassMatrices system_mass_matrices(const FourBar& model) {
  const Mat8 M = assembled_mass_matrix(model);
  SystemMassMatrices out;
  out.M = M.block<4, 4>(2, 2);
  out.Mr.topRows<2>() = M.block<2, 4>(0, 2);
  out.Mr.bottomRows<2>() = M.block<2, 4>(6, 2);
  return out;
}

Expected<DynamicsSample, DynamicsError> forward_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1,
                                                                     double omega1) {
  return solve(model, theta1, omega1, nullptr);
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1) {
  return solve(model, theta1, omega1, &alpha1);
}

}  // namespace bd::core
