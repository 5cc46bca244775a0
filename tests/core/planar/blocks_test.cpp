// The general planar engine's block-triangular route (core/planar/blocks.hpp: positions by the
// blocks' closed forms or Newton's method per block, rates, accelerations and multipliers by
// substitution over the blocks), which driven scenes take, against its general route (Newton's
// method and an LU of the whole system, cp::solve_position and cp::inverse_dynamics at each
// instant): every column of a driven revolution's table, on random linkages of every family the
// engine's referee tests draw. Both routes are exact; they differ by round-off amplified by the
// conditioning of the positions: ~1e-14 of each quantity's scale measured, and up to 2e-12 in
// the angular accelerations, where the general route's LU of the whole system mixes the rows of
// the fastest links into the crank's (its condition number reaches ~1e4 at the transmission
// angles the generators allow, kTransmission in tests/support/planar_mechanisms.hpp); 1e-11
// covers that, while a wrong closed form, branch or substitution term shows at 1e-3 or more.
// That the block route is the exact one there is checked on its own: a crank at constant speed
// has no angular acceleration, and the block route's is zero to round-off of omega^2. The
// independent check of both routes is the referee (referee_driven_test.cpp).
#include "core/planar/blocks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "core/fourbar/samples.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
#include "core/planar/system.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

namespace cd = bd::core::planar::detail;
using Kind = cd::Block::Kind;

constexpr double kTol = 1e-11;
// a constant-speed crank's angular acceleration, relative to its rate squared
constexpr double kCrankAlpha = 1e-14;

std::vector<Kind> kinds(const cp::Model& model) {
  std::vector<Kind> out;
  for (const cd::Block& b : model.system().blocks.blocks) out.push_back(b.kind);
  return out;
}

// The driven scene's table by the general route (tests/support/planar_glue.hpp)
core::Series general_table(const cp::Model& model, const std::vector<double>& speeds,
                           const std::vector<double>& times) {
  core::Series out;
  out.columns = cp::columns(model);
  general_route(model, speeds, times,
                [&](const cp::Instant& in) { cp::append_row(model, in, out); });
  return out;
}

// over a revolution, or `duration` [s] where it is given
Agreement routes_agree(const cp::Linkage& linkage, const std::vector<double>& speeds,
                       const std::string& label, double duration = 0) {
  const cp::Model model(linkage);
  EXPECT_TRUE(model.system().blocks.usable) << label;
  cp::DrivenScene scene;
  scene.speeds = speeds;
  scene.samples = 120;
  scene.duration = duration;
  const cp::Trajectory tr = cp::simulate_driven(model, scene);
  EXPECT_TRUE(tr.ok()) << label << ": " << tr.message;
  const core::Series general = general_table(model, speeds, tr.table.column_values("t"));
  for (std::size_t k = 0; k < linkage.inputs.size(); ++k) {
    const cp::Input& in = linkage.inputs[k];
    if (in.kind != cp::Input::Kind::kAngle) continue;
    const std::string link = linkage.links[static_cast<std::size_t>(in.link)].name;
    double largest = 0;
    for (double alpha : tr.table.column_values("alpha_" + link))
      largest = std::max(largest, std::abs(alpha));
    EXPECT_LE(largest, kCrankAlpha * speeds[k] * speeds[k]) << label << ": " << link;
  }
  Agreement a = compare_tables(model, tr.table, general, label);
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
    all.merge(routes_agree(l, speeds, std::string(family) + " #" + std::to_string(i)));
  }
  std::printf("%s, %d driven revolutions, block route against the general route:\n%s", family,
              count, all.text().c_str());
}

TEST(Blocks, TheLinkagesPeopleBuildAreCranksDyadsGuidesAndFurtherNodes) {
  Rng rng(11);
  // a four-bar: the crank's tip, then the coupler-rocker pin from two circles
  EXPECT_EQ(kinds(cp::Model(cp::linkage_of(core::samples::random_crank_rocker(rng), 0.3))),
            (std::vector<Kind>{Kind::kCrank, Kind::kDyad}));
  // a slider-crank: the crank's tip, then the piston on its guide (a circle and a line)
  const cp::Linkage sc = slider_crank(rng, true);
  EXPECT_EQ(kinds(cp::Model(sc)), (std::vector<Kind>{Kind::kCrank, Kind::kGuide}));
  EXPECT_TRUE(cp::Model(sc).system().blocks.closed);
  // driven by its piston: the piston placed, then the crank's tip from two circles
  EXPECT_EQ(kinds(cp::Model(driven_by_piston(sc))), (std::vector<Kind>{Kind::kSlide, Kind::kDyad}));
  // six-bars and five-bars: every block has a closed form or is solved on its own; a plan exists
  for (bool stephenson : {false, true}) {
    const cp::Model m(six_bar_or_retry(rng, stephenson));
    EXPECT_TRUE(m.system().blocks.usable);
    int rows = 0;
    for (const cd::Block& b : m.system().blocks.blocks) rows += b.size;
    EXPECT_EQ(rows, m.coordinates());
  }
}

TEST(Blocks, AFourBarsBlockRouteEqualsItsGeneralRoute) {
  run_family("four-bars (both branches)", 1, 20, [](Rng& rng) {
    core::FourBar fb = core::samples::random_crank_rocker(rng);
    if (coin(rng))
      fb.branch = fb.branch == core::Branch::kPlus ? core::Branch::kMinus : core::Branch::kPlus;
    return cp::linkage_of(fb, uniform(rng, -kPi, kPi));
  });
}
TEST(Blocks, SliderCranksBlockRouteEqualsItsGeneralRoute) {
  run_family("slider-cranks", 2, 10, [](Rng& rng) { return slider_crank(rng, coin(rng)); });
  // driven by the piston from the drawn position to 80 % of the way to the farther dead centre
  Rng rng(3);
  Agreement all;
  for (int i = 0; i < 10; ++i) {
    const cp::Linkage l = driven_by_piston(slider_crank(rng, coin(rng)));
    const Stroke st = stroke_of(l);
    if (std::min(st.drawn - st.lo, st.hi - st.drawn) < 0.05 * (st.hi - st.lo)) {
      --i;
      continue;
    }
    const double to = st.hi - st.drawn > st.drawn - st.lo ? st.hi : st.lo;
    const double speed = (to > st.drawn ? 1 : -1) * uniform(rng, 0.5, 2.0);
    all.merge(routes_agree(l, {speed}, "slider-crank driven by its piston #" + std::to_string(i),
                           0.8 * std::abs(to - st.drawn) / std::abs(speed)));
  }
  std::printf("slider-cranks driven by their piston, 10 strokes:\n%s", all.text().c_str());
}
TEST(Blocks, QuickReturnsBlockRouteEqualsItsGeneralRoute) {
  run_family("quick returns", 4, 10,
             [](Rng& rng) { return quick_return(rng, coin(rng), coin(rng)); });
}
TEST(Blocks, SixBarsBlockRouteEqualsItsGeneralRoute) {
  run_family("Watt six-bars", 5, 10, [](Rng& rng) { return six_bar_or_retry(rng, false); });
  run_family("Stephenson six-bars", 6, 10, [](Rng& rng) { return six_bar_or_retry(rng, true); });
}
TEST(Blocks, FiveBarsBlockRouteEqualsItsGeneralRoute) {
  run_family("two-input five-bars", 7, 10, [](Rng& rng) { return five_bar(rng); });
}

// The Jacobian's determinant from the blocks' (the free runs' limit-position test reads it) is
// the whole factorisation's: the permutations' sign and every block's determinant, on linkages
// whose plans differ in order and kind.
TEST(Blocks, TheDeterminantFromTheBlocksIsTheWholeJacobians) {
  Rng rng(31);
  std::vector<cp::Linkage> linkages;
  for (int i = 0; i < 4; ++i) {
    core::FourBar fb = core::samples::random_crank_rocker(rng);
    if (i % 2 == 1)
      fb.branch = fb.branch == core::Branch::kPlus ? core::Branch::kMinus : core::Branch::kPlus;
    linkages.push_back(cp::linkage_of(fb, uniform(rng, -kPi, kPi)));
    linkages.push_back(slider_crank(rng, coin(rng)));
    linkages.push_back(quick_return(rng, coin(rng), coin(rng)));
    linkages.push_back(six_bar_or_retry(rng, i % 2 == 1));
    linkages.push_back(five_bar(rng));
  }
  linkages.push_back(driven_by_piston(slider_crank(rng, true)));
  for (std::size_t i = 0; i < linkages.size(); ++i) {
    const cp::Model model(linkages[i]);
    cp::Workspace ws(model);
    ASSERT_TRUE(cp::assemble(model, ws, cp::drawn_inputs(model))) << i;
    const double whole = ws.lu.determinant();
    cd::prime_blocks(model, ws);
    ASSERT_EQ(cd::place_by_blocks(model, ws, ws.instant.x, cp::drawn_inputs(model)),
              cd::Placement::kPlaced)
        << i;
    EXPECT_NEAR(cd::block_determinant(model, ws) / whole, 1.0, 1e-12) << i;
  }
}

// ---------------------------------------------------------------------------------------------
// One-instant calls: cp::solve_position takes the block route where the plan is closed and the
// guess tells each block's branch (PositionRoute::kLeanest, the default), the general route
// where asked (kGeneral). From the same guesses (a driven revolution's instants by the general
// route) at inputs half a step on, both routes give the same instant, by inverse and by forward
// dynamics, to the tolerance above; a plan with a block solved by Newton's method takes the
// general route.

// each instant at inputs[i] from guesses[i], by `route`, inverse or forward dynamics
core::Series instants(const cp::Model& model, const std::vector<std::vector<Vec2>>& guesses,
                      const std::vector<std::vector<double>>& inputs, const std::vector<double>& t,
                      const std::vector<double>& speeds, bool forward, cp::PositionRoute route,
                      int& by_blocks) {
  core::Series out;
  out.columns = cp::columns(model);
  cp::Workspace ws(model);
  const std::vector<double> zero(speeds.size(), 0.0);
  by_blocks = 0;
  for (std::size_t i = 0; i < guesses.size(); ++i) {
    ws.instant.angle = cp::Workspace(model).instant.angle;  // every call on its own
    auto ok = cp::solve_position(model, ws, guesses[i], inputs[i], route);
    if (ok) {
      by_blocks += ws.by_blocks ? 1 : 0;
      ok = forward ? cp::forward_dynamics(model, ws, t[i], speeds, zero)
                   : cp::inverse_dynamics(model, ws, t[i], speeds, zero);
    }
    EXPECT_TRUE(ok) << (ok ? "" : ok.error().detail);
    if (!ok) break;
    cp::append_row(model, ws.instant, out);
  }
  return out;
}

// `share`: the least share of the calls the block route answers
template <class Make>
void one_instant_family(const char* family, std::uint64_t seed, int count, double share,
                        Make make) {
  Rng rng(seed);
  Agreement all;
  int taken = 0, calls = 0;
  for (int i = 0; i < count; ++i) {
    const cp::Linkage l = make(rng);
    const cp::Model model(l);
    std::vector<double> speeds;
    for (std::size_t k = 0; k < l.inputs.size(); ++k) speeds.push_back(random_speed(rng));
    constexpr int kSamples = 48;
    const double period = 2 * kPi / std::abs(speeds[0]);
    std::vector<double> times;
    for (int j = 0; j < kSamples; ++j) times.push_back(period * j / kSamples);
    std::vector<std::vector<Vec2>> guesses;
    std::vector<std::vector<double>> inputs;
    std::vector<double> at;
    general_route(model, speeds, times, [&](const cp::Instant& in) {
      guesses.push_back(in.x);
      at.push_back(in.t + period / (2 * kSamples));
      std::vector<double> z = in.input;
      for (std::size_t k = 0; k < z.size(); ++k) z[k] += speeds[k] * period / (2 * kSamples);
      inputs.push_back(z);
    });
    const std::string label = std::string(family) + " #" + std::to_string(i);
    for (bool forward : {false, true}) {
      int blocks = 0, general = 0;
      const core::Series lean = instants(model, guesses, inputs, at, speeds, forward,
                                         cp::PositionRoute::kLeanest, blocks);
      const core::Series whole = instants(model, guesses, inputs, at, speeds, forward,
                                          cp::PositionRoute::kGeneral, general);
      EXPECT_EQ(general, 0) << label;
      if (!model.system().blocks.closed) {
        EXPECT_EQ(blocks, 0) << label;
      }
      taken += blocks;
      calls += static_cast<int>(guesses.size());
      Agreement a = compare_tables(model, lean, whole, label + (forward ? " forward" : " inverse"));
      expect_agreement(a, kTol, label);
      all.merge(a);
    }
  }
  EXPECT_GE(taken, share * calls) << family;
  std::printf("%s, %d one-instant calls, %d on the block route, against the general route:\n%s",
              family, calls, taken, all.text().c_str());
}

TEST(Blocks, OneInstantCallsTakeTheBlockRouteWhereTheGuessTellsTheBranch) {
  // four-bars on either branch and slider-cranks: closed plans, the block route answers almost
  // every call (the rest are near a dead centre)
  for (const bool flip : {false, true}) {
    Rng rng(21);
    const core::FourBar fb = core::samples::random_crank_rocker(rng);
    core::FourBar other = fb;
    other.branch = fb.branch == core::Branch::kPlus ? core::Branch::kMinus : core::Branch::kPlus;
    const cp::Model model(cp::linkage_of(flip ? other : fb, 0.4));
    cp::Workspace lean(model), whole(model);
    ASSERT_TRUE(cp::assemble(model, whole, {0.7}));
    // from the assembled branch's positions, the block route keeps that branch
    ASSERT_TRUE(cp::solve_position(model, lean, whole.instant.x, {0.75}));
    EXPECT_TRUE(lean.by_blocks);
    ASSERT_TRUE(
        cp::solve_position(model, whole, whole.instant.x, {0.75}, cp::PositionRoute::kGeneral));
    for (std::size_t n = 0; n < lean.instant.x.size(); ++n)
      EXPECT_LE((lean.instant.x[n] - whole.instant.x[n]).norm(), 1e-14) << n;
  }
  // a slider-crank driven by its piston (a slide input, then a dyad), a few steps of its stroke
  // from the drawn position: the block route, equal to the general route
  {
    Rng rng(26);
    const cp::Model model(driven_by_piston(slider_crank(rng, true)));
    const double drawn = cp::drawn_inputs(model)[0];
    const Stroke st = stroke_of(model.linkage());
    cp::Workspace lean(model), whole(model);
    ASSERT_TRUE(cp::assemble(model, whole, {drawn}));
    for (int i = 1; i <= 5; ++i) {
      const double z =
          drawn + 0.02 * i * (st.hi - st.lo) * (st.hi - drawn > drawn - st.lo ? 1 : -1);
      const std::vector<Vec2> guess = whole.instant.x;
      ASSERT_TRUE(cp::solve_position(model, lean, guess, {z}));
      EXPECT_TRUE(lean.by_blocks) << i;
      ASSERT_TRUE(cp::solve_position(model, whole, guess, {z}, cp::PositionRoute::kGeneral));
      for (std::size_t n = 0; n < lean.instant.x.size(); ++n)
        EXPECT_LE((lean.instant.x[n] - whole.instant.x[n]).norm(), 1e-14) << i << " " << n;
    }
  }
  one_instant_family("four-bars (both branches)", 22, 10, 0.9, [](Rng& rng) {
    core::FourBar fb = core::samples::random_crank_rocker(rng);
    if (coin(rng))
      fb.branch = fb.branch == core::Branch::kPlus ? core::Branch::kMinus : core::Branch::kPlus;
    return cp::linkage_of(fb, uniform(rng, -kPi, kPi));
  });
  one_instant_family("slider-cranks", 23, 6, 0.9,
                     [](Rng& rng) { return slider_crank(rng, coin(rng)); });
  // plans with blocks solved by Newton's method take the general route
  one_instant_family("quick returns", 24, 4, 0.0,
                     [](Rng& rng) { return quick_return(rng, coin(rng), coin(rng)); });
  one_instant_family("Watt six-bars", 25, 4, 0.0,
                     [](Rng& rng) { return six_bar_or_retry(rng, false); });
}

}  // namespace
}  // namespace bd::testing::planar
