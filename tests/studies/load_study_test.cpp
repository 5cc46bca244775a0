// Loading and validating study files: every kind of mistake is one line FILE:LINE:COLUMN: message
// with the place of the offending value, and valid files load with their defaults.
#include "studies/load_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>

namespace bd::studies {
namespace {

// a valid study; line numbers below refer to this text
const std::string kBase =
    "name: t\n"                                                                 // 1
    "linkage:\n"                                                                // 2
    "  type: fourbar\n"                                                         // 3
    "  frame: 3.2\n"                                                            // 4
    "  branch: 1\n"                                                             // 5
    "  crank:\n"                                                                // 6
    "    length: 1.0\n"                                                         // 7
    "    mass: 2.1\n"                                                           // 8
    "    s: 0.6\n"                                                              // 9
    "    sigma: 0.3\n"                                                          // 10
    "    inertia: 1.1\n"                                                        // 11
    "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"  // 12
    "  rocker: {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"  // 13
    "scene:\n"                                                                  // 14
    "  type: free\n"                                                            // 15
    "  theta1: 1.0\n"                                                           // 16
    "  duration: 5.0\n";                                                        // 17

// kBase with the first occurrence of `from` replaced by `to` (which must occur)
std::string edit(const std::string& from, const std::string& to) {
  std::string text = kBase;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// the StudyError thrown for `text`; fails the test when none is thrown
StudyError error_of(const std::string& text) {
  try {
    parse_study(text, "study.yaml");
  } catch (const StudyError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return StudyError("none", 0, 0, "no error");
}

// checks place and text, and that what() is the one-line "file:line:col: message"
void expect_error(const std::string& text, int line, int column, const std::string& message) {
  const StudyError e = error_of(text);
  EXPECT_EQ(e.file(), "study.yaml");
  EXPECT_EQ(e.line(), line) << e.what();
  EXPECT_EQ(e.column(), column) << e.what();
  EXPECT_NE(e.message().find(message), std::string::npos)
      << "expected \"" << message << "\" in \"" << e.message() << "\"";
  const std::string what = e.what();
  EXPECT_EQ(what, "study.yaml:" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                      e.message());
  EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
}

TEST(LoadStudy, BaseIsValid) { EXPECT_NO_THROW(parse_study(kBase, "study.yaml")); }

TEST(LoadStudy, UnknownKeyNamesItAndListsTheAllowedOnes) {
  expect_error(edit("    mass: 2.1\n", "    mas: 2.1\n"), 8, 5,
               "unknown key 'mas' in linkage.crank; allowed keys: length, mass, s, sigma, e, f, "
               "inertia");
  expect_error(kBase + "colour: red\n", 18, 1,
               "unknown key 'colour' at the top level; allowed keys: name, linkage, loads, "
               "scene, method, tolerance");
  // a key of the other scene type
  expect_error(edit("  type: free\n", "  type: free\n  revolutions: 2\n"), 16, 3,
               "unknown key 'revolutions' in scene (type: free); allowed keys: type, theta1, "
               "omega1, duration, samples");
  // in a flow map
  expect_error(edit("sigma: 0.4,", "sigm: 0.4,"), 12, 46, "unknown key 'sigm' in linkage.coupler");
}

TEST(LoadStudy, WrongTypeNamesWhatWasExpectedAndWhatWasFound) {
  expect_error(edit("    length: 1.0\n", "    length: abc\n"), 7, 13,
               "linkage.crank.length must be a number in m, got 'abc'");
  // a scalar where a map is expected
  expect_error(edit("  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}",
                    "  coupler: 5"),
               12, 12, "linkage.coupler must be a map");
  // a map where a number is expected
  expect_error(edit("  frame: 3.2\n", "  frame: {a: 1}\n"), 4, 10,
               "linkage.frame must be a number in m, got a map");
  // a list where text is expected
  expect_error(edit("name: t\n", "name: [a, b]\n"), 1, 7, "name must be text, got a list");
  // an empty value is reported at its key
  expect_error(edit("    mass: 2.1\n", "    mass:\n"), 8, 5,
               "linkage.crank.mass must be a number in kg, got nothing");
  expect_error(kBase + "loads: {gravity: [0, -9.81, 1]}\n", 18, 18,
               "loads.gravity must be a list of 2 numbers");
}

TEST(LoadStudy, MissingRequiredKeyIsReportedAtItsMap) {
  expect_error(edit("    inertia: 1.1\n", ""), 6, 3,
               "linkage.crank: missing required key 'inertia'");
  expect_error(edit("  duration: 5.0\n", ""), 14, 1, "scene: missing required key 'duration'");
  expect_error(edit("name: t\n", ""), 1, 1, "missing required key 'name'");
  expect_error(edit("  branch: 1\n", ""), 2, 1, "linkage: missing required key 'branch'");
}

TEST(LoadStudy, NonPhysicalValuesAreReportedWhereTheyAre) {
  expect_error(edit("    length: 1.0\n", "    length: 0\n"), 7, 13,
               "linkage.crank.length must be > 0 m, got 0");
  expect_error(edit("    mass: 2.1\n", "    mass: -1\n"), 8, 11,
               "linkage.crank.mass must be > 0 kg, got -1");
  expect_error(edit("    inertia: 1.1\n", "    inertia: -0.5\n"), 11, 14,
               "linkage.crank.inertia must be >= 0 kg m^2, got -0.5");
  expect_error(edit("mass: 3.0,", "mass: -1.2,"), 12, 32,
               "linkage.coupler.mass must be > 0 kg, got -1.2");
  expect_error(edit("  frame: 3.2\n", "  frame: -3.2\n"), 4, 10,
               "linkage.frame must be > 0 m, got -3.2");
  expect_error(edit("    mass: 2.1\n", "    mass: .nan\n"), 8, 11,
               "linkage.crank.mass must be a finite number in kg, got '.nan'");
  expect_error(edit("    s: 0.6\n", "    s: -0.6\n"), 9, 8, "linkage.crank.s must be >= 0 m");
  expect_error(edit("  duration: 5.0\n", "  duration: 0\n"), 17, 13,
               "scene.duration must be > 0 s, got 0");
  expect_error(kBase + "  samples: 1\n", 18, 12, "scene.samples must be >= 2, got 1");
  expect_error(kBase + "  samples: 2.5\n", 18, 12, "scene.samples must be a whole number");
  expect_error(kBase + "tolerance: 0\n", 18, 12, "tolerance must be > 0");
}

TEST(LoadStudy, BranchMustBePlusOrMinusOne) {
  expect_error(edit("  branch: 1\n", "  branch: 2\n"), 5, 11,
               "linkage.branch must be +1 or -1, got '2'");
}

TEST(LoadStudy, YamlSyntaxErrorsBecomeOneLineErrorsWithTheirPlace) {
  expect_error(edit("  frame: 3.2\n", "   frame: 3.2\n"), 4, 9, "illegal map value");
  expect_error(edit("inertia: 3.1}", "inertia: 3.1"), 13, 9, "end of map flow not found");
}

TEST(LoadStudy, LinkageThatCannotAssembleAtTheInitialAngle) {
  // frame 10: |A1A3| >= 9 > l2 + l3 = 5 at every crank angle
  expect_error(edit("  frame: 3.2\n", "  frame: 10\n"), 16, 11,
               "the linkage cannot be assembled at the initial crank angle: loop cannot close "
               "at theta1 = 1 rad");
  // theta1 defaulted to 0: reported at the scene
  const std::string text = edit("  theta1: 1.0\n", "");
  const auto at = text.find("  frame: 3.2\n");
  std::string no_theta = text;
  no_theta.replace(at, 13, "  frame: 10\n");
  expect_error(no_theta, 14, 1, "cannot be assembled");
}

TEST(LoadStudy, CentreOfMassNeedsExactlyOnePair) {
  expect_error(edit("    sigma: 0.3\n", "    sigma: 0.3\n    e: 0.5\n"), 11, 5,
               "linkage.crank gives its centre of mass both as {s, sigma} and as {e, f}");
  expect_error(edit("    sigma: 0.3\n", ""), 9, 5,
               "linkage.crank.s is given without sigma; give both s and sigma");
  expect_error(edit("    s: 0.6\n    sigma: 0.3\n", "    f: 0.1\n"), 9, 5,
               "linkage.crank.f is given without e");
  expect_error(edit("    s: 0.6\n    sigma: 0.3\n", ""), 6, 3,
               "linkage.crank: missing the centre of mass");
}

TEST(LoadStudy, OtherMistakes) {
  expect_error("", 1, 1, "the study file is empty");
  expect_error("- a\n- b\n", 1, 1, "must be a map");
  expect_error(kBase + "name: u\n", 18, 1, "duplicate key 'name' at the top level");
  expect_error(edit("  type: fourbar\n", "  type: sixbar\n"), 3, 9,
               "linkage.type 'sixbar' is not supported; expected fourbar");
  expect_error(edit("  type: free\n", "  type: frozen\n"), 15, 9,
               "scene.type must be free or driven, got 'frozen'");
  expect_error(edit("name: t\n", "name: ../x\n"), 1, 7, "name may use only letters");
  expect_error(kBase + "method: magic\n", 18, 9,
               "unknown method 'magic'; expected one of auto, opened-loop, complex-masses, "
               "mass-matrix");
}

TEST(LoadStudy, EveryFormulationCanBeRequested) {
  for (const char* name : {"mass-matrix", "opened-loop", "complex-masses"}) {
    const Study s = parse_study(kBase + "method: " + name + "\n", "study.yaml");
    ASSERT_TRUE(s.formulation.has_value()) << name;
    EXPECT_STREQ(core::to_string(*s.formulation), name);
    EXPECT_EQ(s.method_name(), name);
  }
  EXPECT_FALSE(parse_study(kBase + "method: auto\n", "study.yaml").formulation.has_value());
}

TEST(LoadStudy, DrivenSceneNeedsANonZeroSpeed) {
  const std::string driven =
      edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n", "  type: driven\n  omega1: 0\n");
  expect_error(driven, 16, 11, "scene.omega1 must be != 0 rad/s");
  expect_error(edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n", "  type: driven\n"), 14, 1,
               "scene: missing required key 'omega1'");
  expect_error(edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n",
                    "  type: driven\n  omega1: 1\n  duration: 5\n"),
               17, 3, "unknown key 'duration' in scene (type: driven)");
}

TEST(LoadStudy, DefaultsApply) {
  const Study s = parse_study(kBase, "study.yaml");
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.source, "study.yaml");
  EXPECT_FALSE(s.formulation.has_value());
  EXPECT_EQ(s.method_name(), "auto");
  EXPECT_EQ(s.tolerance, 1e-10);
  EXPECT_EQ(s.model.loads.gravity, Vec2(0, 0));
  EXPECT_EQ(s.model.loads.crank.force, Vec2(0, 0));
  EXPECT_EQ(s.model.loads.rocker.moment, 0.0);
  const auto* free = std::get_if<core::FreeScene>(&s.scene);
  ASSERT_NE(free, nullptr);
  EXPECT_EQ(free->theta1, 1.0);
  EXPECT_EQ(free->omega1, 0.0);
  EXPECT_EQ(free->duration, 5.0);
  EXPECT_EQ(free->samples, 501);

  const Study d = parse_study(
      edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n", "  type: driven\n  omega1: 2\n"),
      "study.yaml");
  const auto* driven = std::get_if<core::DrivenScene>(&d.scene);
  ASSERT_NE(driven, nullptr);
  EXPECT_EQ(driven->theta1, 0.0);
  EXPECT_EQ(driven->omega1, 2.0);
  EXPECT_EQ(driven->revolutions, 1);
  EXPECT_EQ(driven->samples, 360);

  // partial loads: only what is given is non-zero
  const Study l = parse_study(kBase + "loads:\n  coupler: {moment: 0.5}\n", "study.yaml");
  EXPECT_EQ(l.model.loads.coupler.moment, 0.5);
  EXPECT_EQ(l.model.loads.coupler.force, Vec2(0, 0));
  EXPECT_EQ(l.model.loads.gravity, Vec2(0, 0));
}

TEST(LoadStudy, CartesianCentreOfMass) {
  const Study s =
      parse_study(edit("    s: 0.6\n    sigma: 0.3\n", "    e: 0.5\n    f: -0.1\n"), "study.yaml");
  EXPECT_EQ(s.model.crank.e, 0.5);
  EXPECT_EQ(s.model.crank.f, -0.1);
  const Study m = parse_study(edit("  branch: 1\n", "  branch: -1\n"), "study.yaml");
  EXPECT_EQ(m.model.branch, core::Branch::kMinus);
}

TEST(LoadStudy, ExamplesLoad) {
  const Study s = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  EXPECT_EQ(s.name, "paper-fourbar");
  EXPECT_EQ(s.model.frame_length, 3.2);
  EXPECT_EQ(s.model.branch, core::Branch::kPlus);
  EXPECT_NEAR(s.model.crank.e, 0.6 * std::cos(0.3), 1e-15);
  EXPECT_NEAR(s.model.rocker.f, 1.66 * std::sin(-0.4), 1e-15);
  EXPECT_EQ(s.model.coupler.inertia, 3.1);
  EXPECT_EQ(s.model.loads.coupler.force, Vec2(1.3, -1.4));
  EXPECT_EQ(s.model.loads.rocker.moment, 0.19);
  EXPECT_EQ(s.model.loads.gravity, Vec2(0, 0));
  const auto& free = std::get<core::FreeScene>(s.scene);
  EXPECT_EQ(free.theta1, 1.0);
  EXPECT_EQ(free.duration, 5.0);
  EXPECT_EQ(free.samples, 501);

  const Study d = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  EXPECT_EQ(d.name, "paper-fourbar-driven");
  EXPECT_EQ(d.model.loads.crank.force, Vec2(0, 0));
  const auto& driven = std::get<core::DrivenScene>(d.scene);
  EXPECT_DOUBLE_EQ(driven.omega1, 2 * M_PI);
  EXPECT_EQ(driven.theta1, 0.0);
  EXPECT_EQ(driven.revolutions, 1);
  EXPECT_EQ(driven.samples, 360);
}

TEST(LoadStudy, UnreadableFileNamesIt) {
  try {
    load_study("/nonexistent/study.yaml");
    FAIL() << "no error";
  } catch (const StudyError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/study.yaml: cannot open the study file");
    EXPECT_EQ(e.line(), 0);
  }
  // a StudyError is a bd::InputError
  EXPECT_THROW(load_study("/nonexistent/study.yaml"), InputError);
}

// ---- linkage.counter_rotations ----

TEST(LoadStudy, CounterRotationsOnTheLinkage) {
  const Study s = parse_study(edit("inertia: 2.1}\n",
                                   "inertia: 2.1}\n"
                                   "  counter_rotations:\n"
                                   "    crank: {inertia: 0.5, at: [0, -1]}\n"
                                   "    rocker: {inertia: 1.5, at: [3.2, -2]}\n"),
                              "study.yaml");
  EXPECT_EQ(s.model.counter_rotations.crank.inertia, 0.5);
  EXPECT_EQ(s.model.counter_rotations.crank.at, Vec2(0, -1));
  EXPECT_EQ(s.model.counter_rotations.rocker.inertia, 1.5);
  EXPECT_EQ(s.model.counter_rotations.rocker.at, Vec2(3.2, -2));
  EXPECT_FALSE(s.balance.has_value());

  // each side optional; none by default
  const Study one =
      parse_study(edit("inertia: 2.1}\n",
                       "inertia: 2.1}\n  counter_rotations: {rocker: {inertia: 1, at: [4, 0]}}\n"),
                  "study.yaml");
  EXPECT_EQ(one.model.counter_rotations.crank.inertia, 0.0);
  EXPECT_EQ(one.model.counter_rotations.rocker.inertia, 1.0);
  EXPECT_FALSE(core::has_counter_rotations(parse_study(kBase, "study.yaml").model));
}

TEST(LoadStudy, CounterRotationMistakes) {
  auto with = [](const std::string& lines) {
    return edit("inertia: 2.1}\n", "inertia: 2.1}\n  counter_rotations:\n" + lines);  // line 15 on
  };
  expect_error(with("    crank: {inertia: -1, at: [0, -1]}\n"), 15, 22,
               "linkage.counter_rotations.crank.inertia must be >= 0 kg m^2, got -1");
  expect_error(with("    rocker: {inertia: 1, at: [3.2, 0]}\n"), 15, 30,
               "linkage.counter_rotations.rocker.at must differ from the rocker's pivot A3 = (3.2, "
               "0) m, got [3.2, 0]");
  expect_error(with("    crank: {inertia: 1, at: [0, 0]}\n"), 15, 29,
               "linkage.counter_rotations.crank.at must differ from the crank's pivot A0");
  expect_error(with("    crank: {inertia: 1}\n"), 15, 5,
               "linkage.counter_rotations.crank: missing required key 'at'");
  expect_error(
      with("    crank: {inertia: 1, at: [0, -1], radius: 2}\n"), 15, 38,
      "unknown key 'radius' in linkage.counter_rotations.crank; allowed keys: inertia, at");
  expect_error(with("    coupler: {inertia: 1, at: [0, -1]}\n"), 15, 5,
               "unknown key 'coupler' in linkage.counter_rotations; allowed keys: crank, rocker");
  expect_error(with("    crank: {inertia: 1, at: [0]}\n"), 15, 29,
               "linkage.counter_rotations.crank.at must be a list of 2 numbers [x, y] in m");
}

// ---- balance ----

// kBase with a Berkof coupler (f2 = 0, I2 = m2 e2 (l2 - e2) = 3 * 1.2 * 1.8)
std::string berkof() {
  return edit("  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n",
              "  coupler: {length: 3.0, mass: 3.0, e: 1.2, f: 0.0, inertia: 6.48}\n");
}

TEST(LoadStudy, ForceBalanceAloneSynthesisesTheDesignAtLoadTime) {
  const Study s = parse_study(kBase + "balance: {force: full}\n", "study.yaml");
  ASSERT_TRUE(s.balance.has_value());
  const BalancedDesign& b = *s.balance;
  EXPECT_TRUE(b.request.force);
  EXPECT_FALSE(b.request.moment);
  EXPECT_TRUE(b.conditions.force_balanced()) << b.conditions.text();
  ASSERT_TRUE(b.crank_counterweight.has_value());
  ASSERT_TRUE(b.rocker_counterweight.has_value());
  // default: point masses at distances l1 and l3 from their pivots
  EXPECT_NEAR(b.crank_counterweight->distance, 1.0, 1e-15);
  EXPECT_NEAR(b.rocker_counterweight->distance, 2.0, 1e-15);
  EXPECT_EQ(b.crank_counterweight->inertia, 0.0);
  EXPECT_DOUBLE_EQ(b.added_mass, b.crank_counterweight->mass + b.rocker_counterweight->mass);
  EXPECT_GT(b.model.crank.mass, s.model.crank.mass);  // the original is kept as it was
  EXPECT_EQ(s.model.crank.mass, 2.1);
  EXPECT_EQ(b.model.coupler.mass, s.model.coupler.mass);
  EXPECT_FALSE(core::has_counter_rotations(b.model));

  // `balance:` with nothing under it: the defaults (force full, moment none)
  const Study d = parse_study(kBase + "balance:\n", "study.yaml");
  ASSERT_TRUE(d.balance.has_value());
  EXPECT_TRUE(d.balance->request.force);
  EXPECT_FALSE(d.balance->request.moment);
  EXPECT_EQ(d.balance->model.crank.mass, b.model.crank.mass);

  // force: none leaves the design as it is
  const Study n = parse_study(kBase + "balance: {force: none}\n", "study.yaml");
  ASSERT_TRUE(n.balance.has_value());
  EXPECT_FALSE(n.balance->crank_counterweight.has_value());
  EXPECT_EQ(n.balance->model.crank.mass, 2.1);
  EXPECT_EQ(n.balance->added_mass, 0.0);
}

TEST(LoadStudy, CounterweightSpecsReachTheSynthesis) {
  const Study s = parse_study(kBase +
                                  "balance:\n"
                                  "  counterweights:\n"
                                  "    crank:  {mass: 2.0}\n"
                                  "    rocker: {distance: 0.8}\n",
                              "study.yaml");
  ASSERT_TRUE(s.balance && s.balance->crank_counterweight && s.balance->rocker_counterweight);
  EXPECT_EQ(s.balance->request.crank_counterweight.mass, 2.0);
  EXPECT_EQ(s.balance->crank_counterweight->mass, 2.0);
  EXPECT_EQ(s.balance->rocker_counterweight->distance, 0.8);
  EXPECT_TRUE(s.balance->conditions.force_balanced());

  // discs: of a given size (position solved), or at a given distance (mass and radius solved)
  const Study d = parse_study(kBase +
                                  "balance:\n"
                                  "  counterweights:\n"
                                  "    crank:  {shape: disc, radius: 0.12, thickness: 0.02, "
                                  "density: 7850}\n"
                                  "    rocker: {shape: disc, distance: 0.8, thickness: 0.03}\n",
                              "study.yaml");
  const BalanceRequest& q = d.balance->request;
  EXPECT_EQ(q.crank_counterweight.shape, balance::CounterweightShape::kDisc);
  EXPECT_EQ(q.crank_counterweight.radius, 0.12);
  EXPECT_EQ(q.crank_counterweight.thickness, 0.02);
  EXPECT_EQ(q.crank_counterweight.density, 7850.0);
  EXPECT_EQ(q.rocker_counterweight.thickness, 0.03);
  EXPECT_EQ(q.rocker_counterweight.density, 7850.0);  // default: steel
  const balance::Counterweight& c = *d.balance->crank_counterweight;
  EXPECT_NEAR(c.mass, 7850 * M_PI * 0.12 * 0.12 * 0.02, 1e-12);
  EXPECT_EQ(c.radius, 0.12);
  EXPECT_NEAR(c.inertia, 0.5 * c.mass * 0.12 * 0.12, 1e-15);
  EXPECT_EQ(d.balance->rocker_counterweight->distance, 0.8);
  EXPECT_GT(d.balance->rocker_counterweight->radius, 0.0);
  EXPECT_TRUE(d.balance->conditions.force_balanced());
}

TEST(LoadStudy, MomentBalanceOfABerkofCoupler) {
  const Study s = parse_study(berkof() + "balance: {force: full, moment: full}\n", "study.yaml");
  ASSERT_TRUE(s.balance.has_value());
  const BalancedDesign& b = *s.balance;
  EXPECT_TRUE(b.conditions.moment_balanced()) << b.conditions.text();
  // default shafts (0, -l1) and (l4, -l3)
  EXPECT_EQ(b.model.counter_rotations.crank.at, Vec2(0, -1.0));
  EXPECT_EQ(b.model.counter_rotations.rocker.at, Vec2(3.2, -2.0));
  EXPECT_GT(b.model.counter_rotations.crank.inertia, 0.0);
  const double J =
      b.model.counter_rotations.crank.inertia + b.model.counter_rotations.rocker.inertia;
  const double counterweights = b.added_inertia - J;
  EXPECT_GE(counterweights, 0.0);  // point masses: m d^2 about the pivots

  const Study at = parse_study(berkof() +
                                   "balance:\n"
                                   "  moment: full\n"
                                   "  counter_rotations:\n"
                                   "    crank:  {at: [0.0, -0.5]}\n"
                                   "    rocker: {at: [3.2, 1.5]}\n",
                               "study.yaml");
  EXPECT_EQ(at.balance->model.counter_rotations.crank.at, Vec2(0, -0.5));
  EXPECT_EQ(at.balance->model.counter_rotations.rocker.at, Vec2(3.2, 1.5));
}

TEST(LoadStudy, BalanceMistakesAreReportedWhereTheyAre) {
  // the balance layer's own verdict, at the `moment` value
  {
    const StudyError e = error_of(kBase + "balance:\n  force: full\n  moment: full\n");
    EXPECT_EQ(e.line(), 20);
    EXPECT_EQ(e.column(), 11);
    EXPECT_EQ(e.message().rfind("balance.moment: full is not possible: ", 0), 0u) << e.what();
    EXPECT_NE(e.message().find("Berkof coupler"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  expect_error(kBase + "balance: {force: none, moment: full}\n", 18, 32,
               "balance.moment: full needs balance.force: full");
  expect_error(kBase + "balance: {force: partial}\n", 18, 18,
               "balance.force must be full or none, got 'partial'");
  expect_error(kBase + "balance: {moment: half}\n", 18, 19,
               "balance.moment must be full or none, got 'half'");
  expect_error(kBase + "balance: {torque: full}\n", 18, 11,
               "unknown key 'torque' in balance; allowed keys: force, moment, counterweights, "
               "counter_rotations");
  expect_error(kBase + "balance: full\n", 18, 10, "balance must be a map");
  const std::string cw = kBase + "balance:\n  counterweights:\n";  // the side is line 20
  expect_error(cw + "    crank: {weight: 2}\n", 20, 13,
               "unknown key 'weight' in balance.counterweights.crank; allowed keys: shape, mass, "
               "distance, radius, thickness, density");
  expect_error(cw + "    coupler: {mass: 2}\n", 20, 5,
               "unknown key 'coupler' in balance.counterweights; allowed keys: crank, rocker");
  expect_error(cw + "    crank: {mass: -1}\n", 20, 19,
               "balance.counterweights.crank.mass must be > 0 kg, got -1");
  expect_error(cw + "    rocker: {distance: 0}\n", 20, 24,
               "balance.counterweights.rocker.distance must be > 0 m, got 0");
  expect_error(cw + "    crank: {mass: 2, distance: 1}\n", 20, 22,
               "balance.counterweights.crank: give at most one of mass, distance and radius");
  expect_error(cw + "    crank: {radius: 0.1}\n", 20, 13,
               "balance.counterweights.crank.radius needs shape: disc");
  expect_error(cw + "    crank: {shape: cube}\n", 20, 20,
               "balance.counterweights.crank.shape must be point or disc, got 'cube'");
  expect_error(cw + "    crank: {shape: disc, density: -7850}\n", 20, 35,
               "balance.counterweights.crank.density must be > 0 kg/m^3, got -7850");
  expect_error(cw + "    crank: {mass: abc}\n", 20, 19,
               "balance.counterweights.crank.mass must be a number in kg, got 'abc'");
  // keys that would be ignored are errors
  expect_error(kBase + "balance:\n  force: none\n  counterweights: {crank: {mass: 2}}\n", 20, 3,
               "balance.counterweights are used only with balance.force: full");
  expect_error(kBase + "balance:\n  counter_rotations: {crank: {at: [0, -1]}}\n", 19, 3,
               "balance.counter_rotations are used only with balance.moment: full");
  const std::string cr = berkof() + "balance:\n  moment: full\n  counter_rotations:\n";  // line 21
  expect_error(cr + "    crank: {at: [0, 0]}\n", 21, 17,
               "balance.counter_rotations.crank.at must differ from the crank's pivot A0");
  expect_error(cr + "    rocker: {at: [3.2, 0]}\n", 21, 18,
               "balance.counter_rotations.rocker.at must differ from the rocker's pivot A3");
  expect_error(cr + "    rocker: {inertia: 2, at: [3.2, -1]}\n", 21, 14,
               "unknown key 'inertia' in balance.counter_rotations.rocker; allowed keys: at");
  expect_error(cr + "    rocker: {}\n", 21, 5,
               "balance.counter_rotations.rocker: missing required key 'at'");
  // balanced.yaml is named <name>-balanced, which must still be a valid name
  expect_error(edit("name: t\n", "name: " + std::string(92, 'a') + "\n") + "balance:\n", 1, 7,
               "name must have at most 91 characters in a study with a balance section");
  EXPECT_NO_THROW(
      parse_study(edit("name: t\n", "name: " + std::string(92, 'a') + "\n"), "study.yaml"));
}

TEST(LoadStudy, BalanceExamplesLoad) {
  const Study f =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  ASSERT_TRUE(f.balance.has_value());
  EXPECT_TRUE(f.balance->conditions.force_balanced());
  EXPECT_FALSE(f.balance->request.moment);
  const Study m = load_study(BD_SOURCE_DIR "/studies/examples/berkof-inline-moment-balanced.yaml");
  ASSERT_TRUE(m.balance.has_value());
  EXPECT_TRUE(m.balance->conditions.moment_balanced());
  EXPECT_EQ(m.model.coupler.inertia, 6.48);
}

}  // namespace
}  // namespace bd::studies
