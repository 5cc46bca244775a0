// The general planar engine against the independent referee (tests/reference/planar: Newton–
// Euler of rigid bodies in maximal coordinates, long-double internals) in DRIVEN scenes: random
// slider-cranks (inline, offset), inverted slider-cranks (the swinging and the turning guide,
// and the shaper with its ram), Watt II and Stephenson III six-bars with a ternary link whose
// centre of mass is off its element's line, and two-input five-bars, all with random masses,
// inertias, point masses, gravity and loads, driven at constant speeds over a revolution.
//
// Every column of the engine's table (link angles, rates, accelerations; slider positions,
// rates, accelerations; node positions; ground and frame-guide reactions; joint forces; Fsh,
// Msh; the drive efforts; the inertial parts) and what the table lacks of an Instant (node
// velocities and accelerations, the inputs' values, rates and accelerations) must equal the
// referee's to 1e-10 relative to each quantity's scale over the run (tests/support/
// planar_glue.hpp, compare_tables). Both codes are exact in a driven scene (no integration):
// they differ by round-off amplified by the conditioning of the positions (transmission angles
// are kept away from 0 and π: tests/support/planar_mechanisms.hpp), ~1e-13 measured; 1e-10
// leaves room for an unlucky draw but not for any modelling error, which shows at 1e-3 or more.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

constexpr double kTol = 1e-10;

// The engine's Instants along a driven scene, evaluated by the public per-instant API exactly as
// the scene is defined (inputs at start + speed t, constant speeds), positions continued from
// the previous instant.
core::Series engine_instants(const cp::Model& model, const std::vector<double>& speeds,
                             const std::vector<double>& times) {
  core::Series out;
  out.columns = instant_columns(model);
  general_route(model, speeds, times,
                [&](const cp::Instant& in) { append_instant(model, in, out); });
  return out;
}

// One driven revolution of the linkage on both codes; the agreement of every quantity.
Agreement driven_agreement(const cp::Linkage& linkage, const std::vector<double>& speeds,
                           int samples, const std::string& label) {
  const cp::Model model(linkage);
  cp::DrivenScene scene;
  scene.speeds = speeds;
  scene.samples = samples;
  const cp::Trajectory tr = cp::simulate_driven(model, scene);
  EXPECT_TRUE(tr.ok()) << label << ": " << tr.message;
  EXPECT_EQ(tr.table.rows(), static_cast<std::size_t>(samples)) << label;
  EXPECT_TRUE(all_finite(tr.table)) << label;
  const Glue g = glue_of(linkage);
  const std::vector<double> times = tr.table.column_values("t");
  std::vector<rf::Sample> ref;
  try {
    ref = rf::driven(g.mechanism, speeds, 0.0, times);
  } catch (const std::exception& e) {
    ADD_FAILURE() << label << ": the referee failed: " << e.what();
    return {};
  }
  Agreement a = compare_tables(model, tr.table, reference_table(model, g, ref), label);
  core::Series reference_instants;
  reference_instants.columns = instant_columns(model);
  for (const rf::Sample& s : ref) append_reference_instant(g, s, reference_instants);
  a.merge(compare_tables(model, engine_instants(model, speeds, times), reference_instants, label));
  expect_agreement(a, kTol, label);
  return a;
}

template <class Make>
void run_family(const char* family, std::uint64_t seed, int count, Make make) {
  Rng rng(seed);
  Agreement all;
  for (int i = 0; i < count; ++i) {
    const cp::Linkage l = make(rng);
    std::vector<double> speeds;
    for (std::size_t k = 0; k < l.inputs.size(); ++k) speeds.push_back(random_speed(rng));
    all.merge(driven_agreement(l, speeds, 120, std::string(family) + " #" + std::to_string(i)));
  }
  std::printf("%s, %d driven revolutions, worst relative differences:\n%s", family, count,
              all.text().c_str());
}

TEST(RefereeDriven, InlineSliderCranks) {
  run_family("inline slider-crank", 101, 36, [](Rng& r) { return slider_crank(r, true); });
}
TEST(RefereeDriven, OffsetSliderCranks) {
  run_family("offset slider-crank", 102, 36, [](Rng& r) { return slider_crank(r, false); });
}
TEST(RefereeDriven, SwingingGuideQuickReturns) {
  run_family("quick return, swinging guide", 103, 36,
             [](Rng& r) { return quick_return(r, false, false); });
}
TEST(RefereeDriven, WhitworthQuickReturns) {
  run_family("Whitworth, turning guide", 104, 36,
             [](Rng& r) { return quick_return(r, true, false); });
}
TEST(RefereeDriven, Shapers) {
  run_family("shaper (guide on the rocker, ram on the frame)", 105, 36,
             [](Rng& r) { return quick_return(r, coin(r), true); });
}
TEST(RefereeDriven, WattSixBars) {
  run_family("Watt II six-bar", 106, 36, [](Rng& r) { return six_bar_or_retry(r, false); });
}
TEST(RefereeDriven, StephensonSixBars) {
  run_family("Stephenson III six-bar", 107, 36, [](Rng& r) { return six_bar_or_retry(r, true); });
}
TEST(RefereeDriven, TwoInputFiveBars) {
  run_family("five-bar, two inputs", 108, 36, [](Rng& r) { return five_bar(r); });
}

// Slider-cranks driven by their piston (a slide input on a frame guide, its effort a force along
// the guide), and quick returns, Whitworths and shapers driven by their block's slide along the
// rocker (a slide input on a link's guide: the force acts on the block and, opposite, on the
// rocker), from the drawn position to 80 % of the way to the farther dead centre. Drawn at least
// 5 % of the stroke from either dead centre: nearer, the crank turns so fast that the referee's
// Newton, continued from one sample to the next, may land on the mirror branch (the engine
// there: tests/core/planar/singular_test.cpp).
template <class Make, class StrokeOf>
void run_slide_driven(const char* family, std::uint64_t seed, Make make, StrokeOf stroke_of) {
  Rng rng(seed);
  Agreement all;
  for (int i = 0; i < 36; ++i) {
    const cp::Linkage l = make(rng);
    const cp::Model model(l);
    const Stroke st = stroke_of(l);
    if (std::min(st.drawn - st.lo, st.hi - st.drawn) < 0.05 * (st.hi - st.lo)) {
      --i;
      continue;
    }
    const double to = st.hi - st.drawn > st.drawn - st.lo ? st.hi : st.lo;
    cp::DrivenScene scene;
    scene.speeds = {(to > st.drawn ? 1 : -1) * uniform(rng, 0.5, 2.0)};
    scene.duration = 0.8 * std::abs(to - st.drawn) / std::abs(scene.speeds[0]);
    scene.samples = 120;
    const cp::Trajectory tr = cp::simulate_driven(model, scene);
    ASSERT_TRUE(tr.ok()) << tr.message;
    const Glue g = glue_of(l);
    const std::string label = std::string(family) + " #" + std::to_string(i);
    const std::vector<double> times = tr.table.column_values("t");
    const std::vector<rf::Sample> ref = rf::driven(g.mechanism, scene.speeds, 0.0, times);
    Agreement a = compare_tables(model, tr.table, reference_table(model, g, ref), label);
    core::Series reference_instants;
    reference_instants.columns = instant_columns(model);
    for (const rf::Sample& s : ref) append_reference_instant(g, s, reference_instants);
    a.merge(compare_tables(model, engine_instants(model, scene.speeds, times), reference_instants, label));
    expect_agreement(a, kTol, label);
    all.merge(a);
  }
  std::printf("%s, 36 strokes, worst relative differences:\n%s", family, all.text().c_str());
}

TEST(RefereeDriven, SliderCranksDrivenByTheirPiston) {
  run_slide_driven("slider-crank driven by its piston", 111,
                   [](Rng& r) { return driven_by_piston(slider_crank(r, coin(r))); },
                   [](const cp::Linkage& l) { return stroke_of(l); });
}
TEST(RefereeDriven, QuickReturnsDrivenByTheirBlockAlongTheRocker) {
  run_slide_driven("quick return / Whitworth / shaper driven by its block", 112,
                   [](Rng& r) { return driven_by_block(quick_return(r, coin(r), coin(r))); },
                   [](const cp::Linkage& l) { return block_stroke_of(l); });
}

// The comparison is sharp: an engine linkage that differs from the referee's mechanism by 1e-5
// (relative) in one datum, or drops a load's moment, is told apart by more than ten times the
// tolerance; the referee with a node's point mass on the other link (not the host) differs in
// that joint's force only. (Not the crank's inertia: at constant speed it carries no load.)
core::Series driven_table(const cp::Linkage& l, double speed) {
  cp::DrivenScene scene;
  scene.speeds = {speed};
  scene.samples = 60;
  const cp::Trajectory tr = cp::simulate_driven(cp::Model(l), scene);
  EXPECT_TRUE(tr.ok()) << tr.message;
  return tr.table;
}

TEST(RefereeDriven, TheComparisonSeesSmallModellingErrors) {
  Rng rng(109);
  for (int i = 0; i < 6; ++i) {
    const cp::Linkage l = six_bar_or_retry(rng, i % 2 == 1);
    const cp::Model model(l);
    const Glue g = glue_of(l);
    const core::Series engine = driven_table(l, 20.0);
    const core::Series ref =
        reference_table(model, g, rf::driven(g.mechanism, {20.0}, 0.0, engine.column_values("t")));
    const std::string name = "six-bar #" + std::to_string(i);
    EXPECT_LT(compare_tables(model, engine, ref, name).overall, kTol) << name;
    auto gap = [&](const cp::Linkage& changed) {
      return compare_tables(model, driven_table(changed, 20.0), ref, name).overall;
    };
    constexpr double d = 1e-5;
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      const double L = cp::element_length(l, static_cast<int>(k));
      cp::Linkage c = l;
      c.links[k].f += d * L;
      EXPECT_GT(gap(c), 10 * kTol) << name << ": f of link " << k << " changed by 1e-5 L";
      c = l;
      c.links[k].e += d * L;
      EXPECT_GT(gap(c), 10 * kTol) << name << ": e of link " << k << " changed by 1e-5 L";
      c = l;
      c.links[k].mass *= 1 + d;
      EXPECT_GT(gap(c), 10 * kTol) << name << ": mass of link " << k << " times 1 + 1e-5";
      if (k == 0) continue;
      c = l;
      c.links[k].inertia *= 1 + d;
      EXPECT_GT(gap(c), 10 * kTol) << name << ": inertia of link " << k << " times 1 + 1e-5";
    }
    cp::Linkage c = l;
    c.loads.link_loads[0].moment = 0;
    EXPECT_GT(gap(c), 10 * kTol) << name << ": a link load's moment dropped";
    c = l;
    c.loads.gravity *= 1 + d;
    EXPECT_GT(gap(c), 10 * kTol) << name << ": gravity times 1 + 1e-5";
  }
  // a point mass on the node's other link: the same motion, different joint forces
  Rng r2(110);
  const cp::Linkage l = slider_crank(r2, false);  // point mass at the piston B, in the rod only
  cp::Linkage with_pin_mass = l;
  with_pin_mass.point_masses.push_back({1, 0.7});  // node A: crank (first) and rod
  const cp::Model model(with_pin_mass);
  Glue g = glue_of(with_pin_mass);
  const core::Series engine = driven_table(with_pin_mass, 20.0);
  const auto times = engine.column_values("t");
  EXPECT_LT(compare_tables(model, engine, reference_table(model, g, rf::driven(g.mechanism, {20.0}, 0.0, times)), "A").overall, kTol);
  // the referee with the mass on the rod instead of the crank (the host)
  auto& crank = g.mechanism.bodies[0].point_masses;
  g.mechanism.bodies[1].point_masses.push_back(crank.back());
  crank.pop_back();
  const Agreement moved = compare_tables(model, engine, reference_table(model, g, rf::driven(g.mechanism, {20.0}, 0.0, times)), "B");
  EXPECT_LT(moved.worst.at(Family::kAngularAcceleration), kTol) << "the motion does not depend on it";
  EXPECT_LT(moved.worst.at(Family::kShakingForce), kTol) << "nor the shaking force";
  EXPECT_GT(moved.worst.at(Family::kJointForce), 1e-3) << "the joint force at A does";
}

}  // namespace
}  // namespace bd::testing::planar
