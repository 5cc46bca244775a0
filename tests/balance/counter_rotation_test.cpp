// Counter-rotation synthesis (balance/counter_rotation.hpp): Berkof's full shaking-force and
// shaking-moment balance of an inline four-bar, verified by the simulated reactions of every
// formulation (which include the counter-rotating discs' shaft reactions), and the input errors.
//
// Tolerance: |Fsh| and |Msh| at every sample within 1e-9 of the unbalanced design's RMS values in
// the same scene. Balance holds exactly for the mass distribution, so what is left is round-off
// of sums of reactions and moments (eps times reactions a few times the unbalanced shaking
// force); a wrong counter-rotation inertia or a missed shaft reaction shows at order one.
#include "balance/counter_rotation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "balance/conditions.hpp"
#include "balance/counterweight.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/input_error.hpp"

namespace bd::balance {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// An inline crank-rocker (f1 = f2 = f3 = 0) with a Berkof coupler, I2 = m2 e2 (l2 - e2): after
// counterweights it can be fully balanced by counter-rotations.
core::FourBar berkof_inline() {
  core::FourBar m;
  m.crank = {0.6, 1.2, 0.25, 0.0, 0.05};
  const double l2 = 2.0, m2 = 2.0, e2 = 0.8;
  m.coupler = {l2, m2, e2, 0.0, m2 * e2 * (l2 - e2)};
  m.rocker = {1.5, 1.5, 0.9, 0.0, 0.3};
  m.frame_length = 2.2;
  m.branch = core::Branch::kPlus;
  return core::make_fourbar(m);
}

const Vec2 kCrankShaft(0.0, -0.5);  // [m], beside A0
const Vec2 kRockerShaft(2.6, 0.3);  // [m], beside A3 = (2.2, 0)

MomentBalancedDesign fully_balanced() {
  const ForceBalancedDesign f = force_balance(berkof_inline(), {}, {});
  return moment_balance(f.model, kCrankShaft, kRockerShaft);
}

TEST(MomentBalance, SetsCounterRotationsToTheReducedInertias) {
  const ForceBalancedDesign f = force_balance(berkof_inline(), {}, {});
  // counterweights on the link lines keep the design inline
  EXPECT_EQ(f.model.crank.f, 0.0);
  EXPECT_EQ(f.model.rocker.f, 0.0);
  const MomentBalancedDesign d = moment_balance(f.model, kCrankShaft, kRockerShaft);
  const ReducedInertias K = reduced_inertias(f.model);
  EXPECT_EQ(d.crank_inertia, K.crank);
  EXPECT_EQ(d.rocker_inertia, K.rocker);
  EXPECT_GT(K.crank, 0.0);
  EXPECT_GT(K.rocker, 0.0);
  EXPECT_EQ(d.model.counter_rotations.crank.inertia, K.crank);
  EXPECT_EQ(d.model.counter_rotations.rocker.inertia, K.rocker);
  EXPECT_EQ(d.model.counter_rotations.crank.at, kCrankShaft);
  EXPECT_EQ(d.model.counter_rotations.rocker.at, kRockerShaft);
  // the links are untouched
  EXPECT_EQ(d.model.crank.inertia, f.model.crank.inertia);
  EXPECT_EQ(d.model.rocker.mass, f.model.rocker.mass);
  const BalanceReport report = check_balance(d.model);
  EXPECT_TRUE(report.force_balanced()) << report.text();
  EXPECT_TRUE(report.moment_balanced()) << report.text();
  EXPECT_FALSE(check_balance(f.model).moment_balanced());
  std::printf("J1 = %.17g kg m², J3 = %.17g kg m²\n", K.crank, K.rocker);
}

// Fsh and Msh of the fully balanced design against the unbalanced design's RMS in one scene
void expect_no_shaking(const core::Trajectory& unbalanced, const core::Trajectory& balanced,
                       const std::string& at) {
  ASSERT_TRUE(unbalanced.ok()) << at << ": " << unbalanced.message;
  ASSERT_TRUE(balanced.ok()) << at << ": " << balanced.message;
  ASSERT_EQ(balanced.samples.size(), unbalanced.samples.size()) << at;
  const core::Metrics u = core::metrics(unbalanced);
  ASSERT_GT(u.Fsh_rms, 0.0) << at;
  ASSERT_GT(u.Msh_rms, 0.0) << at;
  double worst_F = 0.0, worst_M = 0.0;
  for (std::size_t k = 0; k < balanced.samples.size(); ++k) {
    const core::DynamicsSample& s = balanced.samples[k];
    EXPECT_LE(s.Fsh.norm(), 1e-9 * u.Fsh_rms) << at << ", sample " << k << ": |Fsh| "
                                              << s.Fsh.norm() << " of unbalanced RMS " << u.Fsh_rms;
    EXPECT_LE(std::abs(s.Msh), 1e-9 * u.Msh_rms)
        << at << ", sample " << k << ": |Msh| " << std::abs(s.Msh) << " of unbalanced RMS "
        << u.Msh_rms;
    worst_F = std::max(worst_F, s.Fsh.norm() / u.Fsh_rms);
    worst_M = std::max(worst_M, std::abs(s.Msh) / u.Msh_rms);
  }
  std::printf("%s: worst |Fsh| / RMS %.3g, |Msh| / RMS %.3g (unbalanced RMS %.4g N, %.4g N m)\n",
              at.c_str(), worst_F, worst_M, u.Fsh_rms, u.Msh_rms);
}

TEST(MomentBalance, FullyBalancedDesignShakesNeitherDrivenNorFree) {
  const core::FourBar unbalanced = berkof_inline();
  const core::FourBar balanced = fully_balanced().model;
  const core::DrivenScene driven{0.3, kTwoPi, 1, 72};
  const core::FreeScene free{0.3, kTwoPi, 2.0, 201};
  for (const core::Formulation f : core::kFormulations) {
    core::SimulateOptions options;
    options.formulation = f;
    const std::string name = core::to_string(f);
    expect_no_shaking(core::simulate_driven(unbalanced, driven, options),
                      core::simulate_driven(balanced, driven, options), name + ", driven");
    expect_no_shaking(core::simulate_free(unbalanced, free, options),
                      core::simulate_free(balanced, free, options), name + ", free");
  }
}

TEST(MomentBalance, CounterweightsAloneLeaveAShakingMoment) {
  // force balance without the counter-rotations: Fsh = 0 but Msh is not
  const core::FourBar f = force_balance(berkof_inline(), {}, {}).model;
  const core::Trajectory t = core::simulate_driven(f, {0.3, kTwoPi, 1, 72});
  ASSERT_TRUE(t.ok()) << t.message;
  const core::Metrics m = core::metrics(t);
  const core::Metrics u =
      core::metrics(core::simulate_driven(berkof_inline(), {0.3, kTwoPi, 1, 72}));
  EXPECT_LE(m.Fsh_max, 1e-9 * u.Fsh_rms);
  EXPECT_GT(m.Msh_rms, 0.1 * u.Msh_rms);
}

void expect_input_error(const core::FourBar& model, Vec2 crank_at, Vec2 rocker_at,
                        const std::string& starts_with) {
  try {
    (void)moment_balance(model, crank_at, rocker_at);
    ADD_FAILURE() << "no error; expected \"" << starts_with << "...\"";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.substr(0, starts_with.size()), starts_with) << what;
  }
}

TEST(MomentBalance, RejectsDesignsItCannotBalance) {
  // not force balanced
  expect_input_error(berkof_inline(), kCrankShaft, kRockerShaft,
                     "moment_balance needs a force-balanced design: force.crank (eq. 57");
  // a coupler off its centre line
  core::FourBar skew = berkof_inline();
  skew.coupler.f = 0.05;
  expect_input_error(force_balance(skew, {}, {}).model, kCrankShaft, kRockerShaft,
                     "moment_balance needs a Berkof coupler: coupler.f2 (f2 = 0");
  // a coupler whose inertia is not m2 e2 (l2 - e2)
  core::FourBar heavy = berkof_inline();
  heavy.coupler.inertia *= 1.01;
  try {
    (void)moment_balance(force_balance(heavy, {}, {}).model, kCrankShaft, kRockerShaft);
    ADD_FAILURE() << "no error for I2 off by 1%";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("coupler.inertia"), std::string::npos) << what;
    EXPECT_NE(what.find("I2 = 1.939"), std::string::npos) << what;
    EXPECT_NE(what.find("m2 e2 (l2 - e2) = 1.9199999999999999 kg m²"), std::string::npos) << what;
  }
  // a shaft on its link's pivot
  const core::FourBar f = force_balance(berkof_inline(), {}, {}).model;
  expect_input_error(f, Vec2(0, 0), kRockerShaft, "counter_rotations.crank: distance");
  expect_input_error(f, kCrankShaft, Vec2(2.2, 0), "counter_rotations.rocker: distance");
}

TEST(MomentBalance, LeavesItsInputUntouched) {
  const core::FourBar f = force_balance(berkof_inline(), {}, {}).model;
  const core::FourBar copy = f;
  (void)moment_balance(f, kCrankShaft, kRockerShaft);
  EXPECT_EQ(f.counter_rotations.crank.inertia, copy.counter_rotations.crank.inertia);
  EXPECT_FALSE(core::has_counter_rotations(f));
}

}  // namespace
}  // namespace bd::balance
