#include "core/fourbar/mass_matrix.hpp"

#include <cmath>

#include "core/fourbar/detail/formulation_support.hpp"
#include "core/fourbar/detail/instant_dynamics.hpp"

namespace bd::core {

// the kernels' types and steps (core/detail/, core/fourbar/detail/)
using detail::ClosedInstant;
using detail::CrankInput;
using detail::evaluated;
using detail::mass_matrix_at;
using detail::mass_matrix_constants;
using detail::MassMatrixConstants;
using detail::to_vec2;
using detail::Xy;
using detail::xy;

namespace {

using Mat8 = Eigen::Matrix<double, 8, 8>;

// joints in one vector [A0x, A0y, A1x, A1y, A2x, A2y, A3x, A3y]; link k joins joints k-1 and k,
// so its four coordinates are the contiguous segment starting at 2(k-1)

Mat8 assembled_mass_matrix(const FourBar& model) {
  Mat8 M = Mat8::Zero();
  for (int k = 1; k <= 3; ++k)
    M.block<4, 4>(2 * (k - 1), 2 * (k - 1)) += link_mass_matrix(link(model, k));
  return M;
}

// eq. 45's distinct entries (García de Jalón's constant mass matrix in natural coordinates):
// I_q/l² on the diagonal at p, I_p/l² at q, and the off-diagonal block as the complex factor
// w = (-I_red/l², m f/l)
struct LinkBlocks {
  double at_p, at_q;  // [kg]
  Xy w;               // [kg]
};
LinkBlocks link_blocks(const Link& link) {
  const double l = link.length, m = link.mass, e = link.e, f = link.f, I = link.inertia;
  const double Ip = I + m * (e * e + f * f);              // about joint p
  const double Iq = I + m * ((l - e) * (l - e) + f * f);  // about joint q
  const double Ired = I - m * e * (l - e) + m * f * f;    // reduced
  const double l2 = l * l, mf = m * f / l;
  return {Iq / l2, Ip / l2, Xy{-Ired / l2, mf}};
}

// eq. 46's shares of a force F at the centre of mass at the joints p and q: the complex weights
// (1 - s̄/l) and s̄/l, conjugated as the virtual work of a rigid motion asks
struct NodalShares {
  Xy at_p, at_q;  // [N]
};
NodalShares nodal_shares(const Link& link, const Xy& F) {
  const double l = link.length, xi = link.e / l, eta = link.f / l;
  return {Xy{(1 - xi) * F.x - eta * F.y, (1 - xi) * F.y + eta * F.x},
          Xy{xi * F.x + eta * F.y, xi * F.y - eta * F.x}};
}

Expected<DynamicsSample, DynamicsError> one_instant(const FourBar& model, double theta1,
                                                    double omega1, CrankInput input) {
  const MassMatrixConstants c = mass_matrix_constants(model);
  return evaluated(model, theta1, omega1, [&](const ClosedInstant& instant, DynamicsSample& out) {
    return mass_matrix_at(model, c, instant, input, out);
  });
}

}  // namespace

Mat4 link_mass_matrix(const Link& link) {
  // eq. 45: [I_q/l² 1, B; Bᵀ, I_p/l² 1] with B = [u -v; v u], w = (u, v)
  const LinkBlocks b = link_blocks(link);
  const double u = b.w.x, v = b.w.y;
  Mat4 Me;
  Me << b.at_p, 0, u, -v,  //
      0, b.at_p, v, u,     //
      u, v, b.at_q, 0,     //
      -v, u, 0, b.at_q;
  return Me;
}

Vec4 link_nodal_forces(const Link& link, const Vec2& force, double moment, const Vec2& p,
                       const Vec2& q) {
  // eq. 46: F at the centre of mass split by the complex weights (1 - s̄/l) and s̄/l; the
  // moment as a couple perpendicular to the link, M/l² · i(r_q - r_p) at q and its opposite at p
  const double l = link.length;
  const NodalShares shares = nodal_shares(link, xy(force));
  const Vec2 couple = moment / (l * l) * perp(q - p);
  Vec4 out;
  out.segment<2>(0) = to_vec2(shares.at_p) - couple;
  out.segment<2>(2) = to_vec2(shares.at_q) + couple;
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

namespace detail {

MassMatrixConstants mass_matrix_constants(const FourBar& model) {
  const Link &L1 = model.crank, &L2 = model.coupler, &L3 = model.rocker;
  const LinkBlocks M1 = link_blocks(L1), M2 = link_blocks(L2), M3 = link_blocks(L3);
  // the shares of F̄_k + m_k ḡ at the link's joints (eq. 46 without moment)
  auto shares = [&model](const Link& link, const LinkLoad& load) {
    return nodal_shares(link, xy(load.force + link.mass * model.loads.gravity));
  };
  const NodalShares N1 = shares(L1, model.loads.crank), N2 = shares(L2, model.loads.coupler),
                    N3 = shares(L3, model.loads.rocker);
  MassMatrixConstants c;
  // moving joints: the crank's q block and the coupler's p block at A1, the coupler's q block
  // and the rocker's p block at A2, the whole coupler between them
  c.d1 = M1.at_q + M2.at_p;
  c.d2 = M2.at_q + M3.at_p;
  c.w1 = M1.w;
  c.w2 = M2.w;
  c.w3 = M3.w;
  c.F_A0 = N1.at_p;
  c.F_A1 = N1.at_q + N2.at_p;
  c.F_A2 = N2.at_q + N3.at_p;
  c.F_A3 = N3.at_q;
  c.couple1 = model.loads.crank.moment / (L1.length * L1.length);
  c.couple2 = model.loads.coupler.moment / (L2.length * L2.length);
  c.couple3 = model.loads.rocker.moment / (L3.length * L3.length);
  c.inv_l1_sq = 1.0 / (L1.length * L1.length);
  return c;
}

}  // namespace detail

Expected<DynamicsSample, DynamicsError> forward_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1, double omega1) {
  return one_instant(model, theta1, omega1, CrankInput::forward());
}

Expected<DynamicsSample, DynamicsError> inverse_dynamics_mass_matrix(const FourBar& model,
                                                                     double theta1, double omega1,
                                                                     double alpha1) {
  return one_instant(model, theta1, omega1, CrankInput::inverse(alpha1));
}

}  // namespace bd::core
