#include "core/mass_matrix.hpp"

#include <cmath>

#include "core/formulation_support.hpp"

namespace bd::core {

namespace {

using Mat8 = Eigen::Matrix<double, 8, 8>;
using Vec8 = Eigen::Matrix<double, 8, 1>;

// joints in one vector [A0x, A0y, A1x, A1y, A2x, A2y, A3x, A3y]; link k joins joints k-1 and k,
// so its four coordinates are the contiguous segment starting at 2(k-1)

Mat8 assembled_mass_matrix(const FourBar& model) {
  Mat8 M = Mat8::Zero();
  for (int k = 1; k <= 3; ++k) M.block<4, 4>(2 * (k - 1), 2 * (k - 1)) += link_mass_matrix(link(model, k));
  return M;
}

// nodal forces of the applied loads (forces incl. gravity, moments) on all four joints [N];
// link k runs from joint k-1 along its link vector l̄k (eq. 46 needs the joint positions, and
// taking the second joint as first + l̄k makes the nodal moment terms exact whatever the
// loop-closure round-off)
Vec8 assembled_nodal_forces(const FourBar& model, const Joints& j, const LinkVectors& l) {
  const Vec2* nodes[3] = {&j.A0, &j.A1, &j.A2};
  const Vec2* links[3] = {&l.l1, &l.l2, &l.l3};
  Vec8 F = Vec8::Zero();
  for (int k = 1; k <= 3; ++k) {
    const Link& link_k = link(model, k);
    const LinkLoad& load = link_load(model, k);
    const Vec2& p = *nodes[k - 1];
    const Vec2 q = p + *links[k - 1];
    F.segment<4>(2 * (k - 1)) += link_nodal_forces(
        link_k, load.force + link_k.mass * model.loads.gravity, load.moment, p, q);
  }
  return F;
}

// The blocks of the 8x8 assembled matrix that the solve needs: the moving joints among
// themselves (M) and the supports against the moving joints (Mr). The joint accelerations are
// nonzero at A1 and A2 only, so M r̈ needs no other block; assembling them from the three link
// matrices directly skips the 8x8 matrix and its products, most of whose entries are zero.
SystemMassMatrices mass_matrix_blocks(const FourBar& model) {
  const Mat4 M1 = link_mass_matrix(model.crank), M2 = link_mass_matrix(model.coupler),
             M3 = link_mass_matrix(model.rocker);
  SystemMassMatrices out;
  // moving joints [A1, A2]: the crank's q-q block, the whole coupler, the rocker's p-p block
  out.M = M2;
  out.M.topLeftCorner<2, 2>() += M1.bottomRightCorner<2, 2>();
  out.M.bottomRightCorner<2, 2>() += M3.topLeftCorner<2, 2>();
  // supports: A0 couples to A1 through the crank, A3 to A2 through the rocker
  out.Mr.setZero();
  out.Mr.topLeftCorner<2, 2>() = M1.topRightCorner<2, 2>();
  out.Mr.bottomRightCorner<2, 2>() = M3.bottomLeftCorner<2, 2>();
  return out;
}

// Solves the mass-matrix formulation at one instant. Forward when `alpha1` is empty (tau = 0),
// inverse otherwise.
Expected<DynamicsSample, DynamicsError> solve(const FourBar& model, double theta1, double omega1,
                                              const double* alpha1_given) {
  // position and velocity stages and the velocity-product accelerations, once for the instant
  const auto instant = nonsingular_instant(model, theta1, omega1);
  if (!instant) return Unexpected(instant.error());
  const LinkVectors& l = instant->l;
  const double l1 = model.crank.length, l2 = model.coupler.length, l3 = model.rocker.length;
  const Vec2 e1 = l.l1 / l1, e2 = l.l2 / l2, e3 = l.l3 / l3;  // link directions
  const Vec2 A3(model.frame_length, 0.0);
  const Joints j{Vec2(0.0, 0.0), l.l1, A3 - l.l3, A3};
  const double omega3 = instant->state.omega3;

  // accelerations of the moving joints [A1, A2]: r̈ = J·alpha1 + c (eqs. 50-51); A0 and A3 do
  // not move
  Vec4 J, c;
  J << l1 * perp(e1), -instant->tf.Theta3 * l3 * perp(e3);
  c << -omega1 * omega1 * l1 * e1,
      -(instant->bias.gamma3 * l3 * perp(e3) - omega3 * omega3 * l3 * e3);

  const SystemMassMatrices blocks = mass_matrix_blocks(model);
  const Vec8 F = assembled_nodal_forces(model, j, l);
  const Vec4 F_free = F.segment<4>(2);
  // nodal forces of a unit drive moment on the crank (eq. 46 with M1 = 1) at A0 and A1: Jᵀ n = 1
  const Vec4 n = link_nodal_forces(model.crank, Vec2(0, 0), 1.0, j.A0, j.A1);

  // reduced equation (eq. 47 with the virtual displacements of eq. 50): Jᵀ(M r̈ - F) = tau
  double alpha1 = 0, tau = 0;
  if (alpha1_given == nullptr) {
    alpha1 = J.dot(F_free - blocks.M * c) / J.dot(blocks.M * J);
  } else {
    alpha1 = *alpha1_given;
    tau = J.dot(blocks.M * (J * alpha1 + c) - F_free);
  }
  const FourBarState s = instant->accelerated(alpha1);

  // residual of every joint: r = M r̈ - F - tau n. At the moving joints it is carried by the
  // axial forces λ of the three links (the truss elements' length constraints g_k = |l̄k|):
  // r_free = G_freeᵀ λ. At the supports r = (Gᵀλ) - R̄ (R̄ acts ON the ground).
  const Vec4 a_free = J * alpha1 + c;
  Vec4 r_free = blocks.M * a_free - F_free;
  r_free.head<2>() -= tau * n.tail<2>();  // the drive moment acts at A1 (and A0)
  const Vec4 r_supports = blocks.Mr * a_free;  // [A0, A3], inertia part
  const Vec2 r_A0 = r_supports.head<2>() - F.head<2>() - tau * n.head<2>();
  const Vec2 r_A3 = r_supports.tail<2>() - F.tail<2>();
  // G_freeᵀ = [e1 -e2 0; 0 e2 -e3] (∂g1/∂A1 = e1, ∂g2/∂A1 = -e2, ∂g2/∂A2 = e2, ∂g3/∂A2 = -e3)
  // has full column rank, and r_free lies in its range (Jᵀ r_free = 0 is the reduced equation),
  // so the four equations are solved exactly by elimination instead of a 4x3 least-squares QR:
  // the A2 rows, λ2 e2 - λ3 e3 = r_A2, give λ2 and λ3 by Cramer's rule with e2 × e3 =
  // sin(theta3 - theta2), away from zero wherever the dynamics is evaluated (nonsingular_instant);
  // then the A1 rows, λ1 e1 = r_A1 + λ2 e2, projected on e1 give λ1.
  const Vec2 r_A1 = r_free.head<2>(), r_A2 = r_free.tail<2>();
  const double sin23 = cross(e2, e3);
  const double lambda2 = cross(r_A2, e3) / sin23;
  const double lambda3 = cross(r_A2, e2) / sin23;
  const double lambda1 = e1.dot(r_A1 + lambda2 * e2);

  DynamicsSample out;
  out.state = s;
  out.tau = tau;
  out.RA0 = -lambda1 * e1 - r_A0;  // ∂g1/∂A0 = -e1
  out.RA3 = lambda3 * e3 - r_A3;   // ∂g3/∂A3 = +e3
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
