// The harmonic orders of a driven run (harmonics.csv, summary.json) against the physics of the
// slider-crank and an independent transform: the referee's time series (tests/reference/planar,
// Newton-Euler per body, no code shared with the engine) summed by a direct DFT in this file.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/studies.hpp"

namespace bd::studies {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kOmega = 314.1592653589793;  // the engine study's crank speed [rad/s]

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// the engine with its rotating masses balanced (crank m e = -(rod's share at A) r) and its
// cylinder axis at `offset` from the crank shaft [m]
std::string engine(double offset) {
  std::string t = bd::testing::engine_study(360);
  t = replaced(t, "mass: 1.2, e: 0.012", "mass: 1.2, e: -0.01125");
  char b[96];
  std::snprintf(b, sizeof b, "B: [%.17g, %.17g]", 0.04 + std::sqrt(0.14 * 0.14 - offset * offset),
                offset);
  t = replaced(t, "B: [0.18, 0]", b);
  std::snprintf(b, sizeof b, "guide: [[0, %.17g], [1, %.17g]]", offset, offset);
  return replaced(t, "guide: [[0, 0], [1, 0]]", b);
}

// |order k| of x over one revolution sampled from θ0 = 0, by the direct sum
double dft_amplitude(const std::vector<double>& x, int k) {
  std::complex<double> c = 0;
  const int n = static_cast<int>(x.size());
  for (int j = 0; j < n; ++j) {
    c += x[static_cast<std::size_t>(j)] * std::polar(1.0, -2 * kPi * k * j / n);
  }
  return 2 * std::abs(c) / n;
}

struct Checked {
  Harmonics tool;
  std::vector<double> referee_x;  // the referee's inertial shaking force along the cylinder
};

Checked run(const std::string& text) {
  const Study study = parse_study(text, "engine.yaml");
  const RunResult r = compute_study(study);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.harmonics.has_value());
  Checked c{r.harmonics.value_or(Harmonics{}), {}};
  const bd::testing::planar::Glue g = bd::testing::planar::glue_of(study.planar());
  std::vector<double> times;
  for (int j = 0; j < 360; ++j) times.push_back(2 * kPi / kOmega * j / 360);
  for (const referee::Sample& s : referee::driven(g.mechanism, {kOmega}, 0.0, times)) {
    c.referee_x.push_back(s.inertial_force.x());
  }
  return c;
}

// Inline: the reciprocating mass (piston 0.35 kg and the rod's 0.1125 kg at the wrist pin) gives
// exactly m r ω² at order 1 (x = r cos θ + √(l² - r² sin² θ), whose root holds even orders only),
// nothing at odd orders above it, and nothing across the cylinder.
TEST(HarmonicsStudy, AnInlineEnginesOrdersAreThePistonsPrimaryAndEvenOrders) {
  const Checked c = run(engine(0.0));
  ASSERT_EQ(c.tool.orders.size(), 9u);
  EXPECT_EQ(c.tool.input, "crank");
  const double primary = 0.4625 * 0.04 * kOmega * kOmega;
  EXPECT_NEAR(c.tool.orders[1].Fshx.amplitude, primary, 1e-12 * primary);
  EXPECT_NEAR(c.tool.orders[1].Fsh.forward, primary / 2, 1e-12 * primary);
  EXPECT_NEAR(c.tool.orders[1].Fsh.backward, primary / 2, 1e-12 * primary);
  for (int k = 0; k <= 8; ++k) {
    const HarmonicOrder& o = c.tool.orders[static_cast<std::size_t>(k)];
    EXPECT_LE(o.Fshy.amplitude, 1e-12 * primary) << k;
    if (k >= 3 && k % 2 == 1) {
      EXPECT_LE(o.Fshx.amplitude, 1e-12 * primary) << k;
    }
    // the referee's series, transformed independently
    if (k >= 1) {
      EXPECT_NEAR(o.Fshx.amplitude, dft_amplitude(c.referee_x, k), 1e-10 * primary) << k;
    }
  }
  EXPECT_GT(c.tool.orders[2].Fshx.amplitude, 0.2 * primary);  // the secondary, λ = 0.29
  EXPECT_GT(c.tool.orders[4].Fshx.amplitude, 1e-3 * primary);
}

// With the cylinder axis offset the root is no longer even in θ: odd orders appear, and are
// reported as the referee's series has them.
TEST(HarmonicsStudy, AnOffsetEngineShowsOddOrders) {
  const Checked c = run(engine(0.012));
  const double primary = c.tool.orders[1].Fshx.amplitude;
  for (int k : {3, 5}) {
    const double a = c.tool.orders[static_cast<std::size_t>(k)].Fshx.amplitude;
    EXPECT_GT(a, 1e-4 * primary) << k;
    EXPECT_NEAR(a, dft_amplitude(c.referee_x, k), 1e-10 * primary) << k;
  }
}

// At constant speed the forces depend on the position and ω² only, so the engine turned the
// other way has the same orders as functions of the crank angle: amplitudes and phases alike
// (its samples are taken with the angle decreasing, and read back in the angle's order).
TEST(HarmonicsStudy, TurningTheOtherWayGivesTheSameOrdersOfTheCrankAngle) {
  std::string offset = engine(0.012);
  const RunResult ahead = compute_study(parse_study(offset, "e.yaml"));
  const RunResult back = compute_study(
      parse_study(replaced(offset, "speeds: [314.1592653589793]", "speeds: [-314.1592653589793]"),
                  "e.yaml"));
  ASSERT_TRUE(ahead.harmonics && back.harmonics);
  EXPECT_EQ(back.harmonics->speed, -kOmega);
  const double scale = ahead.harmonics->orders[1].Fshx.amplitude;
  const double mscale = ahead.harmonics->orders[1].Msh.amplitude;
  ASSERT_GT(mscale, 0.1);
  for (std::size_t k = 1; k < ahead.harmonics->orders.size(); ++k) {
    const HarmonicOrder &a = ahead.harmonics->orders[k], &b = back.harmonics->orders[k];
    EXPECT_NEAR(b.Fshx.amplitude, a.Fshx.amplitude, 1e-12 * scale) << k;
    EXPECT_NEAR(b.Fsh.forward, a.Fsh.forward, 1e-12 * scale) << k;
    EXPECT_NEAR(b.Fsh.backward, a.Fsh.backward, 1e-12 * scale) << k;
    EXPECT_NEAR(b.Msh.amplitude, a.Msh.amplitude, 1e-12 * mscale) << k;
    if (a.Fshx.amplitude > 1e-6 * scale) {
      // phases on the circle: ±π are one angle
      EXPECT_NEAR(std::remainder(b.Fshx.phase - a.Fshx.phase, 2 * kPi), 0.0, 1e-9) << k;
      EXPECT_NEAR(std::remainder(b.Fsh.forward_phase - a.Fsh.forward_phase, 2 * kPi), 0.0, 1e-9)
          << k;
    }
  }
}

// A four-bar driven by its crank has orders too; its force-balanced design has none.
TEST(HarmonicsStudy, AForceBalancedFourBarHasNoShakingForceOrders) {
  const Study study = load_study(std::string(BD_SOURCE_DIR) +
                                 "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.harmonics && r.balanced && r.balanced->harmonics);
  const double first =
      std::hypot(r.harmonics->orders[1].Fshx.amplitude, r.harmonics->orders[1].Fshy.amplitude);
  ASSERT_GT(first, 1.0);
  for (const HarmonicOrder& o : r.balanced->harmonics->orders) {
    EXPECT_LE(std::hypot(o.Fshx.amplitude, o.Fshy.amplitude), 1e-13 * first) << o.order;
  }
  // the moment is not balanced: its orders remain
  EXPECT_GT(r.balanced->harmonics->orders[1].Msh.amplitude, 1.0);
}

}  // namespace
}  // namespace bd::studies
