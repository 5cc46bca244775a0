// polar_angle() against a long-double atan2 and against std::atan2 (core/polar_angle.hpp).
#include "core/polar_angle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace bd::core {
namespace {

// |a - ref| in units in the last place of the double nearest ref
double ulps(double a, long double ref) {
  const double r = std::abs(static_cast<double>(ref));
  const double ulp = std::nextafter(r, std::numeric_limits<double>::infinity()) - r;
  return static_cast<double>(std::abs(static_cast<long double>(a) - ref) / ulp);
}

struct Worst {
  double absolute{};      // [rad]
  double ulps_small{};    // |angle| < 0.5 rad
  double ulps_large{};    // |angle| >= 0.5 rad
  double std_absolute{};  // std::atan2's [rad]
};

void measure(double y, double x, Worst& w) {
  const long double ref = std::atan2(static_cast<long double>(y), static_cast<long double>(x));
  const double got = polar_angle(y, x);
  w.absolute = std::max(w.absolute, static_cast<double>(std::abs(got - ref)));
  w.std_absolute = std::max(w.std_absolute, static_cast<double>(std::abs(std::atan2(y, x) - ref)));
  double& u = std::abs(ref) < 0.5L ? w.ulps_small : w.ulps_large;
  u = std::max(u, ulps(got, ref));
}

TEST(PolarAngle, WithinARoundingOfTheLibrary) {
  // Long double (64-bit mantissa) is exact enough to measure double errors to ~1e-3 ulp.
  // Vectors: every direction at magnitudes over 2^±30, the unit square, and thin bands around
  // the reduction's switch points a/b = 7/16, 11/16, 1 and their reciprocals, and near the axes.
  std::mt19937_64 rng(20240607);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi),
      log_r(-30.0, 30.0), unit(-1.0, 1.0);
  Worst w;
  for (int i = 0; i < 1'000'000; ++i) {
    const double t = angle(rng), r = std::exp2(log_r(rng));
    measure(r * std::sin(t), r * std::cos(t), w);
  }
  for (int i = 0; i < 200'000; ++i) measure(unit(rng), unit(rng), w);
  for (double c : {7.0 / 16, 11.0 / 16, 1.0, 16.0 / 11, 16.0 / 7}) {
    for (int i = 0; i < 40'000; ++i) {
      const double x = unit(rng), y = x * c * (1 + 1e-6 * unit(rng));
      measure(y, x, w);
      measure(-y, x, w);
    }
  }
  for (int i = 0; i < 40'000; ++i) {
    const double x = unit(rng);
    measure(x * 1e-9 * unit(rng), x, w);
    measure(x, x * 1e-9 * unit(rng), w);
  }
  // the final rounding (half an ulp of the angle, 2.2e-16 near pi) plus the roundings of the
  // quotient r and of the bracket, each half an ulp of |r| <= 7/16 (2.8e-17): 2.8e-16 at most,
  // measured 2.75e-16, where std::atan2, rounding once, measures 2.22e-16
  EXPECT_LT(w.absolute, 2.8e-16);
  EXPECT_LT(w.std_absolute, 2.3e-16);  // the yardstick itself
  // the rounding of the quotient r (half an ulp of r, one ulp of the angle where r and atan(r)
  // straddle a power of two) and the final rounding (half an ulp) bound the relative error by
  // 1.5 ulp plus the fit's 4e-18; measured 1.42 below 0.5 rad and 0.90 above
  EXPECT_LE(w.ulps_small, 1.5);
  EXPECT_LE(w.ulps_large, 1.0);
}

TEST(PolarAngle, ExactWhereTheLibraryIsAndSymmetricInY) {
  // the diagonal, the axes and the special values are std::atan2's exactly (bit for bit)
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double special[][2] = {{1, 1},    {-1, 1},    {1, -1},        {-1, -1},   {0.0, 1},
                               {-0.0, 1}, {0.0, -1},  {-0.0, -1},     {1, 0.0},   {1, -0.0},
                               {-1, 0.0}, {0.0, 0.0}, {-0.0, -0.0},   {inf, 1},   {1, inf},
                               {1, -inf}, {inf, inf}, {3e300, 1e300}, {1e-310, 1}};
  for (const auto& v : special) {
    const double got = polar_angle(v[0], v[1]), want = std::atan2(v[0], v[1]);
    EXPECT_EQ(got, want) << "y = " << v[0] << ", x = " << v[1];
    EXPECT_EQ(std::signbit(got), std::signbit(want)) << "y = " << v[0] << ", x = " << v[1];
  }
  EXPECT_TRUE(std::isnan(polar_angle(nan, 1.0)));
  EXPECT_TRUE(std::isnan(polar_angle(1.0, nan)));
  // the sign of y only flips the result
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 10'000; ++i) {
    const double y = unit(rng), x = unit(rng);
    EXPECT_EQ(polar_angle(-y, x), -polar_angle(y, x));
  }
  EXPECT_EQ(polar_angle(Vec2(0.3, -0.4)), polar_angle(-0.4, 0.3));
}

}  // namespace
}  // namespace bd::core
