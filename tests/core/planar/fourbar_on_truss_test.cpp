// The four-bar on the general planar engine (truss elements in node coordinates) against the
// dedicated closed-form four-bar: at random states of random crank-rockers on both branches,
// inverse and forward dynamics give the same angles, rates, accelerations, support reactions,
// shaking force and moment and drive torque to 1e-12 of each quantity's scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/scales.hpp"

namespace bd::core::planar {
namespace {

// Both routes are exact; they differ by the round-off of small solves (~1e-15 relative); the
// margin covers the amplification of a poorly conditioned position (transmission angle near 0).
constexpr double kTol = 1e-12;

void expect_same(const DynamicsSample& d, const Instant& in, const FourBar& fb,
                 const std::string& what) {
  const double force = bd::testing::force_scale(d);
  const double moment = bd::testing::moment_scale(fb, d);
  const double rate = bd::testing::rate_scale(d), acc = bd::testing::acceleration_scale(d);
  // link angles: the planar engine keeps them continuous; compare modulo 2π
  auto angle_gap = [](double a, double b) { return std::remainder(a - b, 2 * M_PI); };
  EXPECT_NEAR(angle_gap(in.angle[1], d.state.theta2), 0.0, kTol) << what;
  EXPECT_NEAR(angle_gap(in.angle[2], d.state.theta3), 0.0, kTol) << what;
  EXPECT_NEAR(in.omega[1], d.state.omega2, kTol * rate) << what;
  EXPECT_NEAR(in.omega[2], d.state.omega3, kTol * rate) << what;
  EXPECT_NEAR(in.alpha[0], d.state.alpha1, kTol * acc) << what;
  EXPECT_NEAR(in.alpha[1], d.state.alpha2, kTol * acc) << what;
  EXPECT_NEAR(in.alpha[2], d.state.alpha3, kTol * acc) << what;
  EXPECT_LT((in.ground_reaction[0] - d.RA0).norm(), kTol * force) << what;
  EXPECT_LT((in.ground_reaction[1] - d.RA3).norm(), kTol * force) << what;
  EXPECT_LT((in.Fsh - d.Fsh).norm(), kTol * force) << what;
  EXPECT_NEAR(in.Msh, d.Msh, kTol * moment) << what;
  EXPECT_NEAR(in.effort[0], d.tau, kTol * moment) << what;
}

TEST(FourBarOnTruss, InverseDynamicsEqualsTheClosedFormOnRandomLinkagesBothBranches) {
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20, 20), acc(-200, 200);
  int compared = 0;
  for (int i = 0; i < 200; ++i) {
    FourBar fb = samples::random_crank_rocker(rng);
    if (i % 2) fb.branch = fb.branch == Branch::kPlus ? Branch::kMinus : Branch::kPlus;
    const double theta1 = angle(rng), omega1 = rate(rng), alpha1 = acc(rng);
    const auto d = inverse_dynamics(fb, theta1, omega1, alpha1);
    if (!d) continue;  // a dead centre of the dedicated route
    const Model model(linkage_of(fb, theta1));
    Workspace ws(model);
    std::vector<Vec2> guess = ws.instant.x;
    ASSERT_TRUE(solve_position(model, ws, guess, {theta1}));
    const auto r = inverse_dynamics(model, ws, 0.0, {omega1}, {alpha1});
    ASSERT_TRUE(r) << r.error().detail;
    expect_same(*d, ws.instant, fb, "linkage " + std::to_string(i));
    ++compared;
  }
  EXPECT_GT(compared, 190);
}

TEST(FourBarOnTruss, ForwardDynamicsEqualsTheClosedFormOnRandomLinkages) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20, 20);
  int compared = 0;
  for (int i = 0; i < 200; ++i) {
    FourBar fb = samples::random_crank_rocker(rng);
    if (i % 2) fb.branch = fb.branch == Branch::kPlus ? Branch::kMinus : Branch::kPlus;
    const double theta1 = angle(rng), omega1 = rate(rng);
    const auto d = forward_dynamics(fb, theta1, omega1);
    if (!d) continue;
    const Model model(linkage_of(fb, theta1));
    Workspace ws(model);
    ASSERT_TRUE(solve_position(model, ws, ws.instant.x, {theta1}));
    const auto r = forward_dynamics(model, ws, 0.0, {omega1}, {0.0});
    ASSERT_TRUE(r) << r.error().detail;
    expect_same(*d, ws.instant, fb, "linkage " + std::to_string(i));
    ++compared;
  }
  EXPECT_GT(compared, 190);
}

// Counter-rotating discs (Berkof's moment balance) on random four-bars under gravity: the
// general engine's balance shafts with ratio -1 against the four-bar's own discs (a mesh force
// at the midpoint, core/fourbar/counter_rotation.cpp), reaction by reaction, shafts included,
// in inverse and forward dynamics. The two share no code: the four-bar adds each disc's inertia
// to its link and loads the bare linkage with the mesh force; the general engine carries the
// disc on the link's element and adds the tooth force at the pair's pitch point.
TEST(FourBarOnTruss, CounterRotationsEqualTheFourBarsDiscsReactionByReaction) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20, 20), acc(-200, 200),
      inertia(0.001, 0.05), place(-0.3, 0.3);
  int compared = 0;
  for (int i = 0; i < 100; ++i) {
    FourBar fb = samples::random_crank_rocker(rng);
    fb.loads.gravity = Vec2(0.3, -9.81);
    fb.counter_rotations.crank = {inertia(rng), Vec2(place(rng), place(rng) + 0.5)};
    if (i % 3)
      fb.counter_rotations.rocker = {inertia(rng), Vec2(fb.frame_length + place(rng), -0.4)};
    const double theta1 = angle(rng), omega1 = rate(rng), alpha1 = acc(rng);
    const auto d =
        i % 2 ? inverse_dynamics(fb, theta1, omega1, alpha1) : forward_dynamics(fb, theta1, omega1);
    if (!d) continue;
    const Model model(linkage_of(fb, theta1));
    ASSERT_EQ(model.linkage().shafts.size(), i % 3 ? 2u : 1u);
    Workspace ws(model);
    ASSERT_TRUE(solve_position(model, ws, ws.instant.x, {theta1}));
    const auto r = i % 2 ? inverse_dynamics(model, ws, 0.0, {omega1}, {alpha1})
                         : forward_dynamics(model, ws, 0.0, {omega1}, {0.0});
    ASSERT_TRUE(r) << r.error().detail;
    const std::string what = "linkage " + std::to_string(i);
    expect_same(*d, ws.instant, fb, what);
    const double force = bd::testing::force_scale(*d);
    EXPECT_LT((ws.instant.shaft_reaction[0] - d->RC1).norm(), kTol * force) << what;
    if (i % 3) {
      EXPECT_LT((ws.instant.shaft_reaction[1] - d->RC3).norm(), kTol * force) << what;
    }
    ++compared;
  }
  EXPECT_GT(compared, 90);
}

TEST(FourBarOnTruss, AssemblyFollowsTheDrawnBranchToAnyCrankAngle) {
  const FourBar fb = samples::paper_fourbar();
  for (Branch b : {Branch::kPlus, Branch::kMinus}) {
    FourBar m = fb;
    m.branch = b;
    const Model model(linkage_of(m, 1.0));
    Workspace ws(model);
    for (double theta1 : {1.0, 2.5, -2.0, 4.0}) {
      ASSERT_TRUE(assemble(model, ws, {theta1}));
      const auto pose = solve_position(m, theta1);
      ASSERT_TRUE(pose);
      const Joints j = joint_positions(m, *pose);
      EXPECT_LT((ws.instant.x[1] - j.A1).norm(), 1e-13);
      EXPECT_LT((ws.instant.x[2] - j.A2).norm(), 1e-13);
    }
  }
}

}  // namespace
}  // namespace bd::core::planar

namespace bd::core::planar {
namespace {

// the largest difference between a column of the planar table and a four-bar quantity,
// relative to the quantity's largest magnitude over the run
double column_gap(const Trajectory& p, const char* column, const core::Trajectory& f,
                  double (*get)(const DynamicsSample&)) {
  const std::vector<double> col = p.table.column_values(column);
  double scale = 0, gap = 0;
  for (std::size_t i = 0; i < f.samples.size(); ++i)
    scale = std::max(scale, std::abs(get(f.samples[i])));
  for (std::size_t i = 0; i < f.samples.size() && i < col.size(); ++i) {
    gap = std::max(gap, std::abs(col[i] - get(f.samples[i])));
  }
  return gap / std::max(scale, 1e-300);
}

TEST(FourBarOnTruss, FreeMotionAgreesWithTheClosedFormToTheToleranceAskedFor) {
  // the paper's loaded four-bar, 5 s from rest at theta1 = 1: both integrated at tolerance
  // 1e-12 (relative; absolute 1e-14), so each is correct to about 1e-11 of the motion's scale
  const FourBar fb = samples::paper_fourbar();
  core::FreeScene fs{1.0, 0.0, 5.0, 501};
  core::SimulateOptions fo;
  fo.tolerance = 1e-12;
  fo.absolute_tolerance = 1e-14;
  const core::Trajectory f = core::simulate_free(fb, fs, fo);
  ASSERT_TRUE(f.ok()) << f.message;
  const Model model(linkage_of(fb, 1.0));
  for (Route route : {Route::kReduced, Route::kDae}) {
    SimulateOptions po;
    po.route = route;
    po.tolerance = 1e-12;
    po.absolute_tolerance = 1e-14;
    const Trajectory p = simulate_free(model, FreeScene{{1.0}, {0.0}, 5.0, 501}, po);
    ASSERT_TRUE(p.ok()) << to_string(route) << ": " << p.message;
    ASSERT_EQ(p.table.rows(), f.samples.size());
    SCOPED_TRACE(to_string(route));
    EXPECT_LT(
        column_gap(p, "theta_crank", f, [](const DynamicsSample& d) { return d.state.theta1; }),
        1e-10);
    EXPECT_LT(
        column_gap(p, "omega_crank", f, [](const DynamicsSample& d) { return d.state.omega1; }),
        1e-10);
    EXPECT_LT(
        column_gap(p, "alpha_rocker", f, [](const DynamicsSample& d) { return d.state.alpha3; }),
        1e-10);
    EXPECT_LT(column_gap(p, "RA0x", f, [](const DynamicsSample& d) { return d.RA0.x(); }), 1e-10);
    EXPECT_LT(column_gap(p, "RA3y", f, [](const DynamicsSample& d) { return d.RA3.y(); }), 1e-10);
    EXPECT_LT(column_gap(p, "Msh", f, [](const DynamicsSample& d) { return d.Msh; }), 1e-10);
  }
}

TEST(FourBarOnTruss, DrivenRevolutionEqualsTheClosedForm) {
  const FourBar fb = samples::paper_fourbar();
  const core::Trajectory f = core::simulate_driven(fb, core::DrivenScene{0.3, 6.0, 2, 360});
  ASSERT_TRUE(f.ok());
  const Model model(linkage_of(fb, 0.3));
  const Trajectory p = simulate_driven(model, DrivenScene{{0.3}, {6.0}, 2, 0, 360});
  ASSERT_TRUE(p.ok()) << p.message;
  ASSERT_EQ(p.table.rows(), f.samples.size());
  const std::vector<double> t = p.table.column_values("t");
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(t[i], f.t[i], 1e-15 * f.t.back());
  EXPECT_LT(column_gap(p, "tau", f, [](const DynamicsSample& d) { return d.tau; }), 1e-12);
  EXPECT_LT(column_gap(p, "Fshx", f, [](const DynamicsSample& d) { return d.Fsh.x(); }), 1e-12);
  EXPECT_LT(column_gap(p, "Msh", f, [](const DynamicsSample& d) { return d.Msh; }), 1e-12);
  EXPECT_LT(column_gap(p, "RA3x", f, [](const DynamicsSample& d) { return d.RA3.x(); }), 1e-12);
}

}  // namespace
}  // namespace bd::core::planar
