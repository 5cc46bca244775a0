#pragma once
/// Internal to core, not part of its API: core/detail/ and core/fourbar/detail/ hold the
/// implementation's own types and kernels, included only by core's sources, its tests and its
/// benchmarks, never by a public header or a higher layer.
///
/// A planar vector as two plain doubles, for the per-instant kernels of the dynamics (the loop
/// closure, the formulations, the driven sweep). Everywhere else, and in every public header,
/// planar vectors are Vec2.
///
/// Why a second type: Eigen::Vector2d works on both components at once with 16-byte SSE loads.
/// A Vec2 built from two scalars (Vec2(x, y), perp(v), a complex product) is stored as two
/// 8-byte halves, and a 16-byte load of it right after cannot be forwarded from the store
/// buffer: the load waits until the stores have left it, which serialises the pipeline. In the
/// loop closure alone this made one solve several times slower (docs/performance.md). Xy keeps the
/// components in registers and costs nothing to convert: read a Vec2's x() and y(), write a Vec2
/// from two doubles.
///
/// Operations are written out in the same order as types.hpp's cross() and Eigen's dot(), so a
/// formula gives the same bits with either type.
#include <complex>

#include "core/types.hpp"

namespace bd::core::detail {

// the Vec2 overloads (types.hpp) next to the Xy ones below
using bd::cross;
using bd::perp;

struct Xy {
  double x{}, y{};
};

inline Xy xy(const Vec2& v) { return {v.x(), v.y()}; }
inline Xy xy(const std::complex<double>& z) { return {z.real(), z.imag()}; }
inline Vec2 to_vec2(const Xy& v) { return {v.x, v.y}; }

inline Xy operator+(const Xy& a, const Xy& b) { return {a.x + b.x, a.y + b.y}; }
inline Xy operator-(const Xy& a, const Xy& b) { return {a.x - b.x, a.y - b.y}; }
inline Xy operator-(const Xy& a) { return {-a.x, -a.y}; }
inline Xy operator*(double s, const Xy& a) { return {s * a.x, s * a.y}; }
inline Xy operator*(const Xy& a, double s) { return {a.x * s, a.y * s}; }
inline Xy& operator+=(Xy& a, const Xy& b) { return a = a + b; }

inline double dot(const Xy& a, const Xy& b) { return a.x * b.x + a.y * b.y; }
/// a × b = ax·by - ay·bx
inline double cross(const Xy& a, const Xy& b) { return a.x * b.y - a.y * b.x; }
/// Rotation by +90 degrees (i·a).
inline Xy perp(const Xy& a) { return {-a.y, a.x}; }
/// The complex product a·b.
inline Xy cmul(const Xy& a, const Xy& b) { return {a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x}; }
/// conj(a)·b = (a·b, a × b).
inline Xy cmul_conj(const Xy& a, const Xy& b) { return {dot(a, b), cross(a, b)}; }
/// |a|².
inline double squared_norm(const Xy& a) { return a.x * a.x + a.y * a.y; }

}  // namespace bd::core::detail
