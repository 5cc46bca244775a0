// Forward sensitivities of the general engine's free scenes (core/planar/simulate.hpp,
// simulate_free_sensitivities(); metric_gradients() in core/planar/metrics.hpp), on random
// slider-cranks, quick returns, six-bars and a two-input five-bar under gravity, loads, springs
// and drive efforts (tests/support/planar_mechanisms.hpp), with respect to every mass parameter.
//
// The referee: central differences of full simulations (simulate_free, the reduced route) at the
// tighter tolerance 1e-13, the parameter moved by ±h with h = 1e-5 of its scale (the linkage
// changed by with_mass_parameters()). The motion amplifies a change of its parameters (by
// hundreds over 0.3 s, tests/core/planar/referee_free_test.cpp), and with it the differences'
// truncation: measured with h = 1e-4 the referee was off by up to 2e-4 of a derivative, with
// 3e-5 by 2e-5 (the h² of truncation), with 1e-5 by 3e-5 at most (the five-bar; 7e-6 the others),
// where the runs' own error (~1e-10 of each quantity at 1e-13) over 2h begins to count. The
// sensitivities under test run at 1e-10 (their own error test at 1e-7); tightening theirs to
// 1e-9 changed nothing measurable. So every sample's derivative of every column, relative to the
// larger of its largest magnitude over the run and the column's scale over the parameter's (the
// floor of the referee's own error where a column hardly depends on the parameter), and each
// metric's gradient, relative to the larger of its size and the metric's over the parameter's,
// are held to 1e-4: above the referee's error, far below what a wrong formula (an O(1) error)
// gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "core/planar/metrics.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

constexpr double kRelativeStep = 1e-5;
constexpr double kSampleTolerance = 1e-4;
constexpr double kMetricTolerance = 1e-4;

cp::SimulateOptions options(double tolerance) {
  cp::SimulateOptions o;
  o.tolerance = tolerance;
  o.absolute_tolerance = 1e-2 * tolerance;
  return o;
}

// the scale of mass parameter i as the referee steps it: a link's mass m, m L, m L, m L², or the
// point mass's
double scale_of(const cp::Linkage& l, int i) {
  const int links = static_cast<int>(l.links.size());
  if (i >= 4 * links) return l.point_masses[static_cast<std::size_t>(i - 4 * links)].mass;
  const cp::Link& link = l.links[static_cast<std::size_t>(i / 4)];
  const double m = link.mass > 0 ? link.mass : cp::total_mass(l);
  const double L = cp::element_length(l, i / 4);
  return i % 4 == 0 ? m : i % 4 == 3 ? m * L * L : m * L;
}

cp::Trajectory moved(const cp::Linkage& l, int i, double by, const cp::FreeScene& scene) {
  std::vector<double> pi = cp::mass_parameters(l);
  pi[static_cast<std::size_t>(i)] += by;
  return cp::simulate_free(cp::Model(cp::with_mass_parameters(l, pi.data())), scene,
                           options(1e-13));
}

struct Worst {
  double sample = 0, metric = 0;
};

// every sample's derivative and every metric's gradient of one linkage, against the referee
Worst check(const cp::Linkage& l, const cp::FreeScene& scene, const std::string& label) {
  Worst worst;
  const cp::Model model(l);
  std::vector<int> all;
  for (int i = 0; i < cp::mass_parameter_count(l); ++i) all.push_back(i);
  const cp::FreeSensitivities run =
      cp::simulate_free_sensitivities(model, scene, all, options(1e-10));
  EXPECT_TRUE(run.trajectory.ok()) << label << ": " << run.trajectory.message;
  if (!run.trajectory.ok()) return worst;
  EXPECT_EQ(run.derivative.size(), all.size());
  const core::Series& table = run.trajectory.table;
  const std::vector<cp::ColumnMetric> metrics = cp::metric_table(model);
  const Eigen::MatrixXd gradient = cp::metric_gradients(metrics, run);
  const std::vector<double> values = cp::metric_values(metrics, table);
  for (int i : all) {
    const double scale = scale_of(l, i), h = kRelativeStep * scale;
    const cp::Trajectory plus = moved(l, i, h, scene), minus = moved(l, i, -h, scene);
    EXPECT_TRUE(plus.ok() && minus.ok()) << label << ", parameter " << i;
    if (!plus.ok() || !minus.ok()) continue;
    const core::Series& d = run.derivative[static_cast<std::size_t>(i)];
    EXPECT_EQ(d.values.size(), table.values.size()) << label;
    if (d.values.size() != table.values.size()) continue;
    for (std::size_t c = 1; c < table.width(); ++c) {  // t is not differentiated
      double column_scale = 0, derivative_scale = 0;
      for (std::size_t r = 0; r < table.rows(); ++r) {
        column_scale = std::max(column_scale, std::abs(table.at(r, c)));
        derivative_scale = std::max(derivative_scale, std::abs(d.at(r, c)));
      }
      const double bound = std::max(derivative_scale, column_scale / scale);
      if (!(bound > 0)) continue;  // a column that is 0 throughout (an effort never applied)
      for (std::size_t r = 0; r < table.rows(); ++r) {
        const double referee = (plus.table.at(r, c) - minus.table.at(r, c)) / (2 * h);
        const double e = std::abs(d.at(r, c) - referee) / bound;
        worst.sample = std::max(worst.sample, e);
        EXPECT_LE(e, kSampleTolerance) << label << ", " << table.columns[c] << " at t = "
                                       << table.at(r, 0) << " by parameter " << i << ": "
                                       << d.at(r, c) << " against " << referee;
      }
    }
    const std::vector<double> up = cp::metric_values(metrics, plus.table),
                              down = cp::metric_values(metrics, minus.table);
    for (std::size_t k = 0; k < metrics.size(); ++k) {
      const double referee = (up[k] - down[k]) / (2 * h);
      const double g = gradient(static_cast<Eigen::Index>(k), i);
      const double size = std::max(std::abs(referee), values[k] / scale);
      if (!(size > 0)) continue;  // a metric that is 0 throughout
      const double e = std::abs(g - referee) / size;
      worst.metric = std::max(worst.metric, e);
      EXPECT_LE(e, kMetricTolerance) << label << ", " << metrics[k].name << " by parameter " << i
                                     << ": " << g << " against " << referee;
    }
  }
  return worst;
}

template <class Make>
void run_family(const char* family, std::uint64_t seed, int count, Make make) {
  Rng rng(seed);
  Worst all;
  for (int i = 0; i < count; ++i) {
    cp::Linkage l = make(rng);
    cp::FreeScene scene;
    for (cp::Input& in : l.inputs) {
      in.effort = random_effort(rng, 0.005 * energy_of(l));
      scene.rates.push_back((coin(rng) ? 1.0 : -1.0) * uniform(rng, 10.0, 30.0));
    }
    scene.duration = 0.3;
    scene.samples = 31;
    const Worst w = check(cp::make_linkage(l), scene, std::string(family) + " #" + std::to_string(i));
    all.sample = std::max(all.sample, w.sample);
    all.metric = std::max(all.metric, w.metric);
  }
  std::printf("%s: worst sample derivative %.2e, worst metric gradient %.2e (relative)\n", family,
              all.sample, all.metric);
}

TEST(PlanarSensitivity, SliderCranks) {
  run_family("slider-crank", 301, 3, [](Rng& r) { return slider_crank(r, coin(r)); });
}
TEST(PlanarSensitivity, QuickReturnsAndShapers) {
  run_family("quick return", 302, 2, [](Rng& r) { return quick_return(r, coin(r), coin(r)); });
}
TEST(PlanarSensitivity, SixBars) {
  run_family("six-bar", 303, 2, [](Rng& r) { return six_bar_or_retry(r, coin(r)); });
}
TEST(PlanarSensitivity, TwoInputFiveBars) {
  run_family("five-bar", 305, 1, [](Rng& r) { return five_bar(r); });
}

// The sensitivities' run is the plain run to within the integration's error.
TEST(PlanarSensitivity, TheRunIsThePlainRun) {
  Rng rng(306);
  const cp::Linkage l = slider_crank(rng, false);
  cp::FreeScene scene{{}, {20.0}, 0.3, 31};
  const cp::Model model(l);
  const cp::FreeSensitivities run = cp::simulate_free_sensitivities(model, scene, {0, 5}, options(1e-10));
  const cp::Trajectory plain = cp::simulate_free(model, scene, options(1e-10));
  ASSERT_TRUE(run.trajectory.ok() && plain.ok());
  ASSERT_EQ(run.trajectory.table.columns, plain.table.columns);
  ASSERT_EQ(run.trajectory.table.values.size(), plain.table.values.size());
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < plain.table.values.size(); ++k) {
    worst = std::max(worst, std::abs(run.trajectory.table.values[k] - plain.table.values[k]));
    scale = std::max(scale, std::abs(plain.table.values[k]));
  }
  // both at 1e-10 per step over ~10² steps, amplified by the motion (referee_free_test.cpp)
  EXPECT_LT(worst, 1e-6 * scale);
  EXPECT_EQ(run.parameters, (std::vector<int>{0, 5}));
}

TEST(PlanarSensitivity, MistakesAreNamed) {
  Rng rng(307);
  const cp::Model model(slider_crank(rng, false));
  const cp::FreeScene scene{{}, {20.0}, 0.1, 11};
  const auto field_of = [&](const std::vector<int>& parameters, cp::SimulateOptions o) {
    try {
      (void)cp::simulate_free_sensitivities(model, scene, parameters, o);
    } catch (const InputError& e) {
      return e.field() ? e.field()->field + "[" + std::to_string(e.field()->index) + "]"
                       : std::string("no field");
    }
    return std::string("accepted");
  };
  cp::SimulateOptions dae;
  dae.route = cp::Route::kDae;
  EXPECT_EQ(field_of({0}, dae), "route[-1]");
  cp::SimulateOptions erk;
  erk.integrator = core::Integrator::kErk5;
  EXPECT_EQ(field_of({0}, erk), "integrator[-1]");
  EXPECT_EQ(field_of({0, 99}, {}), "parameters[1]");
  EXPECT_EQ(field_of({3, 3}, {}), "parameters[1]");
  EXPECT_EQ(field_of({-1}, {}), "parameters[0]");
}

}  // namespace
}  // namespace bd::testing::planar
