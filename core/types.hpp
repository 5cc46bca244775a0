#pragma once
/// Short fixed-size Eigen aliases used throughout balance-design, and the paper's complex
/// scalars.
///
/// One planar vector type in the API: a point, a displacement, a velocity, a force or a link
/// vector is a Vec2 in every public header. The per-instant kernels compute in a two-double
/// struct, Xy, behind core's detail boundary (core/detail/xy.hpp says why); formula code that
/// follows the paper's complex notation converts at its edges (core/detail/complex_vector.hpp).
/// std::complex<double> appears in the API only as a complex scalar of the paper, which
/// multiplies link vectors: a complex mass m̄ = m(1 - s̄/l) (ComplexMass) or a principal-vector
/// coefficient c with ā = c·l̄ (ComplexCoefficient), never a point or a force.
#include <Eigen/Core>
#include <complex>

namespace bd {

using Vec2 = Eigen::Vector2d;
using Vec4 = Eigen::Vector4d;
using Mat2 = Eigen::Matrix2d;
using Mat4 = Eigen::Matrix4d;
using Mat5 = Eigen::Matrix<double, 5, 5>;
using Vec5 = Eigen::Matrix<double, 5, 1>;

/// A complex mass of the paper, e.g. m̄_p = m(1 - s̄/l) [kg]: times a link vector it gives a
/// mass moment. A scalar, never a point or a force.
using ComplexMass = std::complex<double>;
/// A principal-vector coefficient c of the paper, ā = c·l̄ [-]: turns and scales a link vector.
/// A scalar, never a point or a force.
using ComplexCoefficient = std::complex<double>;

/// Planar cross product z-component: a x b = ax*by - ay*bx.
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
/// Rotation by +90 degrees (multiplication by i in the paper's complex notation).
inline Vec2 perp(const Vec2& a) { return {-a.y(), a.x()}; }
/// Unit vector at angle theta [rad].
inline Vec2 unit(double theta);

}  // namespace bd

#include <cmath>
inline bd::Vec2 bd::unit(double theta) { return {std::cos(theta), std::sin(theta)}; }
