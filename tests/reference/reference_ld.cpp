// The high-precision yardstick: positions by the triangle A1-A2-A3 (paper eqs. 2-4), rates and
// velocity products by cross products of the loop-closure derivatives (eqs. 5, 8), and
// Newton-Euler for each moving link with the four pin forces as unknowns.
//
// Unknowns of the 9x9 (ground axes):
//   P0 ground -> crank at A0, P1 crank -> coupler at A1, P2 coupler -> rocker at A2,
//   P3 ground -> rocker at A3, and x8 = alpha1 (forward, tau = 0) or tau (inverse).
// Reactions ON the ground: RA0 = -P0, RA3 = -P3.
// Every acceleration is affine in alpha1: alpha_k = Theta_k alpha1 + gamma_k, and a centre of
// mass moves with a_k = a0_k + J_k alpha1, where a0_k is its acceleration at alpha1 = 0 and J_k
// its velocity at unit crank rate (omega_k = Theta_k).
#include "tests/reference/reference_ld.hpp"

#include <array>
#include <cmath>

#include <Eigen/Dense>

namespace bd::reference {
namespace {

template <class T>
using V2 = Eigen::Matrix<T, 2, 1>;

template <class T>
T cross2(const V2<T>& a, const V2<T>& b) {
  return a.x() * b.y() - a.y() * b.x();
}
template <class T>
V2<T> rot90(const V2<T>& a) {
  return V2<T>(-a.y(), a.x());
}
template <class T>
V2<T> dir(T theta) {
  return V2<T>(std::cos(theta), std::sin(theta));
}

// the link's parameters in T
template <class T>
struct L {
  T length, mass, e, f, inertia, fx, fy, moment;
};
template <class T>
L<T> link_t(const core::FourBar& m, int k) {
  const core::Link& l = core::link(m, k);
  const core::LinkLoad& q = core::link_load(m, k);
  return {T(l.length), T(l.mass), T(l.e), T(l.f), T(l.inertia), T(q.force.x()), T(q.force.y()),
          T(q.moment)};
}

template <class T>
RefSample<T> solve(const core::FourBar& model, const RefPose<T>& pose, T omega1, bool inverse,
                   T alpha1_given) {
  const std::array<L<T>, 3> lk{link_t<T>(model, 1), link_t<T>(model, 2), link_t<T>(model, 3)};
  const std::array<T, 3> th{pose.theta1, pose.theta2, pose.theta3};
  std::array<V2<T>, 3> lv;  // link vectors l̄1, l̄2, l̄3
  for (int k = 0; k < 3; ++k) lv[k] = lk[k].length * dir(th[k]);

  // first order: Σ Θk i l̄k = 0 with Θ1 = 1 (eq. 5), crossed with l̄3 and l̄2
  const T c23 = cross2(lv[1], lv[2]);
  RefSample<T> s;
  s.pose = pose;
  s.dtheta2_dtheta1 = -cross2(lv[0], lv[2]) / c23;
  s.dtheta3_dtheta1 = cross2(lv[0], lv[1]) / c23;
  s.omega1 = omega1;
  s.omega2 = s.dtheta2_dtheta1 * omega1;
  s.omega3 = s.dtheta3_dtheta1 * omega1;
  // second order: Σ αk i l̄k = b, b = Σ l̄k ωk² (eq. 8)
  const V2<T> b = lv[0] * (omega1 * omega1) + lv[1] * (s.omega2 * s.omega2) +
                  lv[2] * (s.omega3 * s.omega3);
  s.gamma2 = b.dot(lv[2]) / c23;
  s.gamma3 = -b.dot(lv[1]) / c23;

  const std::array<T, 3> Th{T(1), s.dtheta2_dtheta1, s.dtheta3_dtheta1};
  const std::array<T, 3> ga{T(0), s.gamma2, s.gamma3};
  const std::array<T, 3> om{omega1, s.omega2, s.omega3};
  const T alpha1_known = inverse ? alpha1_given : T(0);

  // joints along the chain; a0 at alpha1 = alpha1_known, J per unit alpha1 (forward only)
  std::array<V2<T>, 4> p, a0, J;
  p[0] = V2<T>::Zero();
  a0[0] = V2<T>::Zero();
  J[0] = V2<T>::Zero();
  for (int k = 0; k < 2; ++k) {
    const T alpha = Th[k] * alpha1_known + ga[k];
    p[k + 1] = p[k] + lv[k];
    a0[k + 1] = a0[k] + alpha * rot90(lv[k]) - om[k] * om[k] * lv[k];
    J[k + 1] = J[k] + Th[k] * rot90(lv[k]);
  }
  const V2<T> A3(T(model.frame_length), T(0));
  std::array<V2<T>, 3> c, ac, Jc;
  for (int k = 0; k < 3; ++k) {
    const V2<T> u = dir(th[k]);
    const V2<T> rho = lk[k].e * u + lk[k].f * rot90(u);
    const T alpha = Th[k] * alpha1_known + ga[k];
    c[k] = p[k] + rho;
    ac[k] = a0[k] + alpha * rot90(rho) - om[k] * om[k] * rho;
    Jc[k] = J[k] + Th[k] * rot90(rho);
  }

  // Newton and Euler for each link: rows 3k, 3k+1 (force), 3k+2 (moment about c_k)
  using M9 = Eigen::Matrix<T, 9, 9>;
  using X9 = Eigen::Matrix<T, 9, 1>;
  M9 A = M9::Zero();
  X9 r = X9::Zero();
  const V2<T> g(T(model.loads.gravity.x()), T(model.loads.gravity.y()));
  // moment row of d x P: coefficients (-dy, dx) on (Px, Py)
  auto put_moment = [&A](int row, int col, const V2<T>& d, T sgn) {
    A(row, col) += -sgn * d.y();
    A(row, col + 1) += sgn * d.x();
  };
  for (int k = 0; k < 3; ++k) {
    const int fr = 3 * k, mr = 3 * k + 2;
    const V2<T> F(lk[k].fx, lk[k].fy);
    r.template segment<2>(fr) = lk[k].mass * (ac[k] - g) - F;
    r(mr) = lk[k].inertia * (Th[k] * alpha1_known + ga[k]) - lk[k].moment;
    if (!inverse) {
      A.template block<2, 1>(fr, 8) = -lk[k].mass * Jc[k];
      A(mr, 8) = -lk[k].inertia * Th[k];
    }
  }
  // crank: +P0 at A0, -P1 at A1 (+tau)
  A(0, 0) = 1; A(1, 1) = 1; A(0, 2) = -1; A(1, 3) = -1;
  put_moment(2, 0, V2<T>(p[0] - c[0]), T(1));
  put_moment(2, 2, V2<T>(p[1] - c[0]), T(-1));
  if (inverse) A(2, 8) = 1;
  // coupler: +P1 at A1, -P2 at A2
  A(3, 2) = 1; A(4, 3) = 1; A(3, 4) = -1; A(4, 5) = -1;
  put_moment(5, 2, V2<T>(p[1] - c[1]), T(1));
  put_moment(5, 4, V2<T>(p[2] - c[1]), T(-1));
  // rocker: +P2 at A2, +P3 at A3
  A(6, 4) = 1; A(7, 5) = 1; A(6, 6) = 1; A(7, 7) = 1;
  put_moment(8, 4, V2<T>(p[2] - c[2]), T(1));
  put_moment(8, 6, V2<T>(A3 - c[2]), T(1));

  const Eigen::FullPivLU<M9> lu(A);
  const X9 x = lu.solve(r);
  T pmin = std::abs(lu.matrixLU()(8, 8)), pmax = std::abs(lu.matrixLU()(0, 0));
  s.lu_rcond = pmax > 0 ? pmin / pmax : T(0);

  s.alpha1 = inverse ? alpha1_given : x(8);
  s.tau = inverse ? x(8) : T(0);
  s.alpha2 = s.dtheta2_dtheta1 * s.alpha1 + s.gamma2;
  s.alpha3 = s.dtheta3_dtheta1 * s.alpha1 + s.gamma3;
  s.RA0x = -x(0);
  s.RA0y = -x(1);
  s.RA3x = -x(6);
  s.RA3y = -x(7);
  return s;
}

}  // namespace

template <class T>
std::optional<RefPose<T>> ref_position(const core::FourBar& model, T theta1) {
  const T l1 = T(model.crank.length), l2 = T(model.coupler.length), l3 = T(model.rocker.length),
          l4 = T(model.frame_length);
  // A1 -> A3 (eq. 2)
  const V2<T> l23v(l4 - l1 * std::cos(theta1), -l1 * std::sin(theta1));
  const T l23 = l23v.norm();
  if (!(l23 > 0)) return std::nullopt;
  // twice the triangle's area by Kahan's form of Heron's formula (sides sorted p >= q >= r)
  T p = l2, q = l3, r = l23;
  if (p < q) std::swap(p, q);
  if (q < r) std::swap(q, r);
  if (p < q) std::swap(p, q);
  const T slack = r - (p - q);
  if (slack < 0) return std::nullopt;
  const T area4 = std::sqrt((p + (q + r)) * slack * (r + (p - q)) * (p + (q - r)));
  // A2 at d23 along A1A3 and h23 to its left on branch +1 (eq. 3), link vectors (eq. 4)
  const T d23 = (l23 * l23 + (l2 - l3) * (l2 + l3)) / (2 * l23);
  const T h23 = T(core::sign(model.branch)) * area4 / (2 * l23);
  const V2<T> u = l23v / l23;
  const V2<T> l2v = d23 * u + h23 * rot90(u);
  const V2<T> l3v = l23v - l2v;
  RefPose<T> pose;
  pose.theta1 = theta1;
  pose.theta2 = std::atan2(l2v.y(), l2v.x());
  pose.theta3 = std::atan2(l3v.y(), l3v.x());
  // l̄2 x l̄3 = l̄2 x l̄23 = -h23 l23
  pose.sin_mu = -h23 * l23 / (l2 * l3);
  return pose;
}

template <class T>
RefPose<T> ref_pose_from_angles(T theta1, T theta2, T theta3) {
  return {theta1, theta2, theta3, std::sin(theta3 - theta2)};
}

template <class T>
RefSample<T> ref_forward(const core::FourBar& model, const RefPose<T>& pose, T omega1) {
  return solve<T>(model, pose, omega1, false, T(0));
}

template <class T>
RefSample<T> ref_inverse(const core::FourBar& model, const RefPose<T>& pose, T omega1, T alpha1) {
  return solve<T>(model, pose, omega1, true, alpha1);
}

long double limit_angle(const core::FourBar& model, long double l23_target) {
  const long double l1 = model.crank.length, l4 = model.frame_length;
  const long double c = (l1 * l1 + l4 * l4 - l23_target * l23_target) / (2 * l1 * l4);
  return std::acos(c);
}

template std::optional<RefPose<double>> ref_position(const core::FourBar&, double);
template std::optional<RefPose<long double>> ref_position(const core::FourBar&, long double);
template RefPose<double> ref_pose_from_angles(double, double, double);
template RefPose<long double> ref_pose_from_angles(long double, long double, long double);
template RefSample<double> ref_forward(const core::FourBar&, const RefPose<double>&, double);
template RefSample<long double> ref_forward(const core::FourBar&, const RefPose<long double>&,
                                            long double);
template RefSample<double> ref_inverse(const core::FourBar&, const RefPose<double>&, double,
                                       double);
template RefSample<long double> ref_inverse(const core::FourBar&, const RefPose<long double>&,
                                            long double, long double);

}  // namespace bd::reference
