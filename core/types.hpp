#pragma once
/// Short fixed-size Eigen aliases used throughout balance-design.
#include <Eigen/Core>

namespace bd {

using Vec2 = Eigen::Vector2d;
using Vec4 = Eigen::Vector4d;
using Mat2 = Eigen::Matrix2d;
using Mat4 = Eigen::Matrix4d;
using Mat5 = Eigen::Matrix<double, 5, 5>;
using Vec5 = Eigen::Matrix<double, 5, 1>;

/// Planar cross product z-component: a x b = ax*by - ay*bx.
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
/// Rotation by +90 degrees (multiplication by i in the paper's complex notation).
inline Vec2 perp(const Vec2& a) { return {-a.y(), a.x()}; }
/// Unit vector at angle theta [rad].
inline Vec2 unit(double theta);

}  // namespace bd

#include <cmath>
inline bd::Vec2 bd::unit(double theta) { return {std::cos(theta), std::sin(theta)}; }
