// Self-tests of the planar referee against closed forms, power balances and convergence.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "tests/reference/planar/referee.hpp"
#include "tests/reference/planar/selftest_mechanisms.hpp"

namespace bd::referee {
namespace {

using namespace selftest;

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<std::size_t>(i)] = a + (b - a) * i / (n - 1);
  return t;
}

// Piston position, velocity and acceleration of the crank-driven slider-crank against
//   x = r cos th + D,  D = sqrt(l^2 - s^2),  s = r sin th - e,  s' = r cos th, s'' = -r sin th
//   x'  = -r sin th - s s' / D
//   x'' = -r cos th - (s'^2 + s s'') / D - s^2 s'^2 / D^3
// with th = th0 + w t: dx/dt = x' w, d2x/dt2 = x'' w^2.
TEST(PlanarReferee, SliderCrankPistonMatchesClosedForm) {
  const SliderCrank sc;
  const Mechanism m = sc.build();
  const double w = 37.0;
  const auto samples = driven(m, {w}, 0.0, linspace(0, 2 * std::acos(-1.0) / w, 361));
  double worst = 0;
  for (const Sample& s : samples) {
    const double th = sc.theta0 + w * s.t;
    const double sn = sc.r * std::sin(th) - sc.e, sp = sc.r * std::cos(th),
                 spp = -sc.r * std::sin(th);
    const double D = std::sqrt(sc.l * sc.l - sn * sn);
    const double x = sc.r * std::cos(th) + D;
    const double x1 = -sc.r * std::sin(th) - sn * sp / D;
    const double x2 =
        -sc.r * std::cos(th) - (sp * sp + sn * spp) / D - sn * sn * sp * sp / (D * D * D);
    const PointMotion B = point_motion(m, s, 1, sc.B());
    // 1e-12 relative to the scales r, r w, r w^2 (the closed form itself is good to ~1e-15)
    EXPECT_NEAR(B.p.x(), x, 1e-12 * sc.r);
    EXPECT_NEAR(B.p.y(), sc.e, 1e-12 * sc.r);
    EXPECT_NEAR(B.v.x(), x1 * w, 1e-12 * sc.r * w);
    EXPECT_NEAR(B.a.x(), x2 * w * w, 1e-12 * sc.r * w * w);
    EXPECT_NEAR(B.a.y(), 0, 1e-12 * sc.r * w * w);
    worst = std::max(worst, std::abs(B.a.x() - x2 * w * w) / (sc.r * w * w));
  }
  RecordProperty("worst_relative_acceleration_error", std::to_string(worst));
}

}  // namespace
}  // namespace bd::referee
