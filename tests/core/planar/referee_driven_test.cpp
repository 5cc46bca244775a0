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
  cp::Workspace ws(model);
  const std::vector<double> start = cp::drawn_inputs(model);
  EXPECT_TRUE(cp::assemble(model, ws, start));
  std::vector<double> z(start.size()), zero(start.size(), 0.0);
  for (double t : times) {
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = start[k] + speeds[k] * t;
    const std::vector<Vec2> guess = ws.instant.x;
    auto ok = cp::solve_position(model, ws, guess, z);
    if (ok) ok = cp::inverse_dynamics(model, ws, t, speeds, zero);
    EXPECT_TRUE(ok) << (ok ? "" : ok.error().detail);
    if (!ok) break;
    append_instant(model, ws.instant, out);
  }
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

double random_speed(Rng& rng) {
  return (coin(rng) ? 1.0 : -1.0) * uniform(rng, 5.0, 40.0);
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

}  // namespace
}  // namespace bd::testing::planar
