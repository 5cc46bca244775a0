// The loading side of parameter sweeps: the `sweep:` section's checks (every mistake one line
// FILE:LINE:COLUMN: message at the offending value, bad paths with what the file has there), the
// points of grid, random and Latin-hypercube designs, and point_study(), which sets each path's
// value in the study file and loads it as any study.
#include "studies/sweep/sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "studies/study/load_study.hpp"
#include "studies/study/study_yaml.hpp"
#include "tests/support/study_errors.hpp"

namespace bd::studies {
namespace {

// a valid driven study with a load; line numbers below refer to this text
const std::string kStudy =
    "name: t\n"                                                                  // 1
    "linkage:\n"                                                                 // 2
    "  type: fourbar\n"                                                          // 3
    "  frame: 3.2\n"                                                             // 4
    "  branch: 1\n"                                                              // 5
    "  crank:   {length: 1.0, mass: 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}\n"  // 6
    "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"  // 7
    "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"  // 8
    "loads:\n"                                                                   // 9
    "  crank: {force: [1.1, 1.2], moment: 0.37}\n"                               // 10
    "scene:\n"                                                                   // 11
    "  type: driven\n"                                                           // 12
    "  omega1: 6.0\n"                                                            // 13
    "  samples: 36\n";                                                           // 14

// kStudy with a sweep section whose body starts at line 16
std::string with_sweep(const std::string& body) { return kStudy + "sweep:\n" + body; }

// one parameter at line 17, its path's value at column 13, then `rest` (lines 18...)
std::string one_parameter(const std::string& path,
                          const std::string& rest = "      values: [1, 2]\n") {
  return with_sweep("  parameters:\n    - path: " + path + "\n" + rest);
}

// checks place and text, and that what() is the one-line "file:line:col: message"
void expect_error(const std::string& text, int line, int column, const std::string& message) {
  bd::testing::expect_study_error(text, "sweep.yaml", line, column, message);
}

SweepRequest request_of(const std::string& text) {
  const Study study = parse_study(text, "sweep.yaml");
  EXPECT_TRUE(study.sweep.has_value());
  return study.sweep.value_or(SweepRequest{});
}

// ---- loading ----

TEST(SweepLoad, SectionWithDefaults) {
  const std::string text = with_sweep(
      "  parameters:\n"
      "    - path: linkage.coupler.mass\n"  // 17
      "      from: 1.0\n"
      "      to: 5.0\n"
      "      count: 5\n"
      // in a flow map '[' ends a plain scalar: a path with [i] is quoted there
      "    - {path: \"loads.crank.force[1]\", values: [0.5, -0.5, 2]}\n");  // 21
  const Study study = parse_study(text, "sweep.yaml");
  ASSERT_TRUE(study.sweep.has_value());
  const SweepRequest& r = *study.sweep;
  EXPECT_EQ(r.design, SweepDesign::kGrid);
  EXPECT_EQ(r.seed, 1u);
  EXPECT_EQ(r.threads, 0);
  EXPECT_EQ(r.points, 15);
  ASSERT_EQ(r.parameters.size(), 2u);
  EXPECT_EQ(r.parameters[0].path, "linkage.coupler.mass");
  EXPECT_EQ(r.parameters[0].values, (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(r.parameters[0].from, 1.0);
  EXPECT_EQ(r.parameters[0].to, 5.0);
  EXPECT_FALSE(r.parameters[0].log_scale);
  EXPECT_EQ(r.parameters[0].line, 17);
  EXPECT_EQ(r.parameters[0].column, 7);
  // a values list keeps its order; from and to are its extremes
  EXPECT_EQ(r.parameters[1].values, (std::vector<double>{0.5, -0.5, 2}));
  EXPECT_EQ(r.parameters[1].from, -0.5);
  EXPECT_EQ(r.parameters[1].to, 2.0);
  EXPECT_EQ(r.parameters[1].line, 21);
  EXPECT_EQ(r.parameters[1].column, 7);
  // the file's text, for point_study()
  EXPECT_EQ(r.study_text, text);
  // the study itself is the file's own values
  EXPECT_EQ(study.fourbar().coupler.mass, 3.0);
  // a study without a sweep has none
  EXPECT_FALSE(parse_study(kStudy, "sweep.yaml").sweep.has_value());
}

TEST(SweepLoad, RandomAndLhsSettings) {
  const SweepRequest r =
      request_of(with_sweep("  design: lhs\n"
                            "  points: 40\n"
                            "  seed: 9007199254740991\n"  // 2^53 - 1, the largest seed
                            "  threads: 3\n"
                            "  parameters:\n"
                            "    - {path: scene.omega1, from: 1, to: 100, scale: log}\n"
                            "    - {path: linkage.frame, from: 3.0, to: 3.4}\n"));
  EXPECT_EQ(r.design, SweepDesign::kLatinHypercube);
  EXPECT_EQ(r.points, 40);
  EXPECT_EQ(r.seed, 9007199254740991u);
  EXPECT_EQ(r.threads, 3);
  ASSERT_EQ(r.parameters.size(), 2u);
  EXPECT_TRUE(r.parameters[0].log_scale);
  EXPECT_TRUE(r.parameters[0].values.empty());
  EXPECT_EQ(r.parameters[0].from, 1.0);
  EXPECT_EQ(r.parameters[0].to, 100.0);
  EXPECT_EQ(request_of(with_sweep("  design: random\n  points: 1\n  parameters:\n"
                                  "    - {path: scene.omega1, from: 1, to: 2}\n"))
                .design,
            SweepDesign::kRandom);
  EXPECT_STREQ(to_string(SweepDesign::kGrid), "grid");
  EXPECT_STREQ(to_string(SweepDesign::kRandom), "random");
  EXPECT_STREQ(to_string(SweepDesign::kLatinHypercube), "lhs");
}

TEST(SweepLoad, CombinesWithBalanceOrOptimize) {
  const std::string sweep =
      "sweep:\n  parameters:\n    - {path: linkage.coupler.mass, values: [2, 4]}\n";
  const Study b = parse_study(kStudy + "balance:\n  force: full\n" + sweep, "sweep.yaml");
  EXPECT_TRUE(b.balance.has_value());
  EXPECT_TRUE(b.sweep.has_value());
  const Study o = parse_study(kStudy +
                                  "optimize:\n  objective: {Msh_rms: 1.0}\n"
                                  "  variables: {counterweights: {crank: {}}}\n" +
                                  sweep,
                              "sweep.yaml");
  EXPECT_TRUE(o.optimize.has_value());
  EXPECT_TRUE(o.sweep.has_value());
  // a value of the balance section may be swept like any other
  const SweepRequest r = request_of(kStudy +
                                    "balance:\n  force: full\n"
                                    "  counterweights: {crank: {mass: 2.0}}\n"
                                    "sweep:\n  parameters:\n"
                                    "    - {path: balance.counterweights.crank.mass, "
                                    "from: 1, to: 3, count: 3}\n");
  EXPECT_EQ(r.parameters[0].values, (std::vector<double>{1, 2, 3}));
}

// A value the study writes with a unit ("300 rpm") may be swept: the sweep's plain SI values take
// its place, and each point runs at them. The swept values themselves are plain SI numbers: one
// written with a unit is refused at its place, saying so.
TEST(SweepLoad, AValueWithAUnitIsSweptInSI) {
  std::string text = kStudy;
  text.replace(text.find("omega1: 6.0"), 11, "omega1: 300 rpm");
  const std::string swept = text + "sweep:\n  parameters:\n    - path: scene.omega1\n";
  const Study study = parse_study(swept + "      values: [6, 12]\n", "sweep.yaml");
  ASSERT_TRUE(study.sweep);
  // each point as the same study written with the value in SI
  const auto points = sweep_points(*study.sweep);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(std::get<core::DrivenScene>(study.scene).omega1, 10 * std::numbers::pi);
  EXPECT_EQ(std::get<core::DrivenScene>(point_study(study, points[0]).scene).omega1, 6.0);
  EXPECT_EQ(std::get<core::DrivenScene>(point_study(study, points[1]).scene).omega1, 12.0);
  const std::string message =
      ": the swept values are plain numbers in SI units (rad, m, kg, s, N, rad/s, ...), got "
      "'100 rpm'; the value the path names may carry a unit of its own";
  expect_error(swept + "      values: [6, 100 rpm]\n", 18, 19,
               "sweep.parameters[0].values[1]" + message);
  expect_error(swept + "      from: 100 rpm\n      to: 200\n      count: 2\n", 18, 13,
               "sweep.parameters[0].from" + message);
}

TEST(SweepLoad, BadPathsNameWhatTheFileHas) {
  const std::string p = "sweep.parameters[0].path: ";
  expect_error(one_parameter("linkage.coupler.mas"), 17, 13,
               p + "linkage.coupler has no key 'mas' (it has length, mass, s, sigma, inertia)");
  expect_error(one_parameter("linkag.coupler.mass"), 17, 13,
               p + "the study file has no key 'linkag' (it has name, linkage, loads, scene, "
                   "sweep)");
  // a value left at its default is not in the file
  expect_error(one_parameter("scene.theta1"), 17, 13,
               p + "scene has no key 'theta1' (it has type, omega1, samples)");
  expect_error(one_parameter("linkage.coupler"), 17, 13,
               p + "linkage.coupler is a map (with keys length, mass, s, sigma, inertia), not a "
                   "number; name one of its values, e.g. linkage.coupler.length");
  expect_error(one_parameter("loads.crank.force"), 17, 13,
               p + "loads.crank.force is a list of 2, not a number; name an element, e.g. "
                   "loads.crank.force[0]");
  expect_error(one_parameter("loads.crank.force[2]"), 17, 13,
               p + "loads.crank.force has no element [2] (it is a list of 2: [0] to [1])");
  expect_error(one_parameter("loads.crank.force.x"), 17, 13,
               p + "loads.crank.force is a list of 2, not a map, so it has no key 'x'");
  expect_error(one_parameter("linkage.coupler.mass[0]"), 17, 13,
               p + "linkage.coupler.mass is '3.0', not a list, so it has no element [0]");
  expect_error(one_parameter("loads[0]"), 17, 13,
               p + "loads is a map (with keys crank), not a list, so it has no element [0]");
  // non-numbers
  expect_error(one_parameter("scene.type"), 17, 13, p + "scene.type is 'driven', not a number");
  expect_error(one_parameter("linkage.type"), 17, 13,
               p + "linkage.type is 'fourbar', not a number");
  expect_error(one_parameter("name"), 17, 13,
               p + "name is the study's name (text), not a number to sweep");
  expect_error(one_parameter("sweep.parameters[0].values[0]"), 17, 13,
               p + "sweep.parameters[0].values[0] is in the sweep section itself");
  // not a path at all
  for (const char* bad : {"linkage..mass", "linkage.coupler.", ".linkage", "linkage coupler",
                          "loads.crank.force[01]", "loads.crank.force[x]", "loads.crank.force[1",
                          "loads.crank.force[]", "loads.crank.force[1]x", "linkage/coupler"}) {
    SCOPED_TRACE(bad);
    expect_error(one_parameter(bad), 17, 13,
                 p + "'" + bad +
                     "' is not a path; give map keys joined by '.' and a list "
                     "element by [i], e.g. linkage.coupler.mass or "
                     "loads.crank.force[1]");
  }
  // the path must be text
  expect_error(one_parameter("[linkage]"), 17, 13,
               "sweep.parameters[0].path must be text, got a list");
  // distinct paths: reported at the second
  expect_error(with_sweep("  parameters:\n"
                          "    - {path: scene.omega1, values: [1, 2]}\n"
                          "    - {path: scene.omega1, values: [3]}\n"),
               18, 14,
               "sweep.parameters[1].path: scene.omega1 is already swept by "
               "sweep.parameters[0] (line 17); each path may be swept once");
  // one value reached by two paths through a YAML alias
  const std::string aliased =
      "name: t\n"
      "linkage:\n"
      "  type: fourbar\n"
      "  frame: 3.2\n"
      "  branch: 1\n"
      "  crank:   {length: 1.0, mass: &m 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}\n"
      "  coupler: {length: 3.0, mass: *m, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"
      "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
      "scene: {type: driven, omega1: 6.0}\n"
      "sweep:\n"
      "  parameters:\n"
      "    - {path: linkage.crank.mass, values: [1, 2]}\n"     // 12
      "    - {path: linkage.coupler.mass, values: [3, 4]}\n";  // 13
  expect_error(aliased, 13, 14,
               "sweep.parameters[1].path: linkage.coupler.mass is the same value as "
               "sweep.parameters[0]'s linkage.crank.mass (line 12), through a YAML alias; each "
               "value may be swept once");
  // valid paths of each kind load
  for (const char* good : {"linkage.coupler.mass", "loads.crank.force[1]", "scene.omega1",
                           "linkage.branch", "loads.crank.moment"}) {
    SCOPED_TRACE(good);
    EXPECT_NO_THROW(parse_study(one_parameter(good, "      values: [1]\n"), "sweep.yaml"));
  }
}

TEST(SweepLoad, SectionMistakes) {
  const std::string grid_parameter =
      "  parameters:\n    - {path: linkage.coupler.mass, from: 1, to: 2, count: 3}\n";
  const std::string drawn_parameter =
      "  parameters:\n    - {path: linkage.coupler.mass, from: 1, to: 2}\n";
  expect_error(kStudy + "sweep:\n", 15, 1,
               "sweep must be a map (design, points, seed, threads, parameters), got nothing");
  expect_error(with_sweep("  desing: grid\n" + grid_parameter), 16, 3,
               "unknown key 'desing' in sweep; allowed keys: design, points, seed, threads, "
               "parameters");
  expect_error(with_sweep("  design: sobol\n" + grid_parameter), 16, 11,
               "sweep.design must be grid, random or lhs, got 'sobol'");
  // points and seed belong to drawn designs
  expect_error(with_sweep("  points: 10\n" + grid_parameter), 16, 3,
               "sweep.points is used only by the random and lhs designs");
  expect_error(with_sweep("  design: grid\n  seed: 3\n" + grid_parameter), 17, 3,
               "sweep.seed is used only by the random and lhs designs");
  expect_error(with_sweep("  design: random\n" + drawn_parameter), 15, 1,
               "sweep: missing required key 'points' (how many points the random design draws)");
  const std::string lhs = "  design: lhs\n";
  expect_error(with_sweep(lhs + "  points: 0\n" + drawn_parameter), 17, 11,
               "sweep.points must be >= 1, got 0");
  expect_error(with_sweep(lhs + "  points: 2.5\n" + drawn_parameter), 17, 11,
               "sweep.points must be a whole number, got '2.5'");
  expect_error(with_sweep(lhs + "  points: 1000001\n" + drawn_parameter), 17, 11,
               "sweep.points must be <= 1000000, got 1000001");
  for (const char* seed : {"-1", "1.5", "9007199254740992", "1e300"}) {
    SCOPED_TRACE(seed);
    expect_error(with_sweep(lhs + "  points: 5\n  seed: " + seed + "\n" + drawn_parameter), 18, 9,
                 "sweep.seed must be a whole number from 0 to 2^53 - 1 (9007199254740991)");
  }
  expect_error(with_sweep(lhs + "  points: 5\n  seed: abc\n" + drawn_parameter), 18, 9,
               "sweep.seed must be a number, got 'abc'");
  expect_error(with_sweep("  threads: -1\n" + grid_parameter), 16, 12,
               "sweep.threads must be >= 0, got -1");
  expect_error(with_sweep("  threads: 1025\n" + grid_parameter), 16, 12,
               "sweep.threads must be <= 1024, got 1025");
  expect_error(with_sweep("  threads: 1.5\n" + grid_parameter), 16, 12,
               "sweep.threads must be a whole number, got '1.5'");
  // parameters
  expect_error(with_sweep("  design: grid\n"), 15, 1,
               "sweep: missing required key 'parameters' (the study values to vary, each with "
               "its path)");
  expect_error(with_sweep("  parameters: []\n"), 16, 15,
               "sweep.parameters must be a list of one or more parameters (each a map with path, "
               "and values or from and to), got an empty list");
  expect_error(with_sweep("  parameters: {path: scene.omega1}\n"), 16, 15,
               "sweep.parameters must be a list of one or more parameters (each a map with path, "
               "and values or from and to), got a map");
  expect_error(with_sweep("  parameters:\n    - scene.omega1\n"), 17, 7,
               "sweep.parameters[0] must be a map (path, and values or from, to, count; scale), "
               "got 'scene.omega1'");
  expect_error(with_sweep("  parameters:\n    - {from: 1, to: 2, count: 3}\n"), 17, 7,
               "sweep.parameters[0]: missing required key 'path' (the study value to vary, e.g. "
               "linkage.coupler.mass)");
  expect_error(one_parameter("scene.omega1", "      form: 1\n"), 18, 7,
               "unknown key 'form' in sweep.parameters[0]; allowed keys: path, values, from, to, "
               "count, scale");
  expect_error(one_parameter("scene.omega1", "      values: [1, 2]\n      scale: logarithmic\n"),
               19, 14, "sweep.parameters[0].scale must be linear or log, got 'logarithmic'");
}

TEST(SweepLoad, GridParameterMistakes) {
  const std::string p = "scene.omega1";
  // values, or from/to/count, not both (reported at the later key)
  expect_error(one_parameter(p, "      values: [1, 2]\n      from: 1\n"), 19, 7,
               "sweep.parameters[0]: give either values or from, to and count, not both");
  expect_error(one_parameter(p, "      count: 3\n      values: [1, 2]\n"), 19, 7,
               "sweep.parameters[0]: give either values or from, to and count, not both");
  expect_error(one_parameter(p, "      from: 1\n      to: 2\n"), 17, 7,
               "sweep.parameters[0]: a grid parameter needs values: [...] or from, to and "
               "count; missing 'count'");
  expect_error(one_parameter(p, "      count: 3\n"), 17, 7, "missing 'from'");
  // values
  expect_error(one_parameter(p, "      values: []\n"), 18, 15,
               "sweep.parameters[0].values must be a list of one or more numbers, got an empty "
               "list");
  expect_error(one_parameter(p, "      values: 3\n"), 18, 15,
               "sweep.parameters[0].values must be a list of one or more numbers, got '3'");
  expect_error(one_parameter(p, "      values: [1, x]\n"), 18, 19,
               "sweep.parameters[0].values[1] must be a number, got 'x'");
  expect_error(one_parameter(p, "      values: [1, .nan]\n"), 18, 19,
               "sweep.parameters[0].values[1] must be a finite number, got '.nan'");
  expect_error(one_parameter(p, "      values: [1, 2, 1.0]\n"), 18, 22,
               "sweep.parameters[0].values[2] repeats values[0] (1); a grid's values must be "
               "distinct");
  expect_error(one_parameter(p, "      values: [1, 0]\n      scale: log\n"), 18, 19,
               "sweep.parameters[0].values[1] must be > 0 with scale: log, got 0");
  // from/to/count
  expect_error(one_parameter(p, "      from: 2\n      to: 1\n      count: 3\n"), 19, 11,
               "sweep.parameters[0]: from must be < to, got from = 2, to = 1");
  expect_error(one_parameter(p, "      from: 2\n      to: 2\n      count: 3\n"), 19, 11,
               "from must be < to, got from = 2, to = 2");
  expect_error(one_parameter(p, "      from: 0\n      to: 2\n      count: 3\n      scale: log\n"),
               18, 13, "sweep.parameters[0].from must be > 0 with scale: log, got 0");
  expect_error(one_parameter(p, "      from: 1\n      to: 2\n      count: 1\n"), 20, 14,
               "sweep.parameters[0].count must be >= 2, got 1");
  expect_error(one_parameter(p, "      from: 1\n      to: 2\n      count: 2.5\n"), 20, 14,
               "sweep.parameters[0].count must be a whole number, got '2.5'");
  expect_error(one_parameter(p, "      from: x\n      to: 2\n      count: 3\n"), 18, 13,
               "sweep.parameters[0].from must be a number, got 'x'");
  expect_error(one_parameter(p, "      from: 1\n      to: .inf\n      count: 3\n"), 19, 11,
               "sweep.parameters[0].to must be a finite number, got '.inf'");
  // 10 values within 2 ulps of 1 cannot be distinct
  expect_error(one_parameter(p, "      from: 1\n      to: 1.0000000000000004\n      count: 10\n"),
               20, 14,
               "sweep.parameters[0].count: 10 values from 1 to 1.0000000000000004 are not "
               "distinct in double precision; give fewer");
  // at most 10^6 points, reported at `parameters`
  expect_error(with_sweep("  parameters:\n"
                          "    - {path: scene.omega1, from: 1, to: 2, count: 1001}\n"
                          "    - {path: linkage.frame, from: 3, to: 3.4, count: 1001}\n"),
               16, 3,
               "sweep: the grid has 1001 x 1001 = 1002001 points, more than the 1000000 a sweep "
               "may have");
}

TEST(SweepLoad, DrawnParameterMistakes) {
  const std::string random = "  design: random\n  points: 5\n";
  const std::string lhs = "  design: lhs\n  points: 5\n";
  // random and lhs draw their values: only from and to (parameter at line 19)
  expect_error(with_sweep(random + "  parameters:\n    - path: scene.omega1\n"
                                   "      values: [1, 2]\n"),
               20, 7,
               "sweep.parameters[0].values: the random design draws its values; give from and "
               "to only");
  expect_error(with_sweep(lhs + "  parameters:\n    - path: scene.omega1\n"
                                "      from: 1\n      to: 2\n      count: 3\n"),
               22, 7,
               "sweep.parameters[0].count: the lhs design draws its values; give from and to "
               "only");
  expect_error(with_sweep(lhs + "  parameters:\n    - {path: scene.omega1, to: 2}\n"), 19, 7,
               "sweep.parameters[0]: missing required key 'from' (the lower end of the range)");
  expect_error(with_sweep(random + "  parameters:\n    - {path: scene.omega1, from: 2}\n"), 19, 7,
               "sweep.parameters[0]: missing required key 'to' (the upper end of the range)");
  expect_error(with_sweep(random + "  parameters:\n    - {path: scene.omega1, from: 3, to: 2}\n"),
               19, 41, "sweep.parameters[0]: from must be < to, got from = 3, to = 2");
  expect_error(with_sweep(lhs + "  parameters:\n"
                                "    - {path: scene.omega1, from: -1, to: 2, scale: log}\n"),
               19, 34, "sweep.parameters[0].from must be > 0 with scale: log, got -1");
}

// ---- points ----

// a grid over three parameters: 3 x 2 x 2 points, the first varying slowest
TEST(SweepPoints, GridIsTheProductFirstParameterSlowest) {
  SweepRequest r;
  r.parameters.resize(3);
  r.parameters[0].values = {1, 2, 3};
  r.parameters[1].values = {10, 20};
  r.parameters[2].values = {-1, -2};
  const auto points = sweep_points(r);
  ASSERT_EQ(points.size(), 12u);
  std::size_t i = 0;
  for (double a : {1, 2, 3}) {
    for (double b : {10, 20}) {
      for (double c : {-1, -2}) {
        EXPECT_EQ(points[i], (std::vector<double>{a, b, c})) << "point " << i;
        ++i;
      }
    }
  }
  // a single parameter: its values in order
  r.parameters.resize(1);
  EXPECT_EQ(sweep_points(r), (std::vector<std::vector<double>>{{1}, {2}, {3}}));
}

TEST(SweepPoints, LinearGridHasExactEndsAndEvenSteps) {
  const SweepRequest r =
      request_of(with_sweep("  parameters:\n"
                            "    - {path: scene.omega1, from: 0.1, to: 0.7, count: 7}\n"
                            "    - {path: linkage.frame, from: -1.3, to: 2.9, count: 31}\n"));
  EXPECT_EQ(r.points, 7 * 31);
  for (const SweepParameter& p : r.parameters) {
    const std::size_t n = p.values.size();
    EXPECT_EQ(p.values.front(), p.from);  // exact, not within round-off
    EXPECT_EQ(p.values.back(), p.to);
    // from + (to - from) k / (n - 1): one multiply, divide and add, each rounded once
    const double tol =
        4 * std::numeric_limits<double>::epsilon() * std::max(std::abs(p.from), std::abs(p.to));
    for (std::size_t k = 0; k < n; ++k) {
      const double expected =
          p.from + (p.to - p.from) * static_cast<double>(k) / static_cast<double>(n - 1);
      EXPECT_NEAR(p.values[k], expected, tol) << p.path << " k = " << k;
    }
  }
  const auto points = sweep_points(r);
  ASSERT_EQ(points.size(), 217u);
  EXPECT_EQ(points[0], (std::vector<double>{0.1, -1.3}));
  EXPECT_EQ(points[30], (std::vector<double>{0.1, 2.9}));
  EXPECT_EQ(points[31][0], r.parameters[0].values[1]);
  EXPECT_EQ(points[31][1], -1.3);
  EXPECT_EQ(points[216], (std::vector<double>{0.7, 2.9}));
}

TEST(SweepPoints, LogGridIsGeometric) {
  const SweepRequest r = request_of(
      with_sweep("  parameters:\n    - {path: scene.omega1, from: 1.0e-3, to: 1.0e3, count: 7, "
                 "scale: log}\n"));
  const std::vector<double>& v = r.parameters[0].values;
  ASSERT_EQ(v.size(), 7u);
  EXPECT_EQ(v.front(), 1e-3);
  EXPECT_EQ(v.back(), 1e3);
  // decades: exp of a sum of logs, each good to a few ulps; 1e-14 leaves a wide margin
  for (std::size_t k = 0; k < v.size(); ++k) {
    const double expected = std::pow(10.0, static_cast<double>(k) - 3.0);
    EXPECT_NEAR(v[k] / expected, 1.0, 1e-14) << "k = " << k;
  }
}

// a drawn design over two parameters, the second on a log scale
SweepRequest drawn(SweepDesign design, int points, std::uint64_t seed) {
  SweepRequest r;
  r.design = design;
  r.points = points;
  r.seed = seed;
  r.parameters.resize(2);
  r.parameters[0].from = -2.0;
  r.parameters[0].to = 3.0;
  r.parameters[1].from = 0.01;
  r.parameters[1].to = 100.0;
  r.parameters[1].log_scale = true;
  return r;
}

// A sweep takes its points from a cursor, skipping those other processes compute: a point
// reached after skipping is the very point of the whole table (whose random and LHS values
// are checked against an independent transcription of the generator below), for every design.
TEST(SweepPoints, CursorSkippingPointsGivesTheTablesPoints) {
  SweepRequest grid;
  grid.parameters.resize(3);
  grid.parameters[0].values = {1, 2, 3};
  grid.parameters[1].values = {10, 20};
  grid.parameters[2].values = {-1, -2, -3, -4, -5, -6, -7, -8, -9, -10};
  for (const SweepRequest& r : {grid, drawn(SweepDesign::kRandom, 300, 5),
                                drawn(SweepDesign::kLatinHypercube, 300, 9)}) {
    SCOPED_TRACE(to_string(r.design));
    const auto table = sweep_points(r);
    ASSERT_EQ(static_cast<std::size_t>(sweep_size(r)), table.size());
    PointCursor cursor(r);
    ASSERT_EQ(cursor.size(), sweep_size(r));
    const int n = cursor.size();
    for (int i : {0, 1, 2, 7, 8, 23, n / 2, n - 2, n - 1}) {
      const std::span<const double> v = cursor.at(i);
      EXPECT_EQ(std::vector<double>(v.begin(), v.end()), table[static_cast<std::size_t>(i)])
          << "point " << i;
    }
  }
}

TEST(SweepPoints, RandomIsReproducibleAndInRange) {
  const auto a = sweep_points(drawn(SweepDesign::kRandom, 2000, 17));
  ASSERT_EQ(a.size(), 2000u);
  EXPECT_EQ(a, sweep_points(drawn(SweepDesign::kRandom, 2000, 17)));  // bit for bit
  EXPECT_NE(a, sweep_points(drawn(SweepDesign::kRandom, 2000, 18)));
  double mean0 = 0, mean_log1 = 0;
  for (const auto& p : a) {
    ASSERT_EQ(p.size(), 2u);
    EXPECT_GE(p[0], -2.0);
    EXPECT_LT(p[0], 3.0);
    EXPECT_GE(p[1], 0.01);
    EXPECT_LT(p[1], 100.0);
    mean0 += p[0] / 2000;
    mean_log1 += std::log10(p[1]) / 2000;
  }
  // uniform in [-2, 3) and, for the log parameter, in log10 over [-2, 2): the means of 2000
  // draws are within 5 standard deviations (5 * width / sqrt(12 * 2000)) of the middle
  EXPECT_NEAR(mean0, 0.5, 5 * 5.0 / std::sqrt(12.0 * 2000));
  EXPECT_NEAR(mean_log1, 0.0, 5 * 4.0 / std::sqrt(12.0 * 2000));
}

// the stratum of v in [from, to) cut into n equal parts (log: equal in log), by the edges the
// documented rule gives (from + (to - from) s / n, geometric with log)
std::size_t stratum_of(double v, const SweepParameter& p, std::size_t n) {
  auto edge = [&](std::size_t s) {
    if (s == 0) return p.from;
    if (s == n) return p.to;
    const double u = static_cast<double>(s) / static_cast<double>(n);
    if (!p.log_scale) return p.from + (p.to - p.from) * u;
    const double a = std::log(p.from);
    return std::exp(a + (std::log(p.to) - a) * u);
  };
  for (std::size_t s = 0; s < n; ++s) {
    if (v >= edge(s) && v < edge(s + 1)) return s;
  }
  return n;  // outside
}

TEST(SweepPoints, LatinHypercubeHasOnePointPerStratum) {
  const std::size_t n = 97;
  const SweepRequest r = drawn(SweepDesign::kLatinHypercube, static_cast<int>(n), 5);
  const auto a = sweep_points(r);
  ASSERT_EQ(a.size(), n);
  EXPECT_EQ(a, sweep_points(r));
  EXPECT_NE(a, sweep_points(drawn(SweepDesign::kLatinHypercube, static_cast<int>(n), 6)));
  std::vector<std::vector<std::size_t>> strata(2);
  for (std::size_t j = 0; j < 2; ++j) {
    std::vector<int> hits(n, 0);
    for (const auto& p : a) {
      const std::size_t s = stratum_of(p[j], r.parameters[j], n);
      ASSERT_LT(s, n) << "parameter " << j << " value " << p[j] << " outside [from, to)";
      ++hits[s];
      strata[j].push_back(s);
    }
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), static_cast<long>(n)) << "parameter " << j;
  }
  // the strata are paired at random, not in order or alike for both parameters
  EXPECT_NE(strata[0], strata[1]);
  EXPECT_FALSE(std::is_sorted(strata[0].begin(), strata[0].end()));
  // one point: its single stratum is the whole range
  const auto one = sweep_points(drawn(SweepDesign::kLatinHypercube, 1, 5));
  ASSERT_EQ(one.size(), 1u);
  EXPECT_GE(one[0][0], -2.0);
  EXPECT_LT(one[0][0], 3.0);
}

// The generator is ours (xoshiro256** seeded by splitmix64, doubles from the top 53 bits,
// rejection for integers, Fisher-Yates from the last position), so these points must never
// change: a resumed sweep depends on it. The expected values were computed by an independent
// Python transcription of that algorithm (from 0 to 1, so each value is the draw itself).
TEST(SweepPoints, DrawsAreThoseOfTheDocumentedGenerator) {
  SweepRequest r;
  r.design = SweepDesign::kRandom;
  r.points = 3;
  r.seed = 1;
  r.parameters.resize(2);
  for (SweepParameter& p : r.parameters) {
    p.from = 0.0;
    p.to = 1.0;
  }
  const std::vector<std::vector<double>> random = {{0x1.67e55eda1f8e2p-1, 0x1.0a76ab2c8e6c9p-1},
                                                   {0x1.25f12eac10548p-1, 0x1.90b871ef099a8p-2},
                                                   {0x1.64f491c534466p-1, 0x1.260918937fed0p-3}};
  EXPECT_EQ(sweep_points(r), random);
  r.design = SweepDesign::kLatinHypercube;
  r.points = 5;
  r.seed = 7;
  // strata: parameter 0 {1, 3, 0, 2, 4}, parameter 1 {0, 2, 1, 3, 4}
  const std::vector<std::vector<double>> lhs = {{0x1.97ba6a56cb767p-2, 0x1.68cbe597447a6p-3},
                                                {0x1.8c9271f4af40ap-1, 0x1.f60cfd9dcd7b0p-2},
                                                {0x1.8e251375646f4p-7, 0x1.3fab04da679d6p-2},
                                                {0x1.aefd0b0910592p-2, 0x1.4d7c623d94bdcp-1},
                                                {0x1.c2f0863c511d0p-1, 0x1.c958473204934p-1}};
  EXPECT_EQ(sweep_points(r), lhs);
}

// ---- the study at a point ----

const std::string kPointStudy = with_sweep(
    "  parameters:\n"
    "    - {path: linkage.coupler.mass, from: 1, to: 5, count: 3}\n"
    "    - {path: scene.omega1, values: [2, 4]}\n"
    "    - {path: 'loads.crank.force[1]', values: [-0.5]}\n");

TEST(PointStudy, SetsEachPathAndNothingElse) {
  const Study base = parse_study(kPointStudy, "sweep.yaml");
  const double values[] = {1.25, -7.5, 0.1};
  const Study point = point_study(base, values);
  EXPECT_EQ(point.fourbar().coupler.mass, 1.25);
  ASSERT_TRUE(std::holds_alternative<core::DrivenScene>(point.scene));
  EXPECT_EQ(std::get<core::DrivenScene>(point.scene).omega1, -7.5);
  EXPECT_EQ(point.fourbar().loads.crank.force[1], 0.1);
  EXPECT_EQ(point.name, base.name);
  EXPECT_EQ(point.source, "sweep.yaml");
  EXPECT_FALSE(point.sweep.has_value());
  EXPECT_FALSE(point.balance.has_value());
  // everything else as in the base study: its complete study file, every number "%.17g",
  // differs only in those three values
  Study expected = base;
  expected.fourbar().coupler.mass = 1.25;
  std::get<core::DrivenScene>(expected.scene).omega1 = -7.5;
  expected.fourbar().loads.crank.force[1] = 0.1;
  EXPECT_EQ(study_yaml(point, ""), study_yaml(expected, ""));
  EXPECT_EQ(point.method, base.method);
  EXPECT_EQ(point.tolerance, base.tolerance);
  // the base is untouched, and its own values are the file's
  EXPECT_EQ(base.fourbar().coupler.mass, 3.0);
  EXPECT_EQ(std::get<core::DrivenScene>(base.scene).omega1, 6.0);
  // the design's points set exactly their values ("%.17g" reads back to the same double)
  for (const auto& p : sweep_points(*base.sweep)) {
    const Study s = point_study(base, p);
    EXPECT_EQ(s.fourbar().coupler.mass, p[0]);
    EXPECT_EQ(std::get<core::DrivenScene>(s.scene).omega1, p[1]);
    EXPECT_EQ(s.fourbar().loads.crank.force[1], p[2]);
  }
  // a value that needs all 17 digits survives the text
  const double third = 1.0 / 3.0;
  const double fine[] = {third, 2.0, 1.2};
  EXPECT_EQ(point_study(base, fine).fourbar().coupler.mass, third);
}

TEST(PointStudy, InvalidValueIsReportedAtItsPlaceInTheFile) {
  const Study base = parse_study(kPointStudy, "sweep.yaml");
  const double negative_mass[] = {-1.0, 2.0, 0.0};
  try {
    point_study(base, negative_mass);
    FAIL() << "no error for a negative mass";
  } catch (const StudyError& e) {
    EXPECT_EQ(std::string(e.what()),
              "sweep.yaml:7:32: linkage.coupler.mass must be > 0 kg, got -1");
  }
  const double stopped_crank[] = {2.0, 0.0, 0.0};
  try {
    point_study(base, stopped_crank);
    FAIL() << "no error for omega1 = 0 in a driven scene";
  } catch (const StudyError& e) {
    EXPECT_EQ(e.line(), 13);
    EXPECT_EQ(e.column(), 11);
    EXPECT_NE(e.message().find("scene.omega1 must be != 0 rad/s"), std::string::npos) << e.what();
  }
  // a whole number swept to a fraction
  const Study samples =
      parse_study(one_parameter("scene.samples", "      values: [36]\n"), "sweep.yaml");
  const double fraction[] = {2.5};
  try {
    point_study(samples, fraction);
    FAIL() << "no error for 2.5 samples";
  } catch (const StudyError& e) {
    EXPECT_EQ(std::string(e.what()),
              "sweep.yaml:14:12: scene.samples must be a whole number, got '2.5'");
  }
  // a precondition, not a study mistake
  const double two[] = {1.0, 2.0};
  EXPECT_THROW(point_study(base, two), std::invalid_argument);
  EXPECT_THROW(point_study(parse_study(kStudy, "sweep.yaml"), two), std::invalid_argument);
}

TEST(PointStudy, BalanceIsSynthesisedForThePoint) {
  const Study base = parse_study(kStudy + "balance:\n  force: full\n" +
                                     "sweep:\n  parameters:\n"
                                     "    - {path: linkage.coupler.mass, values: [1, 6]}\n",
                                 "sweep.yaml");
  ASSERT_TRUE(base.balance.has_value());
  const double light[] = {1.0};
  const double heavy[] = {6.0};
  const Study a = point_study(base, light);
  const Study b = point_study(base, heavy);
  ASSERT_TRUE(a.balance.has_value());
  ASSERT_TRUE(b.balance.has_value());
  // counterweights on crank and rocker; the coupler is as swept
  EXPECT_EQ(a.balance->model.coupler.mass, 1.0);
  EXPECT_EQ(b.balance->model.coupler.mass, 6.0);
  // a heavier coupler needs heavier counterweights
  EXPECT_GT(b.balance->added_mass, a.balance->added_mass);
  EXPECT_GT(a.balance->added_mass, 0.0);
}

// each thread keeps the tree of the last study it set up; another study must not get it, and a
// failed point must not leave its value behind
TEST(PointStudy, AlternatingStudiesKeepTheirOwnValues) {
  const Study a = parse_study(kPointStudy, "a.yaml");
  const Study b = parse_study(one_parameter("linkage.frame"), "b.yaml");
  const double va[] = {2.5, 3.0, 0.25};
  const double bad[] = {-2.5, 3.0, 0.25};
  const double vb[] = {3.3};
  for (int round = 0; round < 2; ++round) {
    EXPECT_THROW(point_study(a, bad), StudyError);
    const Study pa = point_study(a, va);
    const Study pb = point_study(b, vb);
    EXPECT_EQ(pa.fourbar().coupler.mass, 2.5);
    EXPECT_EQ(pa.fourbar().frame_length, 3.2);
    EXPECT_EQ(pa.source, "a.yaml");
    EXPECT_EQ(pb.fourbar().frame_length, 3.3);
    EXPECT_EQ(pb.fourbar().coupler.mass, 3.0);
    EXPECT_EQ(std::get<core::DrivenScene>(pb.scene).omega1, 6.0);
    EXPECT_EQ(pb.source, "b.yaml");
  }
}

// point_study() is called from several threads at once
TEST(PointStudy, ThreadsDoNotInterfere) {
  const Study base = parse_study(kPointStudy, "sweep.yaml");
  constexpr int kThreads = 4, kCalls = 25;
  std::vector<int> wrong(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int c = 0; c < kCalls; ++c) {
        const double v[] = {1.0 + t + 0.01 * c, 1.0 + c, 0.5 * t};
        const Study s = point_study(base, v);
        const bool ok = s.fourbar().coupler.mass == v[0] &&
                        std::get<core::DrivenScene>(s.scene).omega1 == v[1] &&
                        s.fourbar().loads.crank.force[1] == v[2];
        if (!ok) ++wrong[static_cast<std::size_t>(t)];
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(wrong, std::vector<int>(kThreads, 0));
}

// ---- the example ----

TEST(SweepExample, PaperFourbarSweepIsA21By21Grid) {
  const Study study =
      load_study(std::string(BD_SOURCE_DIR) + "/studies/examples/paper-fourbar-sweep.yaml");
  ASSERT_TRUE(study.sweep.has_value());
  ASSERT_TRUE(study.balance.has_value());
  const SweepRequest& r = *study.sweep;
  EXPECT_EQ(r.design, SweepDesign::kGrid);
  EXPECT_EQ(r.points, 441);
  ASSERT_EQ(r.parameters.size(), 2u);
  EXPECT_EQ(r.parameters[0].path, "linkage.coupler.mass");
  EXPECT_EQ(r.parameters[1].path, "linkage.coupler.s");
  for (const SweepParameter& p : r.parameters) EXPECT_EQ(p.values.size(), 21u);
  EXPECT_EQ(r.parameters[0].values.front(), 1.0);
  EXPECT_EQ(r.parameters[0].values.back(), 5.0);
  EXPECT_EQ(r.parameters[1].values.front(), 0.5);
  EXPECT_EQ(r.parameters[1].values.back(), 2.5);
  const auto points = sweep_points(r);
  ASSERT_EQ(points.size(), 441u);
  EXPECT_EQ(points[0], (std::vector<double>{1.0, 0.5}));
  EXPECT_EQ(points[440], (std::vector<double>{5.0, 2.5}));
  // every point is a valid study (no bad-input rows); s comes back through e, f within ulps
  for (const auto& p : points) {
    const Study s = point_study(study, p);
    EXPECT_EQ(s.fourbar().coupler.mass, p[0]);
    EXPECT_NEAR(s.fourbar().coupler.s(), p[1], 4 * std::numeric_limits<double>::epsilon() * p[1]);
    EXPECT_NEAR(s.fourbar().coupler.sigma(), study.fourbar().coupler.sigma(), 1e-15);
    ASSERT_TRUE(s.balance.has_value());
  }
}

}  // namespace
}  // namespace bd::studies
