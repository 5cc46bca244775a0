#pragma once
/// The paper's truss element (§4.2, eqs. 41-46): a rigid link described by the Cartesian
/// coordinates of two of its points p and q, with a constant 4x4 mass matrix. A material point
/// at link coordinates ξ + iη (ξ along p->q, η to the left, both in units of |pq|) moves as
/// r = (1 - ξ - iη) p + (ξ + iη) q (eq. 41); the kinetic energy of the link is then the constant
/// quadratic form T = ½ ṙᵀ M ṙ in ṙ = (ṗx, ṗy, q̇x, q̇y), exact for every rigid motion.
/// The four-bar's mass-matrix formulation and the general planar engine share it.
#include "core/types.hpp"

namespace bd::core {

/// A link's mass data on the element p->q of length l: centre of mass at e along and f to the left
/// of p->q from p, inertia about the centre of mass.
struct ElementMass {
  double length{};   // |pq| [m], > 0
  double mass{};     // [kg]
  double e{}, f{};   // centre of mass from p [m]
  double inertia{};  // about the centre of mass [kg m^2]
};

/// The element's mass matrix (eq. 45):
///   [ I_q/l² 1   B ]       I_p = I + m(e² + f²), I_q = I + m((l - e)² + f²),
///   [ Bᵀ   I_p/l² 1 ]      B = [u -v; v u], (u, v) = (-(I - m e (l - e) + m f²)/l², m f/l).
Mat4 element_mass_matrix(const ElementMass& link);

/// The complex weights of a material point at ξ + iη: r = (1 - ξ - iη) p + (ξ + iη) q, as the
/// 2x2 matrices A = (1 - ξ) I - η J and B = ξ I + η J (J the rotation by +90°), r = A p + B q.
struct PointWeights {
  Mat2 at_p, at_q;
};
PointWeights point_weights(double xi, double eta);
/// ξ + iη of the point r on the element p->q: (r - p) / (q - p) as complex numbers.
Vec2 link_coordinates(const Vec2& p, const Vec2& q, const Vec2& r);

/// A force F at the material point ξ + iη and a moment M on the link, as nodal forces on
/// (p, q) with the same virtual work in every rigid motion (eq. 46): Aᵀ F and Bᵀ F, and the
/// moment as the couple M/l² · i(q - p) at q and its opposite at p (l the current |pq|).
Vec4 element_nodal_forces(const PointWeights& at, const Vec2& force, double moment, const Vec2& p,
                          const Vec2& q);

}  // namespace bd::core
