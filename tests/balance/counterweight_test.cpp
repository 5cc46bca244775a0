// Counterweight synthesis (balance/counterweight.hpp): full shaking-force balance of random
// linkages verified by the simulated reactions of every formulation, the realisation of each
// counterweight spec, the parallel-axis merge, and the input errors.
//
// Tolerances.
// - Residuals of eq. 57 after balancing: 1e-12 of force_balance_scales (the masses involved, or
//   the terms' magnitudes if larger). The synthesis is a handful of complex operations, so what
//   is left is a few eps of that scale.
// - Centre of mass over a revolution: 1e-12 of the longest link; Σ m_k r_k / M is computed to a
//   few eps of the lever arms involved.
// - Shaking force: 1e-9 of the unbalanced design's RMS |Fsh| in the same scene. Balance is a
//   property of the mass distribution, so every formulation gives Fsh = 0 up to the round-off of
//   RA0 + RA3 (eps times the reactions, which the counterweights make at most a few times the
//   unbalanced shaking force). The margin covers linkages whose reactions are large compared to
//   their unbalanced shaking force; a formula error shows at order one.
#include "balance/counterweight.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "balance/conditions.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/energy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/input_error.hpp"

namespace bd::balance {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::FourBar without_loads(core::FourBar m) {
  m.loads = core::Loads{};
  return core::make_fourbar(m);
}

double longest_link(const core::FourBar& m) {
  return std::max({m.crank.length, m.coupler.length, m.rocker.length, m.frame_length});
}

// largest |Fsh| over a trajectory's samples
double max_Fsh(const core::Trajectory& t) {
  double worst = 0.0;
  for (const core::DynamicsSample& s : t.samples) worst = std::max(worst, s.Fsh.norm());
  return worst;
}

void expect_residuals_vanish(const core::FourBar& m, const std::string& at) {
  const ForceBalanceResiduals r = force_balance_residuals(m);
  const ForceBalanceScales s = force_balance_scales(m);
  EXPECT_LE(std::abs(r.crank), 1e-12 * s.crank) << at << ": crank residual " << r.crank;
  EXPECT_LE(std::abs(r.rocker), 1e-12 * s.rocker) << at << ": rocker residual " << r.rocker;
  EXPECT_TRUE(check_balance(m).force_balanced()) << at << "\n" << check_balance(m).text();
}

// the crank and rocker point-mass models of a merged link, built independently of merged():
// link inertia as a ring of point masses about its own centre, plus the counterweight
struct PointMasses {
  std::vector<double> m;
  std::vector<Vec2> r;  // link axes from the first joint [m]
};
PointMasses point_masses(const core::Link& link, const Counterweight& cw, bool from_second) {
  PointMasses p;
  // four equal masses on a circle of radius rho about the link's centre of mass carry its
  // inertia m rho² exactly; the same for a disc counterweight
  auto add_body = [&p](double mass, double inertia, const Vec2& c) {
    if (inertia == 0.0) {
      p.m.push_back(mass);
      p.r.push_back(c);
      return;
    }
    const double rho = std::sqrt(inertia / mass);
    for (int k = 0; k < 4; ++k) {
      p.m.push_back(mass / 4);
      p.r.push_back(c + rho * unit(0.7 + k * std::numbers::pi / 2));
    }
  };
  add_body(link.mass, link.inertia, Vec2(link.e, link.f));
  add_body(cw.mass, cw.inertia,
           from_second ? Vec2(Vec2(link.length, 0) + cw.position) : cw.position);
  return p;
}

void expect_merge_is_parallel_axis_sum(const core::Link& link, const Counterweight& cw,
                                       bool from_second, const std::string& at) {
  const core::Link got = merged(link, cw, from_second);
  const PointMasses p = point_masses(link, cw, from_second);
  double M = 0.0;
  Vec2 first = Vec2::Zero();
  for (std::size_t k = 0; k < p.m.size(); ++k) {
    M += p.m[k];
    first += p.m[k] * p.r[k];
  }
  const Vec2 c = first / M;
  double I = 0.0;
  for (std::size_t k = 0; k < p.m.size(); ++k) I += p.m[k] * (p.r[k] - c).squaredNorm();
  const double L = link.length + cw.distance;
  EXPECT_NEAR(got.mass, M, 1e-14 * M) << at;
  EXPECT_NEAR(got.e, c.x(), 1e-12 * L) << at;
  EXPECT_NEAR(got.f, c.y(), 1e-12 * L) << at;
  EXPECT_NEAR(got.inertia, I, 1e-12 * (I + M * L * L)) << at;
  EXPECT_EQ(got.length, link.length) << at;
}

void expect_realisable(const std::optional<Counterweight>& cw, const std::string& at) {
  if (!cw) return;
  EXPECT_GT(cw->mass, 0.0) << at;
  EXPECT_TRUE(std::isfinite(cw->mass)) << at;
  EXPECT_GT(cw->distance, 0.0) << at;
  EXPECT_NEAR(cw->position.norm(), cw->distance, 1e-14 * cw->distance) << at;
}

TEST(ForceBalance, RandomLinkagesLoseTheirShakingForceInEveryFormulation) {
  std::mt19937_64 rng(20240611);
  double worst_residual = 0.0, worst_com = 0.0;
  double worst_driven[3] = {0, 0, 0}, worst_free[3] = {0, 0, 0};
  for (int trial = 0; trial < 100; ++trial) {
    // shaking-force balance is about inertia forces: applied loads and gravity add Σ F to Fsh
    const core::FourBar model = without_loads(core::samples::random_crank_rocker(rng));
    const std::string at = "linkage " + std::to_string(trial);
    const ForceBalancedDesign design = force_balance(model, {}, {});
    const core::FourBar& b = design.model;

    // (a) eq. 57
    expect_residuals_vanish(b, at);
    const ForceBalanceResiduals r = force_balance_residuals(b);
    const ForceBalanceScales rs = force_balance_scales(b);
    worst_residual =
        std::max({worst_residual, std::abs(r.crank) / rs.crank, std::abs(r.rocker) / rs.rocker});
    expect_realisable(design.crank, at);
    expect_realisable(design.rocker, at);
    if (design.crank) expect_merge_is_parallel_axis_sum(model.crank, *design.crank, false, at);
    if (design.rocker) expect_merge_is_parallel_axis_sum(model.rocker, *design.rocker, true, at);
    // the default spec puts the counterweight a link length from its pivot
    if (design.crank) {
      EXPECT_NEAR(design.crank->distance, model.crank.length, 1e-15) << at;
    }
    if (design.rocker) {
      EXPECT_NEAR(design.rocker->distance, model.rocker.length, 1e-15) << at;
    }
    EXPECT_EQ(b.coupler.mass, model.coupler.mass) << at;

    // (b) the centre of mass stands still over a revolution
    const auto p0 = core::solve_position(b, 0.0);
    ASSERT_TRUE(p0.has_value()) << at;
    const Vec2 S0 = core::system_centre_of_mass(b, *p0);
    for (int k = 1; k < 72; ++k) {
      const auto p = core::solve_position(b, kTwoPi * k / 72);
      ASSERT_TRUE(p.has_value()) << at;
      const double moved = (core::system_centre_of_mass(b, *p) - S0).norm();
      worst_com = std::max(worst_com, moved / longest_link(b));
      EXPECT_LE(moved, 1e-12 * longest_link(b)) << at << ", sample " << k;
    }

    // (c) the shaking force vanishes in a driven revolution and in free motion
    const core::DrivenScene driven{0.4, kTwoPi, 1, 72};
    const core::FreeScene free{0.4, kTwoPi, 2.0, 201};
    const core::Trajectory driven_unbalanced = core::simulate_driven(model, driven);
    const core::Trajectory free_unbalanced = core::simulate_free(model, free);
    ASSERT_TRUE(driven_unbalanced.ok()) << at << ": " << driven_unbalanced.message;
    ASSERT_TRUE(free_unbalanced.ok()) << at << ": " << free_unbalanced.message;
    const double driven_scale = core::metrics(driven_unbalanced).Fsh_rms;
    const double free_scale = core::metrics(free_unbalanced).Fsh_rms;
    for (int fi = 0; fi < 3; ++fi) {
      const core::Formulation f = core::kFormulations[fi];
      core::SimulateOptions options;
      options.formulation = f;
      const std::string with = at + ", " + core::to_string(f);
      const core::Trajectory d = core::simulate_driven(b, driven, options);
      const core::Trajectory fr = core::simulate_free(b, free, options);
      ASSERT_TRUE(d.ok()) << with << ": " << d.message;
      ASSERT_TRUE(fr.ok()) << with << ": " << fr.message;
      ASSERT_EQ(d.samples.size(), 72u) << with;
      ASSERT_EQ(fr.samples.size(), 201u) << with;
      for (std::size_t k = 0; k < d.samples.size(); ++k) {
        EXPECT_LE(d.samples[k].Fsh.norm(), 1e-9 * driven_scale)
            << with << ", driven sample " << k << " of unbalanced RMS " << driven_scale;
      }
      for (std::size_t k = 0; k < fr.samples.size(); ++k) {
        EXPECT_LE(fr.samples[k].Fsh.norm(), 1e-9 * free_scale)
            << with << ", free sample " << k << " (t = " << fr.t[k] << ") of unbalanced RMS "
            << free_scale;
      }
      worst_driven[fi] = std::max(worst_driven[fi], max_Fsh(d) / driven_scale);
      worst_free[fi] = std::max(worst_free[fi], max_Fsh(fr) / free_scale);
    }
  }
  // what was measured, for the docs (not asserted beyond the bounds above)
  std::printf("worst relative residual %.3g, centre-of-mass motion %.3g\n", worst_residual,
              worst_com);
  for (int fi = 0; fi < 3; ++fi) {
    std::printf("%s: worst |Fsh| / unbalanced RMS driven %.3g, free %.3g\n",
                core::to_string(core::kFormulations[fi]), worst_driven[fi], worst_free[fi]);
  }
}

TEST(ForceBalance, AlreadyBalancedSideGetsNoCounterweight) {
  const core::FourBar model = core::samples::paper_fourbar_unloaded();
  const ForceBalancedDesign once = force_balance(model, {}, {});
  ASSERT_TRUE(once.crank.has_value());
  ASSERT_TRUE(once.rocker.has_value());
  const ForceBalancedDesign twice = force_balance(once.model, {}, {});
  EXPECT_FALSE(twice.crank.has_value());
  EXPECT_FALSE(twice.rocker.has_value());
  EXPECT_EQ(twice.added_mass, 0.0);
  EXPECT_EQ(twice.model.crank.mass, once.model.crank.mass);
  EXPECT_EQ(twice.model.rocker.inertia, once.model.rocker.inertia);
}

TEST(ForceBalance, LeavesInputUntouchedAndKeepsLoadsAndCounterRotations) {
  const core::FourBar model = core::samples::paper_fourbar();
  const core::FourBar copy = model;
  const ForceBalancedDesign d = force_balance(model, {}, {});
  EXPECT_EQ(model.crank.mass, copy.crank.mass);
  EXPECT_EQ(model.rocker.e, copy.rocker.e);
  EXPECT_EQ(d.model.loads.crank.force, model.loads.crank.force);
  EXPECT_EQ(d.model.frame_length, model.frame_length);
  EXPECT_EQ(d.model.branch, model.branch);
}

// one side of the paper's linkage with each kind of spec
struct SpecCase {
  std::string name;
  CounterweightSpec spec;
};

std::vector<SpecCase> spec_cases() {
  std::vector<SpecCase> cases;
  CounterweightSpec s;
  cases.push_back({"default point", s});
  s = {};
  s.mass = 3.5;
  cases.push_back({"given mass", s});
  s = {};
  s.distance = 0.45;
  cases.push_back({"given distance", s});
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.radius = 0.12;
  s.thickness = 0.05;
  cases.push_back({"disc with radius", s});
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.distance = 0.6;
  cases.push_back({"disc with solved mass", s});
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.mass = 4.0;
  s.density = 2700.0;
  cases.push_back({"disc with given mass", s});
  s = {};
  s.shape = CounterweightShape::kDisc;
  cases.push_back({"default disc", s});
  return cases;
}

TEST(ForceBalance, EverySpecIsRealisedAndBalances) {
  const core::FourBar model = core::samples::paper_fourbar_unloaded();
  for (const SpecCase& c : spec_cases()) {
    const ForceBalancedDesign d = force_balance(model, c.spec, c.spec);
    expect_residuals_vanish(d.model, c.name);
    double added_mass = 0.0, added_inertia = 0.0;
    for (int side = 0; side < 2; ++side) {
      const std::optional<Counterweight>& cw = side == 0 ? d.crank : d.rocker;
      const core::Link& link = side == 0 ? model.crank : model.rocker;
      const std::string at = c.name + (side == 0 ? ", crank" : ", rocker");
      ASSERT_TRUE(cw.has_value()) << at;
      expect_realisable(cw, at);
      expect_merge_is_parallel_axis_sum(link, *cw, side == 1, at);
      const CounterweightSpec& s = c.spec;
      if (s.mass) {
        EXPECT_EQ(cw->mass, *s.mass) << at;
      }
      if (s.distance) {
        EXPECT_NEAR(cw->distance, *s.distance, 1e-15) << at;
      }
      if (!s.mass && !s.distance && !s.radius) {
        EXPECT_NEAR(cw->distance, link.length, 1e-15) << at;
      }
      if (s.shape == CounterweightShape::kDisc) {
        EXPECT_GT(cw->radius, 0.0) << at;
        EXPECT_EQ(cw->thickness, s.thickness) << at;
        // the disc's mass, radius, thickness and density agree, and its inertia is m r²/2
        const double disc_mass =
            s.density * std::numbers::pi * cw->radius * cw->radius * s.thickness;
        EXPECT_NEAR(cw->mass, disc_mass, 1e-14 * disc_mass) << at;
        EXPECT_NEAR(cw->inertia, 0.5 * cw->mass * cw->radius * cw->radius, 1e-15 * cw->inertia)
            << at;
        if (s.radius) {
          EXPECT_EQ(cw->radius, *s.radius) << at;
        }
      } else {
        EXPECT_EQ(cw->radius, 0.0) << at;
        EXPECT_EQ(cw->inertia, 0.0) << at;
      }
      // the mass moment about the pivot is what eq. 57 asks for
      const core::Link& l2 = model.coupler;
      // (in the paper's complex notation)
      using Complex = std::complex<double>;
      const Complex s2(l2.e, l2.f);
      const Complex want = side == 0 ? -l2.mass * (1.0 - s2 / l2.length) * link.length
                                     : l2.mass * s2 * link.length / l2.length;
      const Complex own = side == 0 ? link.mass * Complex(link.e, link.f)
                                    : link.mass * (Complex(link.e, link.f) - link.length);
      const Complex got = own + cw->mass * Complex(cw->position.x(), cw->position.y());
      EXPECT_LE(std::abs(got - want), 1e-13 * std::abs(want)) << at;
      added_mass += cw->mass;
      added_inertia += cw->inertia + cw->mass * cw->distance * cw->distance;
    }
    EXPECT_DOUBLE_EQ(d.added_mass, added_mass) << c.name;
    EXPECT_DOUBLE_EQ(d.added_inertia, added_inertia) << c.name;
  }
}

TEST(ForceBalance, RockerCounterweightSitsBeyondA3SeenFromA2) {
  // a rocker counterweight at q from A3 lies at l3 + q from A2
  core::Link rocker{2.0, 1.0, 0.5, 0.1, 0.2};
  Counterweight cw;
  cw.mass = 3.0;
  cw.position = Vec2(0.4, -0.2);
  cw.distance = cw.position.norm();
  const core::Link m = merged(rocker, cw, true);
  EXPECT_DOUBLE_EQ(m.mass, 4.0);
  EXPECT_DOUBLE_EQ(m.e, (1.0 * 0.5 + 3.0 * 2.4) / 4.0);
  EXPECT_DOUBLE_EQ(m.f, (1.0 * 0.1 + 3.0 * -0.2) / 4.0);
  const core::Link c = merged(rocker, cw, false);
  EXPECT_DOUBLE_EQ(c.e, (1.0 * 0.5 + 3.0 * 0.4) / 4.0);
}

void expect_input_error(const CounterweightSpec& crank, const CounterweightSpec& rocker,
                        const std::string& expected) {
  try {
    (void)force_balance(core::samples::paper_fourbar_unloaded(), crank, rocker);
    ADD_FAILURE() << "no error; expected \"" << expected << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

TEST(ForceBalance, InvalidSpecsAreInputErrors) {
  CounterweightSpec s;
  s.mass = 1.0;
  s.distance = 0.5;
  expect_input_error(s, {},
                     "crank counterweight: give at most one of mass, distance and radius (the "
                     "others are solved), got mass = 1 kg and distance = 0.5 m");
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.mass = 2.0;
  s.radius = 0.1;
  expect_input_error({}, s,
                     "rocker counterweight: give at most one of mass, distance and radius (the "
                     "others are solved), got mass = 2 kg and radius = 0.10000000000000001 m");
  s = {};
  s.mass = -1.0;
  expect_input_error(s, {}, "crank counterweight: mass must be > 0 kg, got -1");
  s = {};
  s.distance = 0.0;
  expect_input_error({}, s, "rocker counterweight: distance must be > 0 m, got 0");
  s = {};
  s.distance = std::nan("");
  expect_input_error(s, {}, "crank counterweight: distance must be > 0 m, got nan");
  s = {};
  s.radius = 0.1;
  expect_input_error(
      s, {},
      "crank counterweight: radius is given for a point counterweight; radius needs shape disc");
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.radius = -0.1;
  expect_input_error(s, {}, "crank counterweight: radius must be > 0 m, got -0.10000000000000001");
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.thickness = 0.0;
  expect_input_error({}, s, "rocker counterweight: thickness must be > 0 m, got 0");
  s = {};
  s.shape = CounterweightShape::kDisc;
  s.density = -7850.0;
  expect_input_error({}, s, "rocker counterweight: density must be > 0 kg/m^3, got -7850");
  // the spec's own validate() says the same without the side
  s = {};
  s.mass = 0.0;
  EXPECT_EQ(problem_text(s.validate()), "mass must be > 0 kg, got 0");
  EXPECT_EQ(s.validate()->field, "mass");
  EXPECT_EQ(problem_text(CounterweightSpec{}.validate()), "");
}

}  // namespace
}  // namespace bd::balance
