// Balance conditions (balance/conditions.hpp): eq. 57 against the frame principal vectors,
// Berkof's reduced inertias against the angular momentum computed link by link, the report, and
// the paper's force-balanced example (§5.2, Fig. 9) verified by its simulated support reactions.
#include "balance/conditions.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "balance/counterweight.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"

namespace bd::balance {
namespace {

// centre-of-mass offsets and mass moments in the paper's complex notation
using Complex = std::complex<double>;

TEST(Conditions, ResidualsAreTheFramePrincipalVectorsTimesTheTotalMass) {
  // eq. 30: ā14 = -(m1 s̄1/l1 + m̄2p) l̄1 / m, ā34 = (m̄2q + m3 (1 - s̄3/l3)) l̄3 / m
  std::mt19937_64 rng(57);
  for (int trial = 0; trial < 50; ++trial) {
    const core::FourBar m = core::samples::random_crank_rocker(rng);
    const ForceBalanceResiduals r = force_balance_residuals(m);
    const core::FrameFactors f = core::frame_factors(m);
    const double mt = core::total_mass(m);
    const ForceBalanceScales s = force_balance_scales(m);
    EXPECT_LE(std::abs(r.crank + mt * f.a14), 1e-14 * s.crank) << trial;
    EXPECT_LE(std::abs(r.rocker - mt * f.a34), 1e-14 * s.rocker) << trial;
    // written out as eq. 58
    const core::Link &l1 = m.crank, &l2 = m.coupler, &l3 = m.rocker;
    EXPECT_NEAR(r.crank.real(),
                l1.mass * l1.e / l1.length + l2.mass * (l2.length - l2.e) / l2.length,
                1e-14 * s.crank);
    EXPECT_NEAR(r.crank.imag(), l1.mass * l1.f / l1.length - l2.mass * l2.f / l2.length,
                1e-14 * s.crank);
    EXPECT_NEAR(r.rocker.real(),
                l2.mass * l2.e / l2.length + l3.mass * (l3.length - l3.e) / l3.length,
                1e-14 * s.rocker);
    EXPECT_NEAR(r.rocker.imag(), l2.mass * l2.f / l2.length - l3.mass * l3.f / l3.length,
                1e-14 * s.rocker);
  }
}

// an inline design with a Berkof coupler, force balanced by counterweights
core::FourBar berkof_force_balanced() {
  core::FourBar m;
  m.crank = {0.8, 1.0, 0.3, 0.0, 0.08};
  const double l2 = 2.5, m2 = 1.8, e2 = 1.1;
  m.coupler = {l2, m2, e2, 0.0, m2 * e2 * (l2 - e2)};
  m.rocker = {1.9, 1.4, 1.2, 0.0, 0.4};
  m.frame_length = 2.4;
  return force_balance(core::make_fourbar(m), {}, {}).model;
}

// angular momentum of the moving links about A0, link by link [kg m^2/s]
double angular_momentum(const core::FourBar& m, const core::FourBarState& s) {
  const core::Pose pose = core::pose_of(s);
  const double omega[3] = {s.omega1, s.omega2, s.omega3};
  double H = 0.0;
  for (int k = 1; k <= 3; ++k) {
    const core::Link& l = core::link(m, k);
    H += l.mass * cross(core::centre_of_mass(m, k, pose), core::centre_of_mass_velocity(m, k, s)) +
         l.inertia * omega[k - 1];
  }
  return H;
}

TEST(Conditions, ReducedInertiasCarryTheAngularMomentumOfABerkofDesign) {
  // with the force balanced and a Berkof coupler, H_A0 = K1 omega1 + K3 omega3 at every state
  const core::FourBar m = berkof_force_balanced();
  ASSERT_TRUE(check_balance(m).force_balanced()) << check_balance(m).text();
  const ReducedInertias K = reduced_inertias(m);
  // the paper's simplified forms (§5.2), which hold once f1 = f3 = 0 and eq. 57 holds
  const core::Link &l1 = m.crank, &l3 = m.rocker;
  EXPECT_NEAR(K.crank, l1.inertia - l1.mass * l1.e * (l1.length - l1.e), 1e-13 * K.crank);
  EXPECT_NEAR(K.rocker, l3.inertia + l3.mass * l3.e * (l3.e - l3.length), 1e-13 * K.rocker);
  for (int k = 0; k < 36; ++k) {
    const double theta1 = 2 * std::numbers::pi * k / 36, omega1 = 1.0 + 0.1 * k;
    const auto pose = core::solve_position(m, theta1);
    ASSERT_TRUE(pose.has_value());
    const core::FourBarState s = core::solve_velocity(m, *pose, omega1);
    const double H = angular_momentum(m, s);
    const double scale = (K.crank + K.rocker) * std::max(std::abs(s.omega1), std::abs(s.omega3));
    EXPECT_NEAR(H, K.crank * s.omega1 + K.rocker * s.omega3, 1e-13 * scale)
        << "theta1 = " << theta1;
  }
}

TEST(Conditions, ReportNamesEveryCondition) {
  const BalanceReport r = check_balance(core::samples::paper_fourbar());
  ASSERT_EQ(r.force.size(), 2u);
  ASSERT_EQ(r.moment.size(), 4u);
  EXPECT_EQ(r.force[0].name, "force.crank");
  EXPECT_EQ(r.force[1].name, "force.rocker");
  EXPECT_EQ(r.moment[0].name, "coupler.f2");
  EXPECT_EQ(r.moment[1].name, "coupler.inertia");
  EXPECT_EQ(r.moment[2].name, "counter_rotation.crank");
  EXPECT_EQ(r.moment[3].name, "counter_rotation.rocker");
  EXPECT_FALSE(r.force_balanced());
  EXPECT_FALSE(r.moment_balanced());
  for (const Condition& c : r.force) {
    EXPECT_FALSE(c.holds) << c.name;
    EXPECT_GT(c.residual, 0.0) << c.name;
    EXPECT_EQ(c.unit, "kg");
  }
  const std::string text = r.text();
  EXPECT_NE(text.find("shaking force: not balanced"), std::string::npos) << text;
  EXPECT_NE(text.find("force.crank: FAILS"), std::string::npos) << text;
  EXPECT_NE(text.find("counter_rotation.rocker: FAILS"), std::string::npos) << text;

  const BalanceReport b = check_balance(berkof_force_balanced());
  EXPECT_TRUE(b.force_balanced()) << b.text();
  EXPECT_TRUE(b.moment[0].holds);
  EXPECT_TRUE(b.moment[1].holds);
  EXPECT_FALSE(b.moment_balanced());  // no counter-rotations yet
  EXPECT_NE(b.text().find("shaking force: balanced"), std::string::npos) << b.text();
}

// The paper's linkage (eq. 56) with s1, sigma1, s3, sigma3 adjusted to eq. 57, masses and
// inertias kept: m1 s̄1 = -m2 (1 - s̄2/l2) l1 and m3 (s̄3 - l3) = m2 s̄2 l3 / l2.
struct PaperBalanced {
  double s1{}, sigma1{}, s3{}, sigma3{};  // [m], [rad], as a study file gives them
  core::FourBar model;
};
PaperBalanced paper_force_balanced() {
  PaperBalanced out;
  core::FourBar m = core::samples::paper_fourbar_unloaded();
  const core::Link &l1 = m.crank, &l2 = m.coupler, &l3 = m.rocker;
  const Complex s2(l2.e, l2.f);
  const Complex s1 = -l2.mass * (1.0 - s2 / l2.length) * l1.length / l1.mass;
  const Complex s3 = l3.length + l2.mass * s2 * l3.length / (l2.length * l3.mass);
  out.s1 = std::abs(s1);
  out.sigma1 = std::arg(s1);
  out.s3 = std::abs(s3);
  out.sigma3 = std::arg(s3);
  // built from the polar values, as the study file's loader does
  m.crank = core::link_from_polar(l1.length, l1.mass, out.s1, out.sigma1, l1.inertia);
  m.rocker = core::link_from_polar(l3.length, l3.mass, out.s3, out.sigma3, l3.inertia);
  out.model = core::make_fourbar(m);
  return out;
}

TEST(PaperExample, ForceBalancedLinkageHasNoShakingForceInFreeMotion) {
  const PaperBalanced p = paper_force_balanced();
  const core::FourBar& m = p.model;
  std::printf("s1 = %.17g, sigma1 = %.17g, s3 = %.17g, sigma3 = %.17g\n", p.s1, p.sigma1, p.s3,
              p.sigma3);
  const BalanceReport report = check_balance(m);
  EXPECT_TRUE(report.force_balanced()) << report.text();
  // §5.2: no loads, theta1 = 1 rad, omega1 = 1 rad/s, 5 s (Fig. 9)
  const core::FreeScene scene{1.0, 1.0, 5.0, 501};
  for (const core::Formulation f : core::kFormulations) {
    core::SimulateOptions options;
    options.formulation = f;
    const core::Trajectory t = core::simulate_free(m, scene, options);
    ASSERT_TRUE(t.ok()) << core::to_string(f) << ": " << t.message;
    double max_RA0 = 0.0, worst = 0.0;
    for (const core::DynamicsSample& s : t.samples) max_RA0 = std::max(max_RA0, s.RA0.norm());
    ASSERT_GT(max_RA0, 0.0);
    for (std::size_t k = 0; k < t.samples.size(); ++k) {
      const core::DynamicsSample& s = t.samples[k];
      const double sum = (s.RA0 + s.RA3).norm();
      worst = std::max(worst, sum / max_RA0);
      EXPECT_LE(sum, 1e-12 * max_RA0) << core::to_string(f) << ", t = " << t.t[k]
                                      << ": |RA0 + RA3| = " << sum << " of max |RA0| = " << max_RA0;
    }
    std::printf("%s: max |RA0| = %.6g N, worst |RA0 + RA3| / max |RA0| = %.3g\n",
                core::to_string(f), max_RA0, worst);
  }
}

}  // namespace
}  // namespace bd::balance
