// The drive torque's harmonic orders (summary.json, harmonics.csv) against a direct discrete
// Fourier sum of the run's own tau samples, written in this file: amplitude 2|Σ τ_j e^{-ikθ_j}|/N
// and the phase of q(θ) = Σ A cos(kθ + φ), for both senses of the crank's turn and for a planar
// linkage's input.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/studies.hpp"

namespace bd {
namespace {

constexpr double kPi = std::numbers::pi;

// order k of q over angles θ_j = θ0 + 2π j/N (the angle increasing): amplitude and phase
std::complex<double> dft(const std::vector<double>& q, const std::vector<double>& theta, int k) {
  std::complex<double> c = 0;
  for (std::size_t j = 0; j < q.size(); ++j) c += q[j] * std::polar(1.0, -k * theta[j]);
  return c * (k == 0 ? 1.0 : 2.0) / static_cast<double>(q.size());
}

void check(const studies::Harmonics& h, const std::vector<double>& tau,
           const std::vector<double>& theta) {
  double largest = 0;
  for (const studies::HarmonicOrder& o : h.orders) largest = std::max(largest, o.tau.amplitude);
  ASSERT_GT(largest, 0.0);
  for (const studies::HarmonicOrder& o : h.orders) {
    const std::complex<double> c = dft(tau, theta, o.order);
    if (o.order == 0) {
      EXPECT_NEAR(o.tau.amplitude, c.real(), 1e-12 * largest);
      continue;
    }
    EXPECT_NEAR(o.tau.amplitude, std::abs(c), 1e-12 * largest) << "order " << o.order;
    if (std::abs(c) > 1e-9 * largest) {
      // A cos(kθ + φ) has the complex coefficient A e^{iφ}
      EXPECT_NEAR(std::remainder(o.tau.phase - std::arg(c), 2 * kPi), 0.0, 1e-9)
          << "order " << o.order;
    }
  }
}

TEST(HarmonicTorque, FourBarDriveTorqueOrdersAreTheDirectTransformOfItsSamples) {
  for (const char* omega : {"6.283185307179586", "-9"}) {
    const std::string text =
        "name: h\nlinkage:\n  type: fourbar\n  frame: 3.2\n  branch: 1\n"
        "  crank:   {length: 1.0, mass: 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"
        "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
        "loads:\n  gravity: [0, -9.81]\n"
        "scene:\n  type: driven\n  theta1: 0.3\n  omega1: " +
        std::string(omega) + "\n  samples: 72\n";
    const studies::Study study = studies::parse_study(text, "h.yaml");
    const studies::RunResult r = studies::compute_study(study);
    ASSERT_TRUE(r.ok() && r.harmonics);
    std::vector<double> tau, theta;
    for (const core::DynamicsSample& s : r.trajectory.samples) {
      tau.push_back(s.tau);
      theta.push_back(s.state.theta1);
    }
    check(*r.harmonics, tau, theta);
    EXPECT_NE(studies::summary_json(study, r).find("\"tau\": {"), std::string::npos);
  }
}

TEST(HarmonicTorque, PlanarDriveTorqueOrdersAreTheDirectTransformOfItsSamples) {
  const studies::Study study = studies::parse_study(bd::testing::engine_study(90), "e.yaml");
  const studies::RunResult r = studies::compute_study(study);
  ASSERT_TRUE(r.ok() && r.harmonics);
  const core::Series& t = r.planar.table;
  std::vector<double> tau = t.column_values("tau"), theta;
  const std::string link = study.planar().links[static_cast<std::size_t>(
                                                    study.planar().inputs[0].link)]
                               .name;
  theta = t.column_values("theta_" + link);
  tau.resize(90);
  theta.resize(90);
  check(*r.harmonics, tau, theta);
}

}  // namespace
}  // namespace bd
