// Peaks resolved between samples (core/peaks.hpp): a coarse driven run's peak metrics against a
// brute force of 100 000 samples per revolution, each evaluated on its own, whose largest sample
// is refined by the parabola through it and its neighbours (error ~ (k h)³ for order k, h =
// 2π/1e5: below 1e-12). The resolved peak must agree to 1e-9 of its value, wherever the coarse
// samples fall, and the place it reports must be the brute force's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/peaks.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/metrics.hpp"
#include "core/planar/simulate.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/planar_mechanisms.hpp"
#include "tests/support/studies.hpp"

namespace bd {
namespace {

namespace cp = core::planar;
using testing::planar::Rng;
using testing::planar::uniform;

constexpr int kBrute = 100000;

// the peak of x sampled at a uniform periodic grid of step h, refined by the parabola through
// the largest sample and its neighbours: value and abscissa
struct Brute {
  double value{}, at{};
};
Brute parabola_peak(const std::vector<double>& x, double h) {
  std::size_t i = 0;
  for (std::size_t j = 1; j < x.size(); ++j)
    if (x[j] > x[i]) i = j;
  const double a = x[(i + x.size() - 1) % x.size()], b = x[i], c = x[(i + 1) % x.size()];
  const double den = a - 2 * b + c;
  const double d = den < 0 ? 0.5 * (a - c) / den : 0.0;  // offset in steps
  return {b - 0.25 * (a - c) * d, (static_cast<double>(i) + d) * h};
}

TEST(ResolvedPeaks, FourBarDrivenPeaksMatchA100000SampleBruteForce) {
  for (int variant = 0; variant < 3; ++variant) {
    core::FourBar fb = core::samples::paper_fourbar();
    if (variant == 1) fb.loads.gravity = Vec2(0, -9.81);
    if (variant == 2) {
      fb.branch = core::Branch::kMinus;
      fb.counter_rotations.crank = {0.7, Vec2(0, -1)};
      fb.counter_rotations.rocker = {1.3, Vec2(fb.frame_length, -1)};
    }
    fb = core::make_fourbar(fb);
    core::DrivenScene scene;
    scene.theta1 = 0.4;
    scene.omega1 = variant == 2 ? -9.0 : 2 * std::numbers::pi;
    scene.samples = 37;  // coarse: about 10° apart
    const core::Trajectory coarse = core::simulate_driven(fb, scene);
    ASSERT_TRUE(coarse.ok()) << coarse.message;
    core::PeakList peaks;
    const core::Metrics resolved =
        core::metrics(fb, scene, coarse, core::Formulation::kMassMatrix, &peaks);
    const core::Metrics sampled = core::metrics(coarse);

    // the brute force: every sample evaluated by itself, by another formulation
    const double period = 2 * std::numbers::pi / std::abs(scene.omega1);
    std::vector<core::DynamicsSample> fine(kBrute);
    for (int j = 0; j < kBrute; ++j) {
      const double t = period * j / kBrute;
      const auto s = core::inverse_dynamics(fb, scene.theta1 + scene.omega1 * t, scene.omega1, 0.0,
                                            core::Formulation::kOpenedLoop);
      ASSERT_TRUE(s);
      fine[static_cast<std::size_t>(j)] = *s;
    }
    bool coarse_was_short = false;
    for (std::size_t k = 0; k < core::kMetricCount; ++k) {
      const core::MetricInfo& info = core::kMetricTable[k];
      if (info.statistic != core::Statistic::kMax) continue;
      std::vector<double> x(fine.size());
      for (std::size_t j = 0; j < fine.size(); ++j) x[j] = core::magnitude(fine[j], info.quantity);
      const Brute b = parabola_peak(x, period / kBrute);
      const double value = resolved.*info.field;
      EXPECT_NEAR(value, b.value, 1e-9 * b.value) << info.name << " variant " << variant;
      EXPECT_GE(value, sampled.*info.field) << info.name;
      // where: the same instant, to the brute force's step (a flat peak only to its sqrt)
      const double dt = std::remainder(peaks.table[k].t - b.at, period);
      EXPECT_LT(std::abs(dt), 1e-3 * period) << info.name << " variant " << variant;
      if (value - sampled.*info.field > 1e-6 * value) coarse_was_short = true;
    }
    // the total shaking force and moment, the joint forces and the counter-rotation shafts'
    // bearings (variant 2: the rocker's disc is accelerated by its gear, so its shaft is loaded)
    for (const core::OutputMetricInfo& info : core::kOutputMetrics) {
      if (info.statistic != core::Statistic::kMax) continue;
      std::vector<double> x(fine.size());
      for (std::size_t j = 0; j < fine.size(); ++j) x[j] = core::magnitude(fine[j], info.quantity);
      const Brute b = parabola_peak(x, period / kBrute);
      EXPECT_NEAR(resolved.*info.field, b.value, 1e-9 * b.value)
          << info.name << " variant " << variant;
      if (variant == 2 && info.quantity == core::OutputQuantity::kCounterRocker) {
        EXPECT_GT(b.value, 1.0) << info.name;
      }
    }
    // 37 samples fall short of the peaks: the refinement is what closes the gap
    EXPECT_TRUE(coarse_was_short) << "variant " << variant;
  }
}

// a planar metric's magnitude in every row of a table
std::vector<double> magnitudes(const core::Series& table, const cp::ColumnMetric& metric) {
  std::vector<int> c;
  for (const std::string& name : metric.columns) c.push_back(table.column(name));
  std::vector<double> x(table.rows());
  for (std::size_t j = 0; j < x.size(); ++j) {
    const double a = table.at(j, static_cast<std::size_t>(c[0]));
    const double b = c.size() > 1 ? table.at(j, static_cast<std::size_t>(c[1])) : 0.0;
    x[j] = std::hypot(a, b);
  }
  return x;
}

TEST(ResolvedPeaks, PlanarDrivenPeaksMatchA100000SampleBruteForce) {
  Rng rng(160);
  for (int trial = 0; trial < 3; ++trial) {
    cp::Linkage l = testing::planar::slider_crank(rng, trial == 0);
    l.loads.gravity = Vec2(0, -9.81);
    l = cp::make_linkage(l);
    const cp::Model model(l);
    cp::DrivenScene scene;
    scene.speeds = {uniform(rng, 5, 30) * (trial == 2 ? -1 : 1)};
    scene.samples = 29;
    const cp::Trajectory coarse = cp::simulate_driven(model, scene);
    ASSERT_TRUE(coarse.ok()) << coarse.message;
    const std::vector<cp::ColumnMetric> table = cp::metric_table(model);
    std::vector<core::Peak> peaks;
    const std::vector<double> resolved = cp::metric_values(model, scene, table, coarse, &peaks);
    cp::DrivenScene fine_scene = scene;
    fine_scene.samples = kBrute;
    const cp::Trajectory fine = cp::simulate_driven(model, fine_scene);
    ASSERT_TRUE(fine.ok()) << fine.message;
    const double period = 2 * std::numbers::pi / std::abs(scene.speeds[0]);
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (table[k].statistic != core::Statistic::kMax) continue;
      const std::vector<double> x = magnitudes(fine.table, table[k]);
      const Brute b = parabola_peak(x, period / kBrute);
      // a peak of round-off (a force that vanishes) has no place to be found
      const double scale = b.value + 1e-9 * resolved[0];
      EXPECT_NEAR(resolved[k], b.value, 1e-9 * scale) << table[k].name << " trial " << trial;
      if (b.value > 1e-6 * resolved[0]) {
        const double dt = std::remainder(peaks[k].t - b.at, period);
        EXPECT_LT(std::abs(dt), 1e-3 * period) << table[k].name << " trial " << trial;
      }
    }
  }
}

// the peak of x sampled at a uniform grid of step h over an open interval, refined by the
// parabola through the largest sample and its neighbours (an end is its own peak)
Brute open_parabola_peak(const std::vector<double>& x, double h) {
  std::size_t i = 0;
  for (std::size_t j = 1; j < x.size(); ++j)
    if (x[j] > x[i]) i = j;
  if (i == 0 || i + 1 == x.size()) return {x[i], static_cast<double>(i) * h};
  const double a = x[i - 1], b = x[i], c = x[i + 1];
  const double den = a - 2 * b + c;
  const double d = den < 0 ? 0.5 * (a - c) / den : 0.0;
  return {b - 0.25 * (a - c) * d, (static_cast<double>(i) + d) * h};
}

// the fine run's peak near the instant t: the parabola through the fine sample nearest t and its
// two neighbours (its vertex, and the vertex's time); none at the run's ends
std::optional<Brute> peak_near(const std::vector<double>& x, double h, double t) {
  const auto j = static_cast<std::size_t>(std::lround(t / h));
  if (j == 0 || j + 1 >= x.size()) return std::nullopt;
  const Brute b = open_parabola_peak({x[j - 1], x[j], x[j + 1]}, h);
  return Brute{b.value, b.at + static_cast<double>(j - 1) * h};
}

// A four-bar study on the general engine (method truss) whose coupler and rocker come within
// |sin| = 4.5e-4 of a straight line at theta1 = pi, inside the closed forms' singular test
// (1e-3), where the engine still answers. Its peaks were the samples' there (tau_max 66 207 N m
// at 360 and 3 600 samples against 77 759): the closed form the between-sample search used
// declined near the dead centre. They are now resolved by the engine that computed the run, and
// equal a brute force of the engine's own samples, 400 001 of them over theta1 = pi -+ 2e-4
// (h = 1e-9 rad; the sharpest peak, tau's, is ~1e-5 rad wide: the parabola's error ~(h/w)^3
// ~ 1e-12; at h = 1e-8 it was 2.6e-9). Tolerance 2e-8: the window's model is drawn at its
// start, its link lengths equal the study's to round-off (~2e-16 m), and this close to the
// dead centre the loads change by the relative change of the gap l2 + l3 - |A1A3| (1e-7 m):
// a condition number ~4e7, ~1e-8 of the values.
TEST(ResolvedPeaks, AFourBarOnTrussElementsResolvesItsPeaksNearADeadCentre) {
  const std::string text =
      "name: near-dead-centre\n"
      "linkage:\n"
      "  type: fourbar\n"
      "  frame: 3.0\n"
      "  branch: 1\n"
      "  crank:   {length: 1.0, mass: 1.0, e: 0.5, f: 0.0, inertia: 0.1}\n"
      "  coupler: {length: 2.00000005, mass: 2.0, e: 1.0, f: 0.0, inertia: 0.7}\n"
      "  rocker:  {length: 2.00000005, mass: 2.0, e: 1.0, f: 0.0, inertia: 0.7}\n"
      "scene: {type: driven, theta1: 0.0, omega1: 6.283185307179586, samples: 360}\n"
      "method: truss\n";
  const studies::Study study = studies::parse_study(text, "dc.yaml");
  const studies::RunResult r = studies::compute_study(study);
  ASSERT_TRUE(r.ok()) << r.status().message;
  // the brute force: the engine's driven run over the window, every sample on its own, drawn at
  // the window's start on the study's branch (assembled there from a drawing at 0 rad, 2e-4 rad
  // from the dead centre, the engine took the mirror branch: tau's two peaks swapped)
  const double omega = 6.283185307179586, half = 2e-4;
  const cp::Model model(cp::linkage_of(study.fourbar(), std::numbers::pi - half));
  cp::DrivenScene window;
  window.start = {std::numbers::pi - half};
  window.speeds = {omega};
  window.duration = 2 * half / omega;
  window.samples = 400001;
  const cp::Trajectory fine = cp::simulate_driven(model, window);
  ASSERT_TRUE(fine.ok()) << fine.message;
  const double h = window.duration / (window.samples - 1);
  const double t0 = (std::numbers::pi - half) / omega;
  const core::Series& table = fine.table;
  // |(x, y)| per sample, |x| where there is no y
  const auto magnitude_of = [&](const char* x, const char* y) {
    std::vector<double> m(table.rows());
    const auto cx = static_cast<std::size_t>(table.column(x));
    for (std::size_t i = 0; i < m.size(); ++i) {
      const double a = table.at(i, cx);
      m[i] =
          y ? std::hypot(a, table.at(i, static_cast<std::size_t>(table.column(y)))) : std::abs(a);
    }
    return m;
  };
  struct Case {
    const char* metric;
    const char* x;
    const char* y;
  };
  for (const Case c :
       {Case{"tau_max", "tau", nullptr}, Case{"Fsh_max", "Fshx_inertial", "Fshy_inertial"},
        Case{"RA0_max", "RA0x", "RA0y"}, Case{"FA2_max", "FA2x", "FA2y"}}) {
    const auto it = std::find_if(r.metric_list.begin(), r.metric_list.end(),
                                 [&](const studies::MetricValue& m) { return m.name == c.metric; });
    ASSERT_NE(it, r.metric_list.end()) << c.metric;
    const std::vector<double> x = magnitude_of(c.x, c.y);
    const Brute b = open_parabola_peak(x, h);
    EXPECT_NEAR(it->value, b.value, 2e-8 * b.value) << c.metric;
    // where it lies: the brute force has the peak there too (tau has two equal ones, at
    // pi -+ 1.47e-4, of the symmetric linkage)
    ASSERT_TRUE(it->t) << c.metric;
    const std::optional<Brute> there = peak_near(x, h, *it->t - t0);
    ASSERT_TRUE(there) << c.metric;
    EXPECT_NEAR(there->value, b.value, 2e-8 * b.value) << c.metric;
  }
}

// A free run's peaks, located between 41 samples by integrating from the sample before each
// instant (core::free_sample_from), against a separate run of 100 001 samples refined by the
// parabola (error ~ (λ h)³ with h = 2e-5 s, below 1e-12): both runs at a tolerance of 1e-12, so
// that their integration errors (~1e-11 of the values) stay below the 1e-9 asked. The paper
// four-bar on the reduced equation (mass matrix) and a triple rocker on the opened loop, which
// passes its limit positions inside the 2 s (the branch flips between samples).
TEST(ResolvedPeaks, FourBarFreePeaksMatchA100000SampleRun) {
  for (int variant = 0; variant < 2; ++variant) {
    const core::FourBar fb =
        variant == 0 ? core::samples::paper_fourbar() : core::samples::triple_rocker();
    core::SimulateOptions options;
    options.formulation =
        variant == 0 ? core::Formulation::kMassMatrix : core::Formulation::kOpenedLoop;
    options.tolerance = 1e-12;
    options.absolute_tolerance = 1e-14;
    core::FreeScene scene;
    scene.theta1 = variant == 0 ? 0.3 : 0.0;
    scene.omega1 = variant == 0 ? 2.0 : 1.0;
    scene.duration = variant == 0 ? 2.0 : 8.0;
    scene.samples = 41;
    const core::Trajectory coarse = core::simulate_free(fb, scene, options);
    ASSERT_TRUE(coarse.ok()) << coarse.message;
    core::PeakList peaks;
    const core::Metrics resolved = core::metrics(fb, coarse, options, &peaks);
    const core::Metrics sampled = core::metrics(coarse);
    core::FreeScene fine_scene = scene;
    fine_scene.samples = kBrute + 1;
    const core::Trajectory fine = core::simulate_free(fb, fine_scene, options);
    ASSERT_TRUE(fine.ok()) << fine.message;
    if (variant == 1) {
      // the crank reverses inside the run: it passes a limit position
      double least = fine.samples[0].state.omega1, most = least;
      for (const core::DynamicsSample& d : fine.samples) {
        least = std::min(least, d.state.omega1);
        most = std::max(most, d.state.omega1);
      }
      ASSERT_LT(least * most, 0.0);
    }
    const double h = scene.duration / kBrute;
    bool coarse_was_short = false;
    for (std::size_t k = 0; k < core::kMetricCount; ++k) {
      const core::MetricInfo& info = core::kMetricTable[k];
      if (info.statistic != core::Statistic::kMax || info.quantity == core::Quantity::kDriveTorque) {
        continue;  // no drive in free motion
      }
      std::vector<double> x(fine.samples.size());
      for (std::size_t j = 0; j < x.size(); ++j) {
        x[j] = core::magnitude(fine.samples[j], info.quantity);
      }
      const Brute b = open_parabola_peak(x, h);
      const double value = resolved.*info.field;
      EXPECT_NEAR(value, b.value, 1e-9 * b.value) << info.name << " variant " << variant;
      EXPECT_GE(value, sampled.*info.field) << info.name;
      // where: an instant where the fine run reaches the peak (a swing that repeats has several):
      // the fine run's parabola there has its vertex within a fine step of it, at the peak
      const std::optional<Brute> near = peak_near(x, h, peaks.table[k].t);
      ASSERT_TRUE(near) << info.name;
      EXPECT_NEAR(near->value, b.value, 1e-9 * b.value) << info.name << " variant " << variant;
      EXPECT_NEAR(near->at, peaks.table[k].t, h) << info.name << " variant " << variant;
      if (value - sampled.*info.field > 1e-6 * value) coarse_was_short = true;
    }
    // the total shaking force and moment and the joint forces
    for (std::size_t k = 0; k < std::size(core::kOutputMetrics); ++k) {
      const core::OutputMetricInfo& info = core::kOutputMetrics[k];
      if (info.statistic != core::Statistic::kMax) continue;
      std::vector<double> x(fine.samples.size());
      for (std::size_t j = 0; j < x.size(); ++j) x[j] = core::magnitude(fine.samples[j], info.quantity);
      const Brute b = open_parabola_peak(x, h);
      EXPECT_NEAR(resolved.*info.field, b.value, 1e-9 * b.value)
          << info.name << " variant " << variant;
    }
    // 41 samples fall short of the peaks: the refinement is what closes the gap
    EXPECT_TRUE(coarse_was_short) << "variant " << variant;
  }
}

// A planar linkage's free run's peaks, located between 41 samples by continuing the run from the
// latest known instant before each instant (core::planar::free_state_from()), against a separate
// run of 100 001 samples refined by the parabola, as the four-bar's above (both at a tolerance
// of 1e-12). Three runs: the paper four-bar drawn as a planar linkage swinging under gravity
// (reduced route); the same driven by a harmonic motor torque, which depends on time, so that
// each restart must integrate in the run's own time (from t0, not from 0); and the triple rocker
// on the dae route, which passes its limit positions inside the 8 s (its crank reverses).
TEST(ResolvedPeaks, PlanarFreePeaksMatchA100000SampleRun) {
  for (int variant = 0; variant < 3; ++variant) {
    const core::FourBar fb =
        variant == 2 ? core::samples::triple_rocker() : core::samples::paper_fourbar();
    cp::Linkage l = cp::linkage_of(fb, variant == 2 ? 0.0 : 0.3);
    if (variant < 2) l.loads.gravity = Vec2(0, -9.81);
    if (variant == 1) l.inputs[0].effort = testing::planar::harmonic(0.0, 40.0, 1.3, 0.4);
    l = cp::make_linkage(l);
    const cp::Model model(l);
    cp::SimulateOptions options;
    options.route = variant == 2 ? cp::Route::kDae : cp::Route::kReduced;
    options.tolerance = 1e-12;
    options.absolute_tolerance = 1e-14;
    cp::FreeScene scene;
    scene.rates = {variant == 2 ? 1.0 : 2.0};
    scene.duration = variant == 2 ? 8.0 : 2.0;
    scene.samples = 41;
    const cp::Trajectory coarse = cp::simulate_free(model, scene, options);
    ASSERT_TRUE(coarse.ok()) << coarse.message;
    const std::vector<cp::ColumnMetric> table = cp::metric_table(model);
    std::vector<core::Peak> peaks;
    const std::vector<double> resolved = cp::metric_values(model, options, table, coarse, &peaks);
    const std::vector<double> sampled = cp::metric_values(table, coarse.table);
    cp::FreeScene fine_scene = scene;
    fine_scene.samples = kBrute + 1;
    const cp::Trajectory fine = cp::simulate_free(model, fine_scene, options);
    ASSERT_TRUE(fine.ok()) << fine.message;
    if (variant == 2) {
      // the crank reverses inside the run: it passes a limit position
      const std::vector<double> omega = fine.table.column_values("omega_crank");
      ASSERT_LT(*std::min_element(omega.begin(), omega.end()) *
                    *std::max_element(omega.begin(), omega.end()),
                0.0);
    }
    const double h = scene.duration / kBrute;
    bool coarse_was_short = false;
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (table[k].statistic != core::Statistic::kMax) continue;
      const std::vector<double> x = magnitudes(fine.table, table[k]);
      if (x[0] == 0.0 && *std::max_element(x.begin(), x.end()) == 0.0) continue;  // no drive
      const Brute b = open_parabola_peak(x, h);
      EXPECT_NEAR(resolved[k], b.value, 1e-9 * b.value) << table[k].name << " variant " << variant;
      EXPECT_GE(resolved[k], sampled[k]) << table[k].name << " variant " << variant;
      // where: an instant where the fine run reaches the peak (a swing that repeats has several):
      // the fine run's parabola there has its vertex within a fine step of it, at the peak (a
      // sharp peak's nearest fine sample may lie some 1e-7 below it)
      const std::optional<Brute> near = peak_near(x, h, peaks[k].t);
      ASSERT_TRUE(near) << table[k].name;
      EXPECT_NEAR(near->value, b.value, 1e-9 * b.value) << table[k].name << " variant " << variant;
      EXPECT_NEAR(near->at, peaks[k].t, h) << table[k].name << " variant " << variant;
      if (resolved[k] - sampled[k] > 1e-6 * resolved[k]) coarse_was_short = true;
    }
    // 41 samples fall short of the peaks: the refinement is what closes the gap
    EXPECT_TRUE(coarse_was_short) << "variant " << variant;
  }
}

// a study: summary.json's peaks come with where they are, and the sample count no longer
// decides them
TEST(ResolvedPeaks, StudyPeaksDoNotDependOnTheSampleCount) {
  auto run = [](int samples) {
    const std::string text =
        "name: p\nlinkage:\n  type: fourbar\n  frame: 3.2\n  branch: 1\n"
        "  crank:   {length: 1.0, mass: 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"
        "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
        "scene:\n  type: driven\n  theta1: 0\n  omega1: 6.283185307179586\n  samples: " +
        std::to_string(samples) + "\n";
    return studies::compute_study(studies::parse_study(text, "p.yaml")).metric_list;
  };
  const studies::MetricList a = run(24), b = run(720);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k].name.ends_with("_max")) {
      EXPECT_NEAR(a[k].value, b[k].value, 1e-9 * b[k].value) << a[k].name;
      ASSERT_TRUE(a[k].t && b[k].t) << a[k].name;
      EXPECT_NEAR(*a[k].t, *b[k].t, 1e-4) << a[k].name;
    } else {
      EXPECT_FALSE(a[k].t) << a[k].name;
    }
  }
}

// Driven at very few samples per turn (5 or 6: the designer's check found the engine's drive
// torque peak at 36.7 N m where it is 49.6 N m, the largest value lying between two samples
// neither of which was a local maximum), the peaks still equal those of 360 samples per turn,
// which the brute-force tests above hold to the exact maxima. So do 1 and 2 samples per turn
// (a designer's check found 1 sample's peaks left at that sample: Fsh_max 224 N for 275 N).
// A spring anchored to the frame at a ground node no link holds (stephenson-sixbar-free.yaml's S):
// that node has no bearing, so no R<node> metric (it was 0, and drawn as a flat bearing load);
// the spring's pull on the frame, R<node>_<spring>, has its RMS and peak instead, the RMS that of
// its columns.
TEST(ResolvedPeaks, ASpringsAnchorHasTheSpringsPullNotABearing) {
  const studies::Study study =
      studies::load_study(BD_SOURCE_DIR "/studies/examples/stephenson-sixbar-free.yaml");
  const studies::RunResult r = studies::compute_study(study);
  ASSERT_TRUE(r.ok()) << r.planar.message;
  auto find = [&](const std::string& name) {
    return std::find_if(r.metric_list.begin(), r.metric_list.end(),
                        [&](const studies::MetricValue& m) { return m.name == name; });
  };
  EXPECT_EQ(find("RS_rms"), r.metric_list.end());
  EXPECT_EQ(find("RS_max"), r.metric_list.end());
  ASSERT_NE(find("RS_return_rms"), r.metric_list.end());
  ASSERT_NE(find("RS_return_max"), r.metric_list.end());
  const auto x = r.planar.table.column_values("RS_returnx"),
             y = r.planar.table.column_values("RS_returny");
  double sum = 0, largest = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sum += x[i] * x[i] + y[i] * y[i];
    largest = std::max(largest, std::hypot(x[i], y[i]));
  }
  const double rms = std::sqrt(sum / static_cast<double>(x.size()));
  EXPECT_GT(rms, 1.0);  // the spring pulls tens of newtons
  EXPECT_NEAR(find("RS_return_rms")->value, rms, 1e-12 * rms);
  EXPECT_GE(find("RS_return_max")->value, largest * (1 - 1e-15));
  EXPECT_LT(find("RS_return_max")->value, largest * 1.01);
  // the other ground nodes keep theirs
  EXPECT_NE(find("RO2_max"), r.metric_list.end());
}

TEST(ResolvedPeaks, PlanarDrivenPeaksAtFiveSamplesPerTurn) {
  auto run = [](int samples) {
    const std::string text = bd::testing::edited_example(
        "engine-slider-crank.yaml", {{"  samples: 360", "  samples: " + std::to_string(samples)}});
    return studies::compute_study(studies::parse_study(text, "e.yaml")).metric_list;
  };
  const studies::MetricList fine = run(360);
  for (int samples : {1, 2, 5, 6, 7}) {
    const studies::MetricList coarse = run(samples);
    ASSERT_EQ(coarse.size(), fine.size());
    for (std::size_t k = 0; k < fine.size(); ++k) {
      if (!fine[k].name.ends_with("_max")) continue;
      EXPECT_NEAR(coarse[k].value, fine[k].value, 1e-9 * fine[k].value)
          << fine[k].name << " at " << samples << " samples";
    }
  }
}

// The instants a free run's peaks are searched at besides its samples: m - 1 evenly between two
// samples the integrator took m > 1 steps between, none where it took one or none, at most
// kMaxStepInstants per interval; none when the step counts do not match the samples.
TEST(ResolvedPeaks, StepInstantsFollowTheIntegratorsSteps) {
  const std::vector<double> t = {0.0, 1.0, 2.0, 3.0, 4.0};
  const std::vector<long> steps = {0, 1, 4, 4, 4 + core::kMaxStepInstants + 10};
  const std::vector<double> s = core::step_instants(t, steps);
  ASSERT_EQ(s.size(), 2u + static_cast<std::size_t>(core::kMaxStepInstants));
  EXPECT_EQ(s[0], 1.0 + 1.0 / 3.0);
  EXPECT_EQ(s[1], 1.0 + 2.0 / 3.0);
  EXPECT_EQ(s[2], 3.0 + 1.0 / static_cast<double>(core::kMaxStepInstants + 1));
  EXPECT_TRUE(std::is_sorted(s.begin(), s.end()));
  EXPECT_LT(s.back(), 4.0);
  EXPECT_TRUE(core::step_instants(t, std::vector<long>{0, 5}).empty());
  // a run that stopped at 4.5 s, 3 steps after its last sample: two instants between, and the
  // stop
  const std::vector<double> stopped = core::step_instants(t, steps, 4.5, steps.back() + 3);
  ASSERT_EQ(stopped.size(), s.size() + 3);
  EXPECT_EQ(stopped[s.size()], 4.0 + 0.5 / 3.0);
  EXPECT_EQ(stopped[s.size() + 1], 4.0 + 1.0 / 3.0);
  EXPECT_EQ(stopped.back(), 4.5);
}

// The triple rocker of studies/examples/triple-rocker-free.yaml as a planar study under gravity,
// its crank drawn at 0.
const std::string kTripleRockerPlanar =
    "name: triple-rocker-planar\n"
    "linkage:\n"
    "  type: planar\n"
    "  nodes:\n"
    "    A0: {at: [0, 0], ground: true}\n"
    "    A1: [2, 0]\n"
    "    A2: [2.75, 1.8540496217739157]\n"
    "    A3: {at: [3.5, 0], ground: true}\n"
    "  links:\n"
    "    crank: {nodes: [A0, A1], mass: 1.0, e: 0.8, f: 0.1, inertia: 0.4}\n"
    "    coupler: {nodes: [A1, A2], mass: 1.5, e: 1.0, f: 0.0, inertia: 0.6}\n"
    "    rocker: {nodes: [A3, A2], mass: 1.2, e: 0.9, f: -0.1, inertia: 0.5}\n"
    "  inputs:\n"
    "    crank: {link: crank}\n"
    "loads:\n"
    "  gravity: [0, -9.81]\n"
    "scene:\n"
    "  type: free\n"
    "  rates: [1.0]\n"
    "  duration: 20.0\n"
    "tolerance: 1e-12\n";

// A free run whose peaks lie wholly between coarse samples: the triple rocker swinging through
// its limit positions under gravity, at 51 samples over 20 s (some 26 to 200 integrator steps
// between two samples). A designer's check found its Msh_max 25 % low there (468.75 N m for
// 621.72): the sharp swing through a limit position fell between two samples, neither of them a
// local maximum of Msh. The peaks are now searched at the integrator's own step density too
// (core::step_instants()), so they equal a 4001-sample run's (samples finer than the steps), on
// the four-bar's opened loop (auto) and the general engine's two routes. Tolerance 1e-12: the
// two runs' integrations agree to ~1e-10 of the values, the 1e-9 asked.
TEST(ResolvedPeaks, FreePeaksBetweenCoarseSamplesAreFoundAtTheIntegratorsSteps) {
  // the triple rocker as a four-bar study (auto: the opened loop; truss-dae: the general engine's
  // dae route, its peaks searched by the closed form) and as a planar study (auto: the reduced
  // route stops at the first limit position, the dae route runs it, its peaks searched by the
  // general engine)
  for (int variant = 0; variant < 3; ++variant) {
    // the variant's study at `samples` over `duration` [s]
    auto study_of = [&](int samples, double duration) {
      studies::Study study =
          variant == 2
              ? studies::parse_study(kTripleRockerPlanar, "p.yaml")
              : studies::load_study(BD_SOURCE_DIR "/studies/examples/triple-rocker-free.yaml");
      if (variant < 2) {
        study.method = variant == 0 ? studies::Method::kAuto : studies::Method::kTrussDae;
        study.tolerance = 1e-12;
        core::FourBar fb = study.fourbar();
        fb.loads.gravity = Vec2(0, -9.81);
        study.linkage = core::make_fourbar(fb);
      }
      std::visit(
          [&](auto& scene) {
            if constexpr (requires { scene.duration; }) {
              scene.samples = samples;
              scene.duration = duration;
            }
          },
          study.scene);
      return study;
    };
    auto run = [&](int samples, std::vector<double>* largest) {
      const studies::Study study = study_of(samples, 20.0);
      const studies::RunResult r = studies::compute_study(study);
      EXPECT_TRUE(r.ok()) << r.status().message;
      if (largest) {
        if (variant < 2) {
          const core::Metrics m = core::metrics(r.trajectory);
          *largest = {m.Fsh_max, m.Msh_max};
        } else {
          const std::vector<double> m =
              cp::metric_values(cp::metric_table(cp::Model(study.planar())), r.planar.table);
          *largest = {m[1], m[3]};
        }
      }
      return r.metric_list;
    };
    std::vector<double> sampled;
    const studies::MetricList a = run(51, &sampled), b = run(4001, nullptr);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (!a[k].name.ends_with("_max") || a[k].name.starts_with("tau")) continue;
      EXPECT_NEAR(a[k].value, b[k].value, 1e-9 * b[k].value) << a[k].name << " variant " << variant;
    }
    // the 51 samples' own largest shaking force or moment is far below its peak
    ASSERT_EQ(a[1].name, "Fsh_max");
    ASSERT_EQ(a[3].name, "Msh_max");
    EXPECT_LT(std::min(sampled[0] / b[1].value, sampled[1] / b[3].value), 0.9)
        << "variant " << variant;
    // where the peak lies: the crank's angle there is the motion's, as a run that ends at that
    // time has it (a separate integration from the start; both at a tolerance of 1e-12)
    ASSERT_TRUE(a[3].t);
    ASSERT_EQ(a[3].inputs.size(), 1u) << "variant " << variant;
    const studies::Study to_peak = study_of(2, *a[3].t);
    const studies::RunResult end = studies::compute_study(to_peak);
    ASSERT_TRUE(end.ok()) << end.status().message;
    const double theta1 = variant < 2 ? end.trajectory.samples.back().state.theta1
                                      : end.planar.table.column_values("theta_crank").back();
    EXPECT_NEAR(a[3].inputs[0], theta1, 1e-8) << "variant " << variant;
  }
}

// A free run that stops at a limit position: its peaks are searched up to where it stopped, not
// only to its last sample. A designer's check found the triple rocker's RA3_max at 51 samples
// (method truss, stopped at t = 1.2994 s, last sample 1.28 s) 8 % below a fine run's: the
// bearing load rises steeply towards the limit. Now the coarse run's peak lies at its stop and
// equals a 40 001-sample run's (last sample 3e-6 s before the stop), on the four-bar's mass
// matrix, on the general engine for a four-bar study, and for a planar study. Tolerance 1e-7:
// each run locates its stop by root finding on its own integrated state (tolerance 1e-10),
// which moves the stop by ~5e-10 s, where RA3 changes by ~1e3 N/s.
TEST(ResolvedPeaks, AStoppedRunsPeaksReachItsStop) {
  // the planar study without gravity, as the four-bar example
  std::string weightless = kTripleRockerPlanar;
  const std::string gravity = "loads:\n  gravity: [0, -9.81]\n";
  ASSERT_NE(weightless.find(gravity), std::string::npos);
  weightless.erase(weightless.find(gravity), gravity.size());
  for (int variant = 0; variant < 3; ++variant) {
    auto run = [&](int samples) {
      studies::Study study =
          variant == 2
              ? studies::parse_study(weightless, "p.yaml")
              : studies::load_study(BD_SOURCE_DIR "/studies/examples/triple-rocker-free.yaml");
      study.method = variant == 0 ? studies::Method::kMassMatrix : studies::Method::kTruss;
      std::visit(
          [&](auto& scene) {
            if constexpr (requires { scene.duration; }) {
              scene.samples = samples;
              scene.duration = 2.0;
            }
          },
          study.scene);
      return studies::compute_study(study);
    };
    const studies::RunResult coarse = run(51), fine = run(40001);
    const bool planar = variant == 2;
    for (const studies::RunResult* r : {&coarse, &fine}) {
      ASSERT_EQ(planar ? r->planar.status : r->trajectory.status, core::SimulationStatus::kSingular)
          << "variant " << variant;
    }
    const double stop = planar ? coarse.planar.stop_time : coarse.trajectory.stop_time;
    const double last =
        planar ? coarse.planar.table.column_values("t").back() : coarse.trajectory.t.back();
    EXPECT_GT(stop, last + 0.01) << "variant " << variant;
    const std::string name = "RA3_max";
    const auto find = [&](const studies::MetricList& list) {
      const auto it = std::find_if(list.begin(), list.end(),
                                   [&](const studies::MetricValue& m) { return m.name == name; });
      EXPECT_NE(it, list.end());
      return *it;
    };
    const studies::MetricValue a = find(coarse.metric_list), b = find(fine.metric_list);
    EXPECT_NEAR(a.value, b.value, 1e-7 * b.value) << "variant " << variant;
    ASSERT_TRUE(a.t);
    EXPECT_NEAR(*a.t, stop, 1e-12) << "variant " << variant;
    // the coarse run's samples alone fall 5 % short
    double sampled = 0;
    if (planar) {
      const std::vector<double> x = coarse.planar.table.column_values("RA3x"),
                                y = coarse.planar.table.column_values("RA3y");
      for (std::size_t i = 0; i < x.size(); ++i)
        sampled = std::max(sampled, std::hypot(x[i], y[i]));
    } else {
      sampled = core::metrics(coarse.trajectory).RA3_max;
    }
    EXPECT_LT(sampled, 0.95 * b.value) << "variant " << variant;
  }
}

// a planar free study, on either route: its reported peaks (metric_list, the run's own route,
// integrator and tolerance) do not depend on the sample count. At a tolerance of 1e-12 the two
// runs' integrations agree to ~1e-11 of the values; their largest samples do not.
TEST(ResolvedPeaks, PlanarFreeStudyPeaksDoNotDependOnTheSampleCount) {
  for (const studies::Method method : {studies::Method::kTruss, studies::Method::kTrussDae}) {
    std::vector<double> sampled[2];
    auto run = [&](int samples, std::vector<double>& largest) {
      studies::Study study =
          studies::load_study(BD_SOURCE_DIR "/studies/examples/stephenson-sixbar-free.yaml");
      study.method = method;
      study.tolerance = 1e-12;
      std::get<cp::FreeScene>(study.scene).samples = samples;
      const studies::RunResult r = studies::compute_study(study);
      EXPECT_TRUE(r.ok());
      largest = cp::metric_values(cp::metric_table(cp::Model(study.planar())), r.planar.table);
      return r.metric_list;
    };
    const studies::MetricList a = run(61, sampled[0]), b = run(601, sampled[1]);
    ASSERT_EQ(a.size(), b.size());
    bool samples_decided = false;
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (!a[k].name.ends_with("_max")) continue;
      if (std::abs(sampled[0][k] - sampled[1][k]) > 1e-6 * b[k].value) samples_decided = true;
      EXPECT_NEAR(a[k].value, b[k].value, 1e-9 * b[k].value)
          << a[k].name << " " << studies::to_string(method);
      ASSERT_TRUE(a[k].t && b[k].t) << a[k].name;
      if (!a[k].name.starts_with("tau")) {  // a constant torque is largest everywhere
        EXPECT_NEAR(*a[k].t, *b[k].t, 1e-4) << a[k].name << " " << studies::to_string(method);
      }
    }
    // the largest samples of the two runs differ: the resolution is what makes them agree
    EXPECT_TRUE(samples_decided) << studies::to_string(method);
  }
}

}  // namespace
}  // namespace bd
