// The general planar engine against the independent referee in FREE motion: random slider-
// cranks, quick returns, shapers, Watt II and Stephenson III six-bars and two-input five-bars
// (tests/support/planar_mechanisms.hpp), started as drawn with random input rates, under
// gravity, link loads, node forces and constant or harmonic drive efforts. The referee runs at
// its default tolerance (1e-15; its samples are correct to ~1e-11 relative by its self-tests:
// these runs, rerun at 1e-17, move by 1e-13 at most).
//
// Three checks per run, every column of the engine's table against the referee's, relative to
// each quantity's scale over the run (tests/support/planar_glue.hpp, compare_tables):
//  1. The engine's forward dynamics at the referee's states (the inputs, their rates and the
//     efforts of each referee sample given to solve_position() and forward_dynamics()): 1e-10.
//     No integration is involved; both codes are exact up to round-off and the referee's ~1e-12.
//  2. simulate_free on both routes (Route::kReduced, the ODE in the inputs; Route::kDae, every
//     node coordinate with Baumgarte stabilisation and projected samples) at tolerance 1e-12
//     (absolute 1e-14): 1e-7. Not the 1e-10 one would like, for a measured reason: CVODE
//     controls the error of each step, and a 0.3 s run takes 500 to 3000 steps, so the global
//     error is ~steps x tolerance, amplified by the motion's own sensitivity (the referee rerun
//     with the first input's initial rate changed by 1e-10 relative moves by up to some hundreds
//     of times that, e.g. 500 for a Stephenson six-bar). Measured worst: 5e-8.
//  3. The same at tolerance 1e-14 (absolute 1e-16): the differences must shrink at least
//     fivefold (or already be below 1e-10), i.e. they are the engine's integration error and
//     converge to the referee; a modelling error (a wrong inertia term, a missing load, a sign)
//     does not shrink with the tolerance. And below 1e-9 (measured worst: 7.5e-10).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>

#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

constexpr double kInstantaneous = 1e-10;
constexpr double kAskedTolerance = 1e-12, kAskedAgreement = 1e-7;
constexpr double kTightTolerance = 1e-14, kTightAgreement = 1e-9;

cp::SimulateOptions options(cp::Route route, double tolerance) {
  cp::SimulateOptions o;
  o.route = route;
  o.tolerance = tolerance;
  o.absolute_tolerance = tolerance * 1e-2;
  return o;
}

// The engine's table and Instants evaluated at the referee's states.
struct AtStates {
  core::Series table, instants;
};
AtStates engine_at_referee_states(const cp::Model& model, const std::vector<rf::Sample>& ref) {
  const cp::Linkage& l = model.linkage();
  AtStates out;
  out.table.columns = cp::columns(model);
  out.instants.columns = instant_columns(model);
  cp::Workspace ws(model);
  std::vector<Vec2> guess = ws.instant.x;
  for (const rf::Sample& s : ref) {
    std::vector<double> z;
    for (std::size_t k = 0; k < l.inputs.size(); ++k)
      z.push_back(drawn_input(l, static_cast<int>(k)) + s.input_values[k]);
    auto ok = cp::solve_position(model, ws, guess, z);
    if (ok) ok = cp::forward_dynamics(model, ws, s.t, s.input_rates, cp::efforts_at(model, s.t));
    EXPECT_TRUE(ok) << (ok ? "" : ok.error().detail);
    if (!ok) break;
    guess = ws.instant.x;
    cp::append_row(model, ws.instant, out.table);
    append_instant(model, ws.instant, out.instants);
  }
  return out;
}

// the worst relative differences: [reduced, dae] x [asked, tight], and at the referee's states
struct FreeRun {
  Agreement a[2][2], instantaneous;
  double speedup = 0;  // the largest |input rate| over the run / its start
  long steps = 0;      // the most steps an engine run took at the asked tolerance
};

FreeRun free_agreement(const cp::Linkage& linkage, const std::vector<double>& rates, double duration,
                   int samples, const std::string& label) {
  FreeRun out;
  const cp::Model model(linkage);
  const Glue g = glue_of(linkage);
  std::vector<double> times;
  for (int i = 0; i < samples; ++i)
    times.push_back(i == samples - 1 ? duration : duration * i / (samples - 1));
  std::vector<rf::Sample> ref;
  try {
    ref = rf::free_run(g.mechanism, rates, duration, times);
  } catch (const std::exception& e) {
    ADD_FAILURE() << label << ": the referee failed: " << e.what();
    return out;
  }
  const core::Series reference = reference_table(model, g, ref);
  for (const rf::Sample& s : ref)
    for (std::size_t k = 0; k < rates.size(); ++k)
      out.speedup = std::max(out.speedup, std::abs(s.input_rates[k] / rates[k]));

  // 1. forward dynamics at the referee's states
  {
    const AtStates e = engine_at_referee_states(model, ref);
    core::Series reference_instants;
    reference_instants.columns = instant_columns(model);
    for (const rf::Sample& s : ref) append_reference_instant(g, s, reference_instants);
    out.instantaneous = compare_tables(model, e.table, reference, label + " (at the referee's states)");
    out.instantaneous.merge(compare_tables(model, e.instants, reference_instants,
                                           label + " (at the referee's states)"));
    expect_agreement(out.instantaneous, kInstantaneous, label + " (at the referee's states)");
  }
  // 2. and 3. integrated on both routes at both tolerances
  for (int r = 0; r < 2; ++r) {
    const cp::Route route = r == 0 ? cp::Route::kReduced : cp::Route::kDae;
    for (int k = 0; k < 2; ++k) {
      const double tolerance = k == 0 ? kAskedTolerance : kTightTolerance;
      char what[300];
      std::snprintf(what, sizeof what, "%s (%s, tolerance %.0e)", label.c_str(),
                    cp::to_string(route), tolerance);
      const cp::Trajectory tr = cp::simulate_free(
          model, cp::FreeScene{{}, rates, duration, samples}, options(route, tolerance));
      EXPECT_TRUE(tr.ok()) << what << ": " << tr.message;
      EXPECT_TRUE(all_finite(tr.table)) << what;
      EXPECT_EQ(tr.table.column_values("t"), times) << what;  // the scene's sample times
      if (k == 0) out.steps = std::max(out.steps, tr.steps);
      out.a[r][k] = compare_tables(model, tr.table, reference, what);
      expect_agreement(out.a[r][k], k == 0 ? kAskedAgreement : kTightAgreement, what);
    }
    // the differences are integration errors: they shrink with the tolerance
    EXPECT_LE(out.a[r][1].overall, std::max(1e-10, out.a[r][0].overall / 5))
        << label << " (" << cp::to_string(route) << "): at tolerance " << kAskedTolerance
        << " the worst difference is " << out.a[r][0].overall << " (" << out.a[r][0].overall_where
        << "), at " << kTightTolerance << " still " << out.a[r][1].overall << " ("
        << out.a[r][1].overall_where << ")";
  }
  return out;
}

template <class Make>
void run_family(const char* family, std::uint64_t seed, int count, double duration, Make make) {
  Rng rng(seed);
  FreeRun all;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < count; ++i) {
    cp::Linkage l = make(rng);
    std::vector<double> rates;
    for (cp::Input& in : l.inputs) {
      in.effort = random_effort(rng, 0.005 * energy_of(l));  // as random_loads()' moments
      rates.push_back((coin(rng) ? 1.0 : -1.0) * uniform(rng, 10.0, 30.0));
    }
    const FreeRun r = free_agreement(l, rates, duration, 31, std::string(family) + " #" + std::to_string(i));
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) all.a[a][b].merge(r.a[a][b]);
    all.instantaneous.merge(r.instantaneous);
    all.speedup = std::max(all.speedup, r.speedup);
    all.steps = std::max(all.steps, r.steps);
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %d free runs of %g s (%.0f ms; input rates up to %.1f times their start; up to "
              "%ld steps at %.0e)\n at the referee's states: worst %.2e\n%s",
              family, count, duration, ms, all.speedup, all.steps, kAskedTolerance,
              all.instantaneous.overall, all.instantaneous.text().c_str());
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      std::printf(" %s route, tolerance %.0e: worst %.2e\n%s", a == 0 ? "reduced" : "dae",
                  b == 0 ? kAskedTolerance : kTightTolerance, all.a[a][b].overall,
                  b == 0 ? all.a[a][b].text().c_str() : "");
}

TEST(RefereeFree, SliderCranks) {
  run_family("slider-crank (inline and offset)", 201, 12, 0.3,
             [](Rng& r) { return slider_crank(r, coin(r)); });
}
TEST(RefereeFree, QuickReturnsWhitworthsAndShapers) {
  run_family("quick return / Whitworth / shaper", 202, 12, 0.3,
             [](Rng& r) { return quick_return(r, coin(r), coin(r)); });
}
TEST(RefereeFree, WattSixBars) {
  run_family("Watt II six-bar", 203, 12, 0.3, [](Rng& r) { return six_bar_or_retry(r, false); });
}
TEST(RefereeFree, StephensonSixBars) {
  run_family("Stephenson III six-bar", 204, 12, 0.3,
             [](Rng& r) { return six_bar_or_retry(r, true); });
}
TEST(RefereeFree, TwoInputFiveBarsWithTwoEfforts) {
  run_family("five-bar, two inputs", 205, 12, 0.3, [](Rng& r) { return five_bar(r); });
}

// Slide inputs with efforts: slider-cranks pushed by a force on their piston (along a frame
// guide; the drive's reaction is on the frame) and quick returns by a force on their block
// (along the rocker; the reaction is on the rocker), started away from the dead centres towards
// the farther one and run for half the time the starting rate would take to reach it.
TEST(RefereeFree, SlideInputsWithForces) {
  Rng rng(206);
  FreeRun all;
  for (int i = 0; i < 12; ++i) {
    const bool piston = i % 2 == 0;
    cp::Linkage l = piston ? driven_by_piston(slider_crank(rng, coin(rng)))
                           : driven_by_block(quick_return(rng, coin(rng), coin(rng)));
    const Stroke st = piston ? stroke_of(l) : block_stroke_of(l);
    if (std::min(st.drawn - st.lo, st.hi - st.drawn) < 0.2 * (st.hi - st.lo)) {
      --i;
      continue;
    }
    const double to = st.hi - st.drawn > st.drawn - st.lo ? st.hi : st.lo;
    const double rate = (to > st.drawn ? 1 : -1) * uniform(rng, 0.5, 2.0);
    const double force = 0.005 * energy_of(l) / size_of(l);  // as the moments, per metre
    l.inputs[0].effort = random_effort(rng, force);
    const double duration = 0.5 * std::abs(to - st.drawn) / std::abs(rate);
    const FreeRun r = free_agreement(l, {rate}, duration, 31,
                                 std::string(piston ? "slider-crank pushed by its piston #"
                                                    : "quick return pushed along its rocker #") +
                                     std::to_string(i));
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) all.a[a][b].merge(r.a[a][b]);
    all.instantaneous.merge(r.instantaneous);
  }
  std::printf("slide inputs with forces: at the referee's states %.2e; reduced %.2e / %.2e, dae "
              "%.2e / %.2e at tolerance %.0e / %.0e\n",
              all.instantaneous.overall, all.a[0][0].overall, all.a[0][1].overall,
              all.a[1][0].overall, all.a[1][1].overall, kAskedTolerance, kTightTolerance);
}

}  // namespace
}  // namespace bd::testing::planar
