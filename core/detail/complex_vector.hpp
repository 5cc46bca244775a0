#pragma once
/// Internal to core, not part of its API (see core/detail/xy.hpp).
///
/// The paper writes planar vectors as complex numbers. Formula code that follows it closely (the
/// principal vectors, the complex masses' principal-vector forms, the tests that check them)
/// computes in std::complex<double> and converts at its edges with these two functions. In the
/// public API a planar vector is always a Vec2, and std::complex only a complex scalar of the
/// paper (core/types.hpp).
#include <complex>

#include "core/types.hpp"

namespace bd::core::detail {

/// A planar vector or a complex scalar in the paper's complex notation.
using Complex = std::complex<double>;
inline Complex to_complex(const Vec2& v) { return {v.x(), v.y()}; }
inline Vec2 to_vec(const Complex& z) { return {z.real(), z.imag()}; }

}  // namespace bd::core::detail
