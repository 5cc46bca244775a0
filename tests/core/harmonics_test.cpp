// Harmonic orders by the FFT against quantities built from known orders: amplitudes and phases
// come back to round-off, at any starting angle; a vector quantity splits into the parts that
// turn with and against the input as built; orders that alias are left out.
#include "core/harmonics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

namespace bd::core {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Harmonics, RealOrdersComeBackAsBuilt) {
  const int n = 90;
  const double theta0 = 2.3;  // the input's angle at the first sample
  const double amp[] = {0.7, 3.0, 0.0, 1.25, 0.5}, phase[] = {0, -2.0, 0, 3.1, 0.4};
  std::vector<double> q(n);
  for (int j = 0; j < n; ++j) {
    const double theta = theta0 + 2 * kPi * j / n;
    q[j] = amp[0];
    for (int k = 1; k < 5; ++k) q[j] += amp[k] * std::cos(k * theta + phase[k]);
  }
  const std::vector<Harmonic> h = harmonic_orders(q, theta0, 8);
  ASSERT_EQ(h.size(), 9u);
  EXPECT_NEAR(h[0].amplitude, 0.7, 1e-14);
  for (int k = 1; k <= 8; ++k) {
    EXPECT_EQ(h[k].order, k);
    EXPECT_NEAR(h[k].amplitude, k < 5 ? amp[k] : 0.0, 1e-14) << k;
    if (k < 5 && amp[k] > 0) {
      EXPECT_NEAR(h[k].phase, phase[k], 1e-13) << k;
    }
  }
  // 12 samples resolve orders up to 5 only
  EXPECT_EQ(harmonic_orders(std::vector<double>(12, 1.0), 0, 20).size(), 6u);
}

TEST(Harmonics, AVectorSplitsIntoTheOrdersThatTurnWithAndAgainstTheInput) {
  const int n = 64;
  const double theta0 = -0.8;
  std::vector<double> x(n), y(n);
  for (int j = 0; j < n; ++j) {
    const double theta = theta0 + 2 * kPi * j / n;
    // order 1 forward 2 at phase 0.3; order 2 backward 0.5 at phase -1.1; order 3 along x only:
    // 0.8 cos(3θ + 0.2) = forward 0.4 at 0.2 plus backward 0.4 at -0.2
    const std::complex<double> f = 2.0 * std::polar(1.0, theta + 0.3) +
                                   0.5 * std::polar(1.0, -(2 * theta + 1.1)) +
                                   std::complex<double>(0.8 * std::cos(3 * theta + 0.2), 0);
    x[j] = f.real();
    y[j] = f.imag();
  }
  const std::vector<RotatingHarmonic> h = rotating_orders(x, y, theta0, 4);
  ASSERT_EQ(h.size(), 4u);
  EXPECT_NEAR(h[0].forward, 2.0, 1e-14);
  EXPECT_NEAR(h[0].forward_phase, 0.3, 1e-14);
  EXPECT_NEAR(h[0].backward, 0.0, 1e-14);
  EXPECT_NEAR(h[1].forward, 0.0, 1e-14);
  EXPECT_NEAR(h[1].backward, 0.5, 1e-14);
  EXPECT_NEAR(h[1].backward_phase, -1.1, 1e-14);
  EXPECT_NEAR(h[2].forward, 0.4, 1e-14);
  EXPECT_NEAR(h[2].backward, 0.4, 1e-14);
  EXPECT_NEAR(h[2].forward_phase, 0.2, 1e-14);
  EXPECT_NEAR(h[2].backward_phase, -0.2, 1e-14);
  EXPECT_NEAR(h[3].forward + h[3].backward, 0.0, 1e-14);
}

}  // namespace
}  // namespace bd::core
