#pragma once
/// The angle of a planar vector, atan2(y, x), at a fraction of the C library's cost.
///
/// The dynamics returns θ2 and θ3 with every sample, so each evaluation takes the angles of two
/// vectors. glibc's atan2 rounds correctly, at a higher cost (docs/performance.md compares
/// them); polar_angle() rounds a little more: in units in the last place of the angle it is within
/// 1.5 ulp below 0.5 rad (the quotient's rounding counts twice where the result falls below a
/// power of two the quotient is above) and within 1 ulp above, against a long-double reference
/// (tests/core/polar_angle_test.cpp). Either is far below the position solve's own error in the
/// angles.
///
/// Method (the reduction of Sun's fdlibm): with a = min(|x|, |y|) and b = max(|x|, |y|),
/// atan(a/b) = A + atan(r) with A = 0, atan(1/2) or π/4 and
///   r = a/b,  (2a - b)/(2b + a)  or  (a - b)/(a + b)   for a/b < 7/16, < 11/16, <= 1,
/// so |r| <= 7/16, one division suffices, and every numerator is exact (Sterbenz). Then
/// atan(r) = r - r·S with S = r²·P(r²), P of degree 11 our own Chebyshev fit of
/// (1 - atan(r)/r)/r² (error 3.9e-18 on |r| <= 7/16). The octant gives the angle as
/// B + s·atan(r), where B = K + s·A (K = 0, π/2 or π; s = ±1) is stored as a pair hi + lo, so
/// that the result is one rounding of a sum whose large term is exact.
#include <cmath>

#include "core/types.hpp"

namespace bd::core {

namespace polar_angle_detail {

// 1 - atan(r)/r = z·(c0 + c1 z + ... + c11 z^11), z = r², |r| <= 7/16 (Chebyshev fit, error of
// the bracket 3.9e-18)
inline constexpr double kC[12] = {
    0.3333333333333333,  -0.1999999999999941,  0.14285714285566806,  -0.11111111096645038,
    0.09090908355602592, -0.07692285554889286, 0.06666241923359964,  -0.05876946456755061,
    0.05216679739313656, -0.04492259293193656, 0.033128134256069586, -0.014773184616983806};

// B = K + s·A as hi + lo, indexed [octant][reduction]: octant 0 |y| <= x, 1 |y| > |x| with
// x >= 0, 2 |y| <= -x, 3 |y| > |x| with x < 0; reduction A = 0, atan(1/2), π/4
inline constexpr double kHi[4][3] = {{0.0, 0.4636476090008061, 0.7853981633974483},
                                     {1.5707963267948966, 1.1071487177940904, 0.7853981633974483},
                                     {3.141592653589793, 2.677945044588987, 2.356194490192345},
                                     {1.5707963267948966, 2.0344439357957027, 2.356194490192345}};
inline constexpr double kLo[4][3] = {
    {0.0, 2.2698777452961687e-17, 3.061616997868383e-17},
    {6.123233995736766e-17, 9.40447137356638e-17, 3.061616997868383e-17},
    {1.2246467991473532e-16, 1.5527705369303147e-16, 9.184850993605148e-17},
    {6.123233995736766e-17, 2.841996617907152e-17, 9.184850993605148e-17}};
// the sign s of atan(r) in each octant
inline constexpr double kSign[4] = {1.0, -1.0, -1.0, 1.0};

}  // namespace polar_angle_detail

/// The angle of (x, y) from the x axis [rad] in [-π, π], as std::atan2(y, x), to within one unit
/// in the last place. Zeros, infinities, NaNs and magnitudes beyond 1e300 go to std::atan2.
inline double polar_angle(double y, double x) {
  namespace d = polar_angle_detail;
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double a = steep ? ax : ay, b = steep ? ay : ax;
  if (!(a > 0.0) || !(b < 1e300)) return std::atan2(y, x);
  // reduction: r = (p·a - q·b)/(p·b + q·a) with (p, q) = (1, 0), (2, 1), (1, 1)
  int k = 0;
  double num = a, den = b;
  if (a >= 0.6875 * b) {
    k = 2;
    num = a - b;
    den = a + b;
  } else if (a >= 0.4375 * b) {
    k = 1;
    num = 2.0 * a - b;
    den = 2.0 * b + a;
  }
  const int octant = (x < 0.0 ? 2 : 0) + (steep ? 1 : 0);
  const double r = d::kSign[octant] * (num / den);
  // S = 1 - atan(r)/r, even and odd powers of w = z² evaluated side by side
  const double z = r * r, w = z * z;
  const double s1 =
      z * (d::kC[0] +
           w * (d::kC[2] + w * (d::kC[4] + w * (d::kC[6] + w * (d::kC[8] + w * d::kC[10])))));
  const double s2 =
      w * (d::kC[1] +
           w * (d::kC[3] + w * (d::kC[5] + w * (d::kC[7] + w * (d::kC[9] + w * d::kC[11])))));
  const double angle = d::kHi[octant][k] - ((r * (s1 + s2) - d::kLo[octant][k]) - r);
  return y < 0.0 ? -angle : angle;
}

/// The angle of v [rad] in [-π, π] (polar_angle(v.y(), v.x())).
inline double polar_angle(const Vec2& v) { return polar_angle(v.y(), v.x()); }

}  // namespace bd::core
