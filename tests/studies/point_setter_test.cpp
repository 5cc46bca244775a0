// The study at a sweep point from the loaded model (studies/sweep/point_setter.hpp) against the
// YAML loader's (point_study(), an independent route: the study file's text with the values set,
// read again): at every point of sweeps over each field the setter knows, including points the
// loader refuses, both give the same study, the same metrics to the bit, or the same message.
#include "studies/sweep/point_setter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {
namespace {

const std::string kLinkage =
    "name: t\n"
    "linkage:\n"
    "  type: fourbar\n"
    "  frame: 3.2\n"
    "  branch: 1\n"
    "  crank:   {length: 1.0, mass: 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}\n"
    "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"
    "  rocker:  {length: 2.0, mass: 2.2, e: 1.5, f: -0.6, inertia: 2.1}\n"
    "loads:\n"
    "  gravity: [0, -9.81]\n"
    "  crank: {force: [1.1, 1.2], moment: 0.37}\n"
    "  coupler: {force: [1.3, -1.4], moment: 0.28}\n";

// every point's study both ways: the same metrics bit for bit, or the same refusal; returns how
// many points the setter built itself (not left to the loader)
int expect_same_points(const std::string& text) {
  const Study base = parse_study(text, "t.yaml");
  const std::optional<detail::PointSetter> setter = detail::PointSetter::make(base);
  EXPECT_TRUE(setter.has_value()) << "the setter knows every swept field here";
  if (!setter) return 0;
  int built = 0;
  for (const std::vector<double>& v : sweep_points(*base.sweep)) {
    std::string loader_error, setter_error;
    std::optional<Study> loaded, set;
    try {
      loaded = point_study(base, v);
    } catch (const InputError& e) {
      loader_error = e.what();
    }
    try {
      set = detail::sweep_point_study(base, v);
    } catch (const InputError& e) {
      setter_error = e.what();
    }
    built += setter->apply(base, v).has_value();
    EXPECT_EQ(setter_error, loader_error);
    EXPECT_EQ(setter->apply(base, v).has_value(), loaded.has_value())
        << "the setter accepts exactly the points the loader accepts, at " << v[0];
    if (!loaded || !set) continue;
    const RunResult a = compute_study(*loaded);
    const RunResult b = compute_study(*set);
    EXPECT_EQ(a.metric_list.size(), b.metric_list.size());
    for (std::size_t m = 0; m < std::min(a.metric_list.size(), b.metric_list.size()); ++m) {
      // the same model and scene: the same arithmetic, so the same bits
      EXPECT_EQ(a.metric_list[m].value, b.metric_list[m].value) << a.metric_list[m].name;
    }
    if (loaded->balance && b.balanced) {
      EXPECT_TRUE(b.balanced.has_value());
      for (std::size_t m = 0; m < a.balanced->metric_list.size(); ++m) {
        EXPECT_EQ(a.balanced->metric_list[m].value, b.balanced->metric_list[m].value);
      }
    }
  }
  return built;
}

TEST(PointSetter, DrivenLinkageFieldsAndLoadsMatchTheLoader) {
  // negative masses and s, a crank too long to turn, a zero speed: refused by both
  const int built = expect_same_points(
      kLinkage +
      "scene: {type: driven, theta1: 0.2, omega1: 6.0, samples: 24}\n"
      "balance: {force: full}\n"
      "sweep:\n"
      "  parameters:\n"
      "    - {path: linkage.coupler.mass, values: [-1.0, 0.5, 4.0]}\n"
      "    - {path: linkage.coupler.s, values: [-0.2, 2.0]}\n"
      "    - {path: linkage.crank.length, values: [1.1, 1.95]}\n"
      "    - {path: linkage.rocker.f, values: [0.3]}\n"
      "    - {path: \"loads.coupler.force[1]\", values: [2.5]}\n"
      "    - {path: \"loads.gravity[0]\", values: [0.5]}\n"
      "    - {path: scene.omega1, values: [0.0, -3.0]}\n");
  // valid: coupler mass 0.5 or 4, s 2, crank length 1.1, speed -3; the other 22 refused
  EXPECT_EQ(built, 2);
}

TEST(PointSetter, FreeSceneFieldsMatchTheLoader) {
  const int built = expect_same_points(
      kLinkage +
      "scene: {type: free, theta1: 1.0, omega1: 0.5, duration: 1.0, samples: 21}\n"
      "sweep:\n"
      "  design: lhs\n"
      "  points: 12\n"
      "  parameters:\n"
      "    - {path: scene.duration, from: -0.5, to: 2.0}\n"
      "    - {path: scene.theta1, from: 0.0, to: 6.0}\n"
      "    - {path: linkage.frame, from: 2.5, to: 4.5}\n"
      "    - {path: linkage.crank.sigma, from: -1.0, to: 1.0}\n"
      "    - {path: loads.crank.moment, from: -1.0, to: 1.0}\n");
  EXPECT_GT(built, 0);
}

TEST(PointSetter, UnknownFieldsAndUnitsAreLeftToTheLoader) {
  // a method's tolerance has no setter; s beside a sigma given in degrees cannot be rebuilt
  for (const std::string& sweep :
       {std::string("tolerance: 1e-8\nsweep:\n  parameters:\n"
                    "    - {path: tolerance, values: [1e-9, 1e-8]}\n"),
        std::string("sweep:\n  parameters:\n    - {path: linkage.coupler.s, values: [1, 2]}\n")}) {
    std::string text = kLinkage + "scene: {type: driven, omega1: 6.0, samples: 12}\n" + sweep;
    if (sweep.find("coupler.s") != std::string::npos) {
      text.replace(text.find("sigma: 0.4"), 10, "sigma: 23 deg");
    }
    const Study base = parse_study(text, "t.yaml");
    EXPECT_FALSE(detail::PointSetter::make(base).has_value()) << sweep;
    // and the points still come, through the loader
    const std::vector<double> v = sweep_points(*base.sweep)[1];
    EXPECT_EQ(compute_study(detail::sweep_point_study(base, v)).metric_list[0].value,
              compute_study(point_study(base, v)).metric_list[0].value);
  }
}

}  // namespace
}  // namespace bd::studies
