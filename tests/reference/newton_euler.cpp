// The Newton–Euler referee: each moving link is a free rigid body held by its pins.
//
// Unknown pin forces (ground axes):
//   P0  ground  -> crank   at A0          P1  crank   -> coupler at A1
//   P2  coupler -> rocker  at A2          P3  ground  -> rocker  at A3
// so the crank feels -P1 at A1 and the coupler feels -P2 at A2 (action = reaction), and the
// reactions of the mechanism ON the ground are RA0 = -P0, RA3 = -P3.
//
// Link k has mass m_k, inertia I_k about its centre of mass c_k, applied force F_k (at c_k),
// moment M_k and weight m_k g; tau acts on the crank from the frame. With a_k the acceleration
// of c_k and alpha_k the angular acceleration, Newton (force) and Euler (moment about c_k):
//
//   crank    P0 - P1           = m1 a1 - F1 - m1 g
//            (A0-c1)xP0 - (A1-c1)xP1 + tau = I1 alpha1 - M1
//   coupler  P1 - P2           = m2 a2 - F2 - m2 g
//            (A1-c2)xP1 - (A2-c2)xP2       = I2 alpha2 - M2
//   rocker   P2 + P3           = m3 a3 - F3 - m3 g
//            (A2-c3)xP2 + (A3-c3)xP3       = I3 alpha3 - M3
//
// (x is the planar cross product). The kinematics makes every acceleration affine in alpha1:
//   alpha_k = Theta_k alpha1 + gamma_k          (Theta_1 = 1, gamma_1 = 0)
//   a_k     = a0_k + J_k alpha1,   J_k = dc_k/dtheta1
// where a0_k is the centre-of-mass acceleration at alpha1 = 0 (alpha_k = gamma_k) and J_k is the
// centre-of-mass velocity at unit crank rate (omega_k = Theta_k): differentiating v_k = J_k omega1
// gives a_k = J_k alpha1 + (dJ_k/dtheta1) omega1^2. Centre-of-mass accelerations follow from the
// joint accelerations as a_c = a_joint + alpha x rho - omega^2 rho, rho = c - joint.
//
// Counter-rotating discs (model.counter_rotations, each present when its J > 0) are further rigid
// bodies. Disc d turns on a shaft fixed in the frame at C, geared to link k (crank: pivot P = A0,
// rocker: pivot P = A3) with ratio -1: a gear rigid with link k, centred on P, meshes with the
// disc's gear, both of pitch radius |C - P|/2, at M = (P + C)/2. Rolling without slip at M:
// link k's gear has v_M = omega_k perp(M - P) = omega_k perp(C - P)/2 and the disc's gear
// omega_disc perp(M - C) = -omega_disc perp(C - P)/2, so omega_disc = -omega_k and
// alpha_disc = -alpha_k. The ideal mesh carries only the tangential force G = g t,
// t = perp(C - P)/|C - P|, ON the disc at M, and -G ON link k at M. The disc's centre of mass is
// on its shaft (it never translates; its weight goes straight into the shaft and is not modelled).
// Unknowns per disc: the shaft's bearing force B ON the disc (2) and g (1). Its equations:
//
//   disc     B + g t                  = 0                    (no translation)
//            (M - C) x (g t)          = J alpha_disc = -J alpha_k   (moment about the shaft)
//
// and link k gains -g t in its force equation and -(M - c_k) x (g t) in its moment equation.
// The force ON the ground at the shaft is RC = -B.
//
// Nine equations plus three per disc; the unknowns are the eight pin-force components, the
// disc unknowns and one more:
//   forward dynamics: alpha1 (tau = 0), moving -m_k J_k alpha1, -I_k Theta_k alpha1 and the
//                     discs' +J Theta_k alpha1 left;
//   inverse dynamics: tau (alpha1 given), a +1 in the crank's moment row.
// A 9x9, 12x12 or 15x15 LU solve gives them. Then Fsh = RA0 + RA3 + RC1 + RC3 and, about A0,
// Msh = l4 RA3y - tau + C1 x RC1 + C3 x RC3 (the drive's stator reacts on the frame with -tau;
// the shafts carry RC1, RC3 into the frame at C1, C3). Without discs the 9x9 system is exactly
// the one of the plain four-bar.
#include "tests/reference/newton_euler.hpp"

#include <Eigen/Dense>
#include <stdexcept>
#include <string>

namespace bd::reference {
namespace {

// the largest system: nine link equations and three per disc, two discs
constexpr int kMaxUnknowns = 15;
using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns, kMaxUnknowns>;
using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;

enum class Unknown { kAlpha1, kTau };

// the point `base` carries an offset r that turns with a link at omega, alpha
PointMotion follow(const PointMotion& base, const Vec2& r, double omega, double alpha) {
  return {base.p + r, base.v + omega * perp(r), base.a + alpha * perp(r) - omega * omega * r};
}

// offset of a point at (e, f) in the axes of a link at angle theta
Vec2 offset(double e, double f, double theta) { return e * unit(theta) + f * perp(unit(theta)); }

// coefficients of P in the planar cross product d x P = dx Py - dy Px
Eigen::RowVector2d cross_row(const Vec2& d) { return {-d.y(), d.x()}; }

// A present counter-rotating disc: its shaft C, inertia J and the link (index 0 crank, 2 rocker)
// and pivot P it is geared to.
struct Disc {
  double J{};
  Vec2 C{0, 0};
  int link{};
  Vec2 P{0, 0};
};

// The n x n system solved with a fixed-size LU (n = 9 as the plain four-bar always had).
template <int N>
VecN lu_solve(const MatN& A, const VecN& b, double theta1) {
  const Eigen::Matrix<double, N, N> Af = A;
  const Eigen::Matrix<double, N, 1> bf = b;
  const Eigen::FullPivLU<Eigen::Matrix<double, N, N>> lu(Af);
  if (!lu.isInvertible()) {
    throw std::domain_error("newton_euler: singular " + std::to_string(N) + "x" +
                            std::to_string(N) + " system at theta1 = " + std::to_string(theta1) +
                            " rad");
  }
  const Eigen::Matrix<double, N, 1> x = lu.solve(bf);
  return x;
}

core::DynamicsSample solve(const core::FourBar& model, double theta1, double omega1,
                           Unknown unknown, double alpha1_given) {
  // position and first-order kinematics from core's closed forms
  const auto pose = core::solve_position(model, theta1);
  if (!pose) throw std::domain_error("newton_euler: " + pose.error().what());
  const core::TransferFunctions tf = core::transfer_functions(model, *pose);

  core::FourBarState state;
  state.theta1 = pose->theta1;
  state.theta2 = pose->theta2;
  state.theta3 = pose->theta3;
  state.omega1 = omega1;
  state.omega2 = tf.dtheta2_dtheta1 * omega1;
  state.omega3 = tf.dtheta3_dtheta1 * omega1;
  const core::AccelerationBias bias = core::acceleration_bias(model, state);

  // a0_k: the accelerations at alpha1 = 0
  core::FourBarState no_crank_acceleration = state;
  no_crank_acceleration.alpha2 = bias.gamma2;
  no_crank_acceleration.alpha3 = bias.gamma3;
  const LinkageMotion m0 = linkage_motion(model, no_crank_acceleration);

  // J_k: the centre-of-mass velocities at unit crank rate
  core::FourBarState unit_rate = state;
  unit_rate.omega1 = 1.0;
  unit_rate.omega2 = tf.dtheta2_dtheta1;
  unit_rate.omega3 = tf.dtheta3_dtheta1;
  const LinkageMotion mJ = linkage_motion(model, unit_rate);

  const std::array<const core::Link*, 3> links{&model.crank, &model.coupler, &model.rocker};
  const std::array<const core::LinkLoad*, 3> loads{&model.loads.crank, &model.loads.coupler,
                                                   &model.loads.rocker};
  const std::array<double, 3> dtheta_dtheta1{1.0, tf.dtheta2_dtheta1, tf.dtheta3_dtheta1};
  const std::array<double, 3> gamma{0.0, bias.gamma2, bias.gamma3};
  const Vec2 A0{0.0, 0.0};
  const Vec2 A3{model.frame_length, 0.0};
  const Vec2 A1 = m0.A1.p;
  const Vec2 A2 = m0.A2.p;

  // with alpha1 given, the accelerations are known in full
  const double alpha1_known = unknown == Unknown::kTau ? alpha1_given : 0.0;

  // the counter-rotating discs present (J > 0), crank's first
  std::array<Disc, 2> discs{};
  int n_discs = 0;
  const std::array<const core::CounterRotation*, 2> rotations{&model.counter_rotations.crank,
                                                              &model.counter_rotations.rocker};
  const std::array<int, 2> geared_link{0, 2};
  const std::array<Vec2, 2> pivot{A0, A3};
  std::array<int, 2> disc_of{-1, -1};  // index in discs of the crank's and the rocker's disc
  for (int i = 0; i < 2; ++i) {
    if (!(rotations[i]->inertia > 0)) continue;
    if ((rotations[i]->at - pivot[i]).norm() == 0) {
      throw std::domain_error("newton_euler: counter-rotation shaft on its link's pivot");
    }
    disc_of[i] = n_discs;
    discs[n_discs++] = {rotations[i]->inertia, rotations[i]->at, geared_link[i], pivot[i]};
  }
  const int n = 9 + 3 * n_discs;

  MatN A = MatN::Zero(n, n);
  VecN b = VecN::Zero(n);
  // unknown columns: P0 -> 0, P1 -> 2, P2 -> 4, P3 -> 6, alpha1 or tau -> 8
  // rows of link k: force 3k, 3k+1; moment 3k+2
  for (int k = 0; k < 3; ++k) {
    const core::Link& L = *links[k];
    const Vec2 ak = m0.com[k].a + alpha1_known * mJ.com[k].v;
    const double alphak = gamma[k] + dtheta_dtheta1[k] * alpha1_known;
    const int f = 3 * k;
    const int m = 3 * k + 2;
    // right-hand sides: m a - F - m g and I alpha - M
    b.segment<2>(f) = L.mass * ak - loads[k]->force - L.mass * model.loads.gravity;
    b(m) = L.inertia * alphak - loads[k]->moment;
    // the unknown alpha1 moved to the left
    if (unknown == Unknown::kAlpha1) {
      A.block<2, 1>(f, 8) = -L.mass * mJ.com[k].v;
      A(m, 8) = -L.inertia * dtheta_dtheta1[k];
    }
  }
  const Eigen::Matrix2d I2 = Eigen::Matrix2d::Identity();
  const Vec2 c1 = m0.com[0].p, c2 = m0.com[1].p, c3 = m0.com[2].p;
  // crank: +P0 at A0, -P1 at A1, tau from the frame
  A.block<2, 2>(0, 0) = I2;
  A.block<2, 2>(0, 2) = -I2;
  A.block<1, 2>(2, 0) = cross_row(A0 - c1);
  A.block<1, 2>(2, 2) = -cross_row(A1 - c1);
  if (unknown == Unknown::kTau) A(2, 8) = 1.0;
  // coupler: +P1 at A1, -P2 at A2
  A.block<2, 2>(3, 2) = I2;
  A.block<2, 2>(3, 4) = -I2;
  A.block<1, 2>(5, 2) = cross_row(A1 - c2);
  A.block<1, 2>(5, 4) = -cross_row(A2 - c2);
  // rocker: +P2 at A2, +P3 at A3
  A.block<2, 2>(6, 4) = I2;
  A.block<2, 2>(6, 6) = I2;
  A.block<1, 2>(8, 4) = cross_row(A2 - c3);
  A.block<1, 2>(8, 6) = cross_row(A3 - c3);

  // discs: unknown columns B -> 9 + 3d, 9 + 3d + 1 and g -> 9 + 3d + 2; rows: force 9 + 3d,
  // 9 + 3d + 1, moment about the shaft 9 + 3d + 2
  const std::array<Vec2, 3> com{c1, c2, c3};
  for (int d = 0; d < n_discs; ++d) {
    const Disc& D = discs[d];
    const int k = D.link;
    const Vec2 t = perp(D.C - D.P) / (D.C - D.P).norm();  // mesh direction
    const Vec2 M = 0.5 * (D.P + D.C);                     // mesh point
    const int col_B = 9 + 3 * d, col_g = 9 + 3 * d + 2;
    const int row_f = 9 + 3 * d, row_m = 9 + 3 * d + 2;
    // disc: B + g t = 0
    A.block<2, 2>(row_f, col_B) = I2;
    A.block<2, 1>(row_f, col_g) = t;
    // disc: (M - C) x (g t) = -J alpha_k, alpha_k = Theta_k alpha1 + gamma_k
    A(row_m, col_g) = cross(M - D.C, t);
    if (unknown == Unknown::kAlpha1) {
      A(row_m, 8) = D.J * dtheta_dtheta1[k];
      b(row_m) = -D.J * gamma[k];
    } else {
      b(row_m) = -D.J * (gamma[k] + dtheta_dtheta1[k] * alpha1_known);
    }
    // link k: -g t at M
    A.block<2, 1>(3 * k, col_g) = -t;
    A(3 * k + 2, col_g) = -cross(M - com[k], t);
  }

  const VecN x = n == 9    ? lu_solve<9>(A, b, theta1)
                 : n == 12 ? lu_solve<12>(A, b, theta1)
                           : lu_solve<15>(A, b, theta1);

  // the sample: full state, reactions on the ground, shaking force and moment
  core::DynamicsSample s;
  s.state = state;
  s.state.alpha1 = unknown == Unknown::kAlpha1 ? x(8) : alpha1_given;
  s.state.alpha2 = tf.dtheta2_dtheta1 * s.state.alpha1 + bias.gamma2;
  s.state.alpha3 = tf.dtheta3_dtheta1 * s.state.alpha1 + bias.gamma3;
  s.tau = unknown == Unknown::kTau ? x(8) : 0.0;
  s.RA0 = -x.segment<2>(0);
  s.RA3 = -x.segment<2>(6);
  s.Fsh = s.RA0 + s.RA3;
  s.Msh = model.frame_length * s.RA3.y() - s.tau;
  // the shafts: force ON the ground = minus the bearing force on the disc
  if (disc_of[0] >= 0) s.RC1 = -x.segment<2>(9 + 3 * disc_of[0]);
  if (disc_of[1] >= 0) s.RC3 = -x.segment<2>(9 + 3 * disc_of[1]);
  if (n_discs > 0) {
    s.Fsh += s.RC1 + s.RC3;
    s.Msh += cross(model.counter_rotations.crank.at, s.RC1) +
             cross(model.counter_rotations.rocker.at, s.RC3);
  }
  return s;
}

}  // namespace

LinkageMotion linkage_motion(const core::FourBar& model, const core::FourBarState& s) {
  // joints along the chain A0 -> A1 -> A2 -> A3, each link turning at its own rate
  const PointMotion A0{};
  LinkageMotion out;
  out.A1 = follow(A0, model.crank.length * unit(s.theta1), s.omega1, s.alpha1);
  out.A2 = follow(out.A1, model.coupler.length * unit(s.theta2), s.omega2, s.alpha2);
  out.A3 = follow(out.A2, model.rocker.length * unit(s.theta3), s.omega3, s.alpha3);
  // centres of mass from each link's first joint
  out.com[0] = follow(A0, offset(model.crank.e, model.crank.f, s.theta1), s.omega1, s.alpha1);
  out.com[1] =
      follow(out.A1, offset(model.coupler.e, model.coupler.f, s.theta2), s.omega2, s.alpha2);
  out.com[2] = follow(out.A2, offset(model.rocker.e, model.rocker.f, s.theta3), s.omega3, s.alpha3);
  return out;
}

core::DynamicsSample newton_euler_forward(const core::FourBar& model, double theta1,
                                          double omega1) {
  return solve(model, theta1, omega1, Unknown::kAlpha1, 0.0);
}

core::DynamicsSample newton_euler_inverse(const core::FourBar& model, double theta1, double omega1,
                                          double alpha1) {
  return solve(model, theta1, omega1, Unknown::kTau, alpha1);
}

}  // namespace bd::reference
