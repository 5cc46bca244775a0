// Loading and validating study files: every kind of mistake is one line FILE:LINE:COLUMN: message
// with the place of the offending value, and valid files load with their defaults.
#include "studies/study/load_study.hpp"
#include "studies/study/method.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>

#include "tests/support/study_errors.hpp"

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
  return bd::testing::study_error_of(text, "study.yaml");
}

// checks place and text, and that what() is the one-line "file:line:col: message"
void expect_error(const std::string& text, int line, int column, const std::string& message) {
  bd::testing::expect_study_error(text, "study.yaml", line, column, message);
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
               "linkage.crank.inertia must be >= 0 kg m², got -0.5");
  expect_error(edit("mass: 3.0,", "mass: -1.2,"), 12, 32,
               "linkage.coupler.mass must be > 0 kg, got -1.2");
  expect_error(edit("  frame: 3.2\n", "  frame: -3.2\n"), 4, 10,
               "linkage.frame must be > 0 m, got -3.2");
  // the value as a person reads it (the shortest text that reads back as it), not 17 digits
  for (const char* written : {"-0.1", "-210 g"}) {
    EXPECT_EQ(bd::testing::study_error_of(
                  edit("    mass: 2.1\n", std::string("    mass: ") + written + "\n"), "s.yaml")
                  .message(),
              std::string("linkage.crank.mass must be > 0 kg, got ") +
                  (written[1] == '0' ? "-0.1" : "-0.21"));
  }
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
  // yaml-cpp's words said as what to look at, its words kept
  expect_error(edit("  frame: 3.2\n", "   frame: 3.2\n"), 4, 9,
               "a 'key: value' where none can be: the keys of one map line up, so check this "
               "line's indentation against the keys above it; a value holding ': ' needs quotes "
               "(YAML: illegal map value)");
  expect_error(edit("inertia: 3.1}", "inertia: 3.1"), 13, 9,
               "a '{' is not closed by a '}' (YAML: end of map flow not found)");
  expect_error(edit("  coupler: {", "  coupler: [{"), 13, 3,
               "a '[' is not closed by a ']' (YAML: end of sequence flow not found)");
  // a quote left open takes the keys below as text up to the next quote, which YAML allows
  // (as a valid document missing its keys, or an error where the next quote ends it)
  expect_error(edit("name: t\n", "name: \"t\n") + "  samples: 9  # \"9\n", 1, 7,
               "this quoted value is not closed on its line: it runs on to line 2 ('linkage:') "
               "and takes it as text; close the quote");
  expect_error(edit("name: t\n", "name: \"t\n") + "  samples: \"9\"\n", 1, 7,
               "it runs on to line 2 ('linkage:')");
  expect_error(edit("  type: free\n", "  type: 'free\n") + "  samples: 'x'\n", 15, 9,
               "it runs on to line 16 ('theta1: 1.0')");
  // on the last line, where yaml-cpp ends the value at the file's end without a word
  expect_error(kBase + "method: \"auto\n", 18, 9,
               "this quoted value is not closed: no closing quote before the end of the file");
  // a quoted value may run on over lines deeper than its key, and hold quotes of the other kind
  // or doubled
  // or doubled (read whole, then refused as a name for its characters)
  expect_error(edit("name: t\n", "name: \"a \\\" b\n  c: d 'e'\"\n"), 1, 7,
               "got 'a \" b c: d 'e''");
  expect_error(edit("name: t\n", "name: 'it''s\n  - x'\n"), 1, 7, "got 'it's - x'");
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
    ASSERT_TRUE(formulation_of(s.method).has_value()) << name;
    EXPECT_STREQ(core::to_string(*formulation_of(s.method)), name);
    EXPECT_EQ(s.method_name(), name);
  }
  EXPECT_EQ(parse_study(kBase + "method: auto\n", "study.yaml").method, Method::kAuto);
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
  EXPECT_EQ(s.method, Method::kAuto);
  EXPECT_EQ(s.method_name(), "auto");
  EXPECT_EQ(s.tolerance, 1e-10);
  EXPECT_EQ(s.fourbar().loads.gravity, Vec2(0, 0));
  EXPECT_EQ(s.fourbar().loads.crank.force, Vec2(0, 0));
  EXPECT_EQ(s.fourbar().loads.rocker.moment, 0.0);
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
  EXPECT_EQ(l.fourbar().loads.coupler.moment, 0.5);
  EXPECT_EQ(l.fourbar().loads.coupler.force, Vec2(0, 0));
  EXPECT_EQ(l.fourbar().loads.gravity, Vec2(0, 0));
}

TEST(LoadStudy, CartesianCentreOfMass) {
  const Study s =
      parse_study(edit("    s: 0.6\n    sigma: 0.3\n", "    e: 0.5\n    f: -0.1\n"), "study.yaml");
  EXPECT_EQ(s.fourbar().crank.e, 0.5);
  EXPECT_EQ(s.fourbar().crank.f, -0.1);
  const Study m = parse_study(edit("  branch: 1\n", "  branch: -1\n"), "study.yaml");
  EXPECT_EQ(m.fourbar().branch, core::Branch::kMinus);
}

TEST(LoadStudy, ExamplesLoad) {
  const Study s = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  EXPECT_EQ(s.name, "paper-fourbar");
  EXPECT_EQ(s.fourbar().frame_length, 3.2);
  EXPECT_EQ(s.fourbar().branch, core::Branch::kPlus);
  EXPECT_NEAR(s.fourbar().crank.e, 0.6 * std::cos(0.3), 1e-15);
  EXPECT_NEAR(s.fourbar().rocker.f, 1.66 * std::sin(-0.4), 1e-15);
  EXPECT_EQ(s.fourbar().coupler.inertia, 3.1);
  EXPECT_EQ(s.fourbar().loads.coupler.force, Vec2(1.3, -1.4));
  EXPECT_EQ(s.fourbar().loads.rocker.moment, 0.19);
  EXPECT_EQ(s.fourbar().loads.gravity, Vec2(0, 0));
  const auto& free = std::get<core::FreeScene>(s.scene);
  EXPECT_EQ(free.theta1, 1.0);
  EXPECT_EQ(free.duration, 5.0);
  EXPECT_EQ(free.samples, 501);

  const Study d = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  EXPECT_EQ(d.name, "paper-fourbar-driven");
  EXPECT_EQ(d.fourbar().loads.crank.force, Vec2(0, 0));
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
  EXPECT_EQ(s.fourbar().counter_rotations.crank.inertia, 0.5);
  EXPECT_EQ(s.fourbar().counter_rotations.crank.at, Vec2(0, -1));
  EXPECT_EQ(s.fourbar().counter_rotations.rocker.inertia, 1.5);
  EXPECT_EQ(s.fourbar().counter_rotations.rocker.at, Vec2(3.2, -2));
  EXPECT_FALSE(s.balance.has_value());

  // each side optional; none by default
  const Study one =
      parse_study(edit("inertia: 2.1}\n",
                       "inertia: 2.1}\n  counter_rotations: {rocker: {inertia: 1, at: [4, 0]}}\n"),
                  "study.yaml");
  EXPECT_EQ(one.fourbar().counter_rotations.crank.inertia, 0.0);
  EXPECT_EQ(one.fourbar().counter_rotations.rocker.inertia, 1.0);
  EXPECT_FALSE(core::has_counter_rotations(parse_study(kBase, "study.yaml").fourbar()));
}

TEST(LoadStudy, CounterRotationMistakes) {
  auto with = [](const std::string& lines) {
    return edit("inertia: 2.1}\n", "inertia: 2.1}\n  counter_rotations:\n" + lines);  // line 15 on
  };
  expect_error(with("    crank: {inertia: -1, at: [0, -1]}\n"), 15, 22,
               "linkage.counter_rotations.crank.inertia must be >= 0 kg m², got -1");
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
  const balance::BalancedDesign& b = *s.balance;
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
  EXPECT_GT(b.model.crank.mass, s.fourbar().crank.mass);  // the original is kept as it was
  EXPECT_EQ(s.fourbar().crank.mass, 2.1);
  EXPECT_EQ(b.model.coupler.mass, s.fourbar().coupler.mass);
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
  const balance::BalanceRequest& q = d.balance->request;
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
  const balance::BalancedDesign& b = *s.balance;
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
  EXPECT_EQ(m.fourbar().coupler.inertia, 6.48);
}

// ---- optimize ----

// kBase in a driven scene (same line numbers: lines 15-17 stay three lines)
std::string driven() {
  return edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n",
              "  type: driven\n  theta1: 1.0\n  omega1: 6.283185307179586\n");
}

// a complete optimize section from line 18
const std::string kOptimize =
    "optimize:\n"                                                                   // 18
    "  algorithm: slsqp\n"                                                          // 19
    "  objective: {Msh_rms: 1.0, tau_rms: 0.5}\n"                                   // 20
    "  constraints:\n"                                                              // 21
    "    force_balance: true\n"                                                     // 22
    "    Fsh_rms: 0.2\n"                                                            // 23
    "    added_mass: 6.0\n"                                                         // 24
    "  variables:\n"                                                                // 25
    "    counterweights:\n"                                                         // 26
    "      crank: {mass_max: 8.0, distance_max: 0.9}\n"                             // 27
    "      rocker: {mass_max: 9.0, shape: disc, thickness: 0.03, density: 7000}\n"  // 28
    "    links:\n"                                                                  // 29
    "      coupler: {mass: [2.0, 4.0], inertia: [1.0, 8.0]}\n"                      // 30
    "  max_evaluations: 500\n"                                                      // 31
    "  tolerance: 1.0e-7\n"                                                         // 32
    "  pareto: {first: Fsh_rms, second: Msh_rms, points: 5}\n";                     // 33

// driven() + kOptimize with the first occurrence of `from` in the section replaced by `to`
std::string opt_edit(const std::string& from, const std::string& to) {
  std::string text = kOptimize;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return driven() + text;
}

// a minimal optimize section from line 18 (variables at line 20)
const std::string kMinimal =
    "optimize:\n"                                 // 18
    "  objective: {Msh_rms: 1}\n"                 // 19
    "  variables:\n"                              // 20
    "    counterweights: {crank: , rocker: }\n";  // 21

TEST(LoadStudy, OptimizeSectionReadsEveryKey) {
  const Study s = parse_study(driven() + kOptimize, "study.yaml");
  ASSERT_TRUE(s.optimize.has_value());
  EXPECT_FALSE(s.balance.has_value());
  const OptimizeRequest& r = *s.optimize;
  EXPECT_EQ(r.options.algorithm, optimize::Algorithm::kSlsqp);
  EXPECT_EQ(r.options.max_evaluations, 500);
  EXPECT_EQ(r.options.relative_tolerance, 1e-7);
  ASSERT_EQ(r.objective.size(), 2u);
  EXPECT_EQ(r.objective[0].metric, optimize::Metric::kMshRms);
  EXPECT_EQ(r.objective[0].weight, 1.0);
  EXPECT_EQ(r.objective[1].metric, optimize::Metric::kTauRms);
  EXPECT_EQ(r.objective[1].weight, 0.5);
  EXPECT_TRUE(r.force_balance);
  ASSERT_EQ(r.limits.size(), 2u);
  EXPECT_EQ(r.limits[0].metric, optimize::Metric::kFshRms);
  EXPECT_EQ(r.limits[0].value, 0.2);
  EXPECT_EQ(r.limits[1].metric, optimize::Metric::kAddedMass);
  EXPECT_EQ(r.limits[1].value, 6.0);
  ASSERT_EQ(r.counterweights.size(), 2u);
  EXPECT_EQ(r.counterweights[0].link, 1);
  EXPECT_EQ(r.counterweights[0].mass_max, 8.0);
  EXPECT_EQ(r.counterweights[0].distance_max, 0.9);
  EXPECT_EQ(r.counterweights[0].shape, balance::CounterweightShape::kPoint);
  EXPECT_EQ(r.counterweights[1].link, 3);
  EXPECT_EQ(r.counterweights[1].mass_max, 9.0);
  EXPECT_EQ(r.counterweights[1].distance_max, 2.0);  // default: the rocker's length
  EXPECT_EQ(r.counterweights[1].shape, balance::CounterweightShape::kDisc);
  EXPECT_EQ(r.counterweights[1].thickness, 0.03);
  EXPECT_EQ(r.counterweights[1].density, 7000.0);
  using P = optimize::LinkParameterVariable::Parameter;
  ASSERT_EQ(r.link_parameters.size(), 2u);
  EXPECT_EQ(r.link_parameters[0].link, 2);
  EXPECT_EQ(r.link_parameters[0].parameter, P::kMass);
  EXPECT_EQ(r.link_parameters[0].lower, 2.0);
  EXPECT_EQ(r.link_parameters[0].upper, 4.0);
  EXPECT_EQ(r.link_parameters[1].parameter, P::kInertia);
  EXPECT_EQ(r.link_parameters[1].upper, 8.0);
  ASSERT_TRUE(r.pareto.has_value());
  EXPECT_EQ(r.pareto->first, optimize::Metric::kFshRms);
  EXPECT_EQ(r.pareto->second, optimize::Metric::kMshRms);
  EXPECT_EQ(r.pareto->points, 5);

  // the design problem: the study's model, scene, tolerance and the formulation its run uses
  const optimize::DesignProblem p = design_problem(s);
  EXPECT_EQ(p.original.coupler.mass, s.fourbar().coupler.mass);
  EXPECT_TRUE(std::holds_alternative<core::DrivenScene>(p.scene));
  EXPECT_EQ(p.formulation, choose_method(s).formulation);
  EXPECT_EQ(p.tolerance, s.tolerance);
  EXPECT_TRUE(p.force_balance);
  EXPECT_TRUE(p.resolve_peaks);  // peaks: resolved, the default in a driven scene
  EXPECT_FALSE(p.validate());
  const Study resolved = parse_study(
      opt_edit("  tolerance: 1.0e-7\n", "  tolerance: 1.0e-7\n  peaks: resolved\n"), "study.yaml");
  EXPECT_TRUE(resolved.optimize->resolve_peaks);
  const Study sampled = parse_study(
      opt_edit("  tolerance: 1.0e-7\n", "  tolerance: 1.0e-7\n  peaks: sampled\n"), "study.yaml");
  EXPECT_FALSE(sampled.optimize->resolve_peaks);
  EXPECT_FALSE(design_problem(sampled).resolve_peaks);
  EXPECT_TRUE(design_problem(resolved).resolve_peaks);
}

TEST(LoadStudy, OptimizeDefaults) {
  const Study s = parse_study(driven() + kMinimal, "study.yaml");
  ASSERT_TRUE(s.optimize.has_value());
  const OptimizeRequest& r = *s.optimize;
  const optimize::OptimizeOptions defaults;
  EXPECT_EQ(r.options.algorithm, optimize::Algorithm::kSlsqp);
  EXPECT_EQ(r.options.max_evaluations, defaults.max_evaluations);
  EXPECT_EQ(r.options.relative_tolerance, defaults.relative_tolerance);
  EXPECT_FALSE(r.force_balance);
  EXPECT_TRUE(r.limits.empty());
  EXPECT_FALSE(r.pareto.has_value());
  ASSERT_EQ(r.counterweights.size(), 2u);
  // point masses of up to 10 kg within the link's own length of the pivot
  EXPECT_EQ(r.counterweights[0].mass_max, 10.0);
  EXPECT_EQ(r.counterweights[0].distance_max, 1.0);
  EXPECT_EQ(r.counterweights[1].distance_max, 2.0);
  EXPECT_EQ(r.counterweights[1].shape, balance::CounterweightShape::kPoint);
  EXPECT_TRUE(r.link_parameters.empty());

  // every algorithm by name, in a driven scene
  for (const char* name : {"slsqp", "mma", "ipopt", "mlsl", "isres", "cobyla"}) {
    const Study a = parse_study(driven() + kMinimal + "  algorithm: " + name + "\n", "study.yaml");
    EXPECT_STREQ(optimize::to_string(a.optimize->options.algorithm), name);
  }
  // constraints may be empty; added_mass may be negative (take mass away)
  EXPECT_NO_THROW(parse_study(driven() + kMinimal + "  constraints:\n", "study.yaml"));
  const Study neg =
      parse_study(driven() + kMinimal + "  constraints: {added_mass: -0.5}\n", "study.yaml");
  EXPECT_EQ(neg.optimize->limits.at(0).value, -0.5);
}

// starts belong to mlsl: its default of 8 is no bound on another algorithm's evaluations (a
// cobyla run of 5 evaluations, free or driven, is valid), and mlsl's default that cannot share
// max_evaluations is said at the section as the default
TEST(LoadStudy, StartsAreCheckedOnlyWhereMlslMakesThem) {
  // kBase set in motion (free: it starts at rest without loads), and driven
  const std::string free_scene = edit("  duration: 5.0\n", "  omega1: 1.0\n  duration: 5.0\n");
  for (const std::string& scene : {free_scene, driven()}) {
    for (const char* name : {"cobyla", "slsqp"}) {
      if (scene == free_scene && std::string(name) == "slsqp") continue;  // free: no gradients
      const Study s = parse_study(
          scene + kMinimal + "  algorithm: " + name + "\n  max_evaluations: 5\n", "study.yaml");
      ASSERT_TRUE(s.optimize.has_value()) << name;
      EXPECT_EQ(s.optimize->options.max_evaluations, 5) << name;
    }
  }
  expect_error(driven() + kMinimal + "  algorithm: mlsl\n  max_evaluations: 5\n", 18, 1,
               "optimize: starts must be >= 1 and <= max_evaluations (5: each start needs an "
               "evaluation), got 8 (the default; give optimize.starts)");
  EXPECT_NO_THROW(
      parse_study(driven() + kMinimal + "  algorithm: mlsl\n  max_evaluations: 5\n  starts: 5\n",
                  "study.yaml"));
}

TEST(LoadStudy, OptimizeMistakesAreReportedWhereTheyAre) {
  const std::string all =
      "Fsh_rms, Fsh_max, Msh_rms, Msh_max, tau_rms, tau_max, RA0_rms, RA0_max, RA3_rms, "
      "RA3_max, added_mass";
  expect_error(opt_edit("  tolerance: 1.0e-7\n", "  tolerence: 1.0e-7\n"), 32, 3,
               "unknown key 'tolerence' in optimize; allowed keys: algorithm, objective, "
               "constraints, variables, max_evaluations, starts, tolerance, peaks, pareto");
  // peaks: sampled or resolved, at the key's value
  expect_error(opt_edit("  tolerance: 1.0e-7\n", "  tolerance: 1.0e-7\n  peaks: exact\n"), 33,
               10, "optimize.peaks must be resolved or sampled, got 'exact'");
  // starts: mlsl's local runs, an error with another algorithm, at the key's value
  expect_error(opt_edit("  tolerance: 1.0e-7\n", "  tolerance: 1.0e-7\n  starts: 4\n"), 33, 11,
               "optimize.starts is the number of local runs of the multistart mlsl; algorithm "
               "slsqp runs once");
  for (const char* starts : {"0", "501"}) {  // at least one, at most max_evaluations (500)
    std::string mlsl = opt_edit("algorithm: slsqp", "algorithm: mlsl");
    mlsl.insert(mlsl.find("  tolerance: 1.0e-7\n  pareto"), std::string("  starts: ") + starts +
                                                                "\n");
    expect_error(mlsl, 32, 11, starts[0] == '0' ? "optimize.starts" : "optimize: starts must be "
                                                                      ">= 1 and <= max_evaluations");
  }
  expect_error(opt_edit("algorithm: slsqp", "algorithm: bfgs"), 19, 14,
               "unknown algorithm 'bfgs' in optimize.algorithm; expected one of slsqp, mma, "
               "ipopt, mlsl, isres, cobyla");
  // metric names: the valid ones are listed
  expect_error(opt_edit("Msh_rms: 1.0,", "Msh_mean: 1.0,"), 20, 15,
               "unknown metric 'Msh_mean' in optimize.objective; expected one of " + all);
  expect_error(opt_edit("    Fsh_rms: 0.2\n", "    Fsh_peak: 0.2\n"), 23, 5,
               "unknown constraint 'Fsh_peak' in optimize.constraints; expected force_balance "
               "or one of " +
                   all);
  expect_error(opt_edit("first: Fsh_rms", "first: shaking"), 33, 19,
               "unknown metric 'shaking' in optimize.pareto.first; expected one of " + all);
  // values
  expect_error(opt_edit("tau_rms: 0.5", "tau_rms: -0.5"), 20, 38,
               "optimize.objective.tau_rms must be >= 0 (a weight), got -0.5");
  expect_error(opt_edit("{Msh_rms: 1.0, tau_rms: 0.5}", "{Msh_rms: 0, tau_rms: 0}"), 20, 3,
               "optimize.objective needs at least one metric with a weight > 0");
  expect_error(opt_edit("Fsh_rms: 0.2", "Fsh_rms: 0"), 23, 14,
               "optimize.constraints.Fsh_rms must be > 0 (a fraction of the original design's "
               "value), got 0");
  expect_error(opt_edit("force_balance: true", "force_balance: full"), 22, 20,
               "optimize.constraints.force_balance must be true or false, got 'full'");
  expect_error(opt_edit("mass_max: 8.0", "mass_max: -8"), 27, 25,
               "optimize.variables.counterweights.crank.mass_max must be > 0 kg, got -8");
  expect_error(opt_edit("distance_max: 0.9", "distance_max: 0"), 27, 44,
               "optimize.variables.counterweights.crank.distance_max must be > 0 m, got 0");
  expect_error(opt_edit("{mass_max: 8.0,", "{thickness: 0.02, mass_max: 8.0,"), 27, 15,
               "optimize.variables.counterweights.crank.thickness needs shape: disc");
  expect_error(opt_edit("shape: disc", "shape: cube"), 28, 38,
               "optimize.variables.counterweights.rocker.shape must be point or disc, got 'cube'");
  expect_error(opt_edit("      crank: {", "      coupler: {"), 27, 7,
               "unknown key 'coupler' in optimize.variables.counterweights; allowed keys: crank, "
               "rocker");
  expect_error(opt_edit("mass: [2.0, 4.0]", "mass: [4.0, 2.0]"), 30, 23,
               "optimize.variables.links.coupler.mass must have lower < upper, got [4, 2]");
  expect_error(opt_edit("mass: [2.0, 4.0]", "mass: [0, 4.0]"), 30, 24,
               "optimize.variables.links.coupler.mass lower bound must be > 0 kg");
  expect_error(opt_edit("inertia: [1.0, 8.0]", "inertia: [-1.0, 8.0]"), 30, 45,
               "optimize.variables.links.coupler.inertia lower bound must be >= 0 kg m²");
  expect_error(opt_edit("mass: [2.0, 4.0]", "mass: 3.0"), 30, 23,
               "optimize.variables.links.coupler.mass must be a list of 2 numbers [lower, "
               "upper] in kg, got '3.0'");
  expect_error(opt_edit("{mass: [2.0, 4.0],", "{length: [2.0, 4.0],"), 30, 17,
               "unknown key 'length' in optimize.variables.links.coupler; allowed keys: mass, e, "
               "f, inertia");
  expect_error(
      opt_edit("      coupler: {mass: [2.0, 4.0], inertia: [1.0, 8.0]}", "      coupler: {}"), 30,
      7, "optimize.variables.links.coupler: give at least one of mass, e, f, inertia");
  expect_error(opt_edit("max_evaluations: 500", "max_evaluations: 0"), 31, 20,
               "optimize.max_evaluations must be >= 1, got 0");
  expect_error(opt_edit("max_evaluations: 500", "max_evaluations: 2.5"), 31, 20,
               "optimize.max_evaluations must be a whole number");
  expect_error(opt_edit("tolerance: 1.0e-7", "tolerance: 2"), 32, 14,
               "optimize.tolerance must be > 0 and < 1");
  expect_error(opt_edit("second: Msh_rms", "second: Fsh_rms"), 33, 36,
               "optimize.pareto.second must differ from first (both are Fsh_rms)");
  expect_error(opt_edit("points: 5", "points: 1"), 33, 53, "optimize.pareto.points must be >= 2");
  expect_error(opt_edit("{first: Fsh_rms, ", "{"), 33, 3,
               "optimize.pareto: missing required key 'first'");
  // required keys, empty section, no variables
  expect_error(driven() + "optimize:\n  variables: {counterweights: {crank: }}\n", 18, 1,
               "optimize: missing required key 'objective'");
  expect_error(driven() + "optimize: {objective: {Msh_rms: 1}}\n", 18, 1,
               "optimize: missing required key 'variables'");
  expect_error(driven() + "optimize:\n", 18, 1, "optimize must be a map");
  expect_error(driven() + "optimize:\n  objective: {Msh_rms: 1}\n  variables: {links: }\n", 20, 3,
               "optimize.variables: no design variable");
}

TEST(LoadStudy, OptimizeAndBalanceAreMutuallyExclusive) {
  expect_error(driven() + "balance: {force: full}\n" + kMinimal, 19, 1,
               "a study has a balance section or an optimize section, not both (balance is "
               "given at line 18)");
  expect_error(driven() + kMinimal + "balance: {force: full}\n", 22, 1,
               "a study has a balance section or an optimize section, not both (optimize is "
               "given at line 18)");
  // optimized.yaml is named <name>-optimized, which must still be a valid name
  const std::string long_name =
      "name: " + std::string(91, 'a') + "\n" + driven().substr(std::string("name: t\n").size());
  expect_error(long_name + kMinimal, 1, 7,
               "name must have at most 90 characters in a study with an optimize section");
}

TEST(LoadStudy, OptimizeMetricsAFreeSceneCannotHave) {
  // no drive torque in free motion: nothing to normalise by
  expect_error(kBase +
                   "optimize:\n  algorithm: cobyla\n  objective: {tau_rms: 1}\n"
                   "  variables: {counterweights: {crank: }}\n",
               20, 15, "optimize.objective.tau_rms: a free scene has no drive torque");
  expect_error(kBase +
                   "optimize:\n  algorithm: cobyla\n  objective: {Msh_rms: 1}\n"
                   "  constraints: {tau_max: 2}\n  variables: {counterweights: {crank: }}\n",
               21, 17, "optimize.constraints.tau_max: a free scene has no drive torque");
}

TEST(LoadStudy, GradientAlgorithmInAFreeSceneOnTheOpenedLoopIsAnErrorAtAlgorithm) {
  // kBase set in motion (one line longer: the optimize section starts at line 19)
  const std::string moving = edit("  duration: 5.0\n", "  duration: 0.5\n  omega1: 6.0\n");
  const std::string section =
      "  objective: {Msh_rms: 1}\n  variables: {counterweights: {crank: }}\n";
  // the reduced equation has gradients by forward sensitivities
  EXPECT_NO_THROW(parse_study(moving + "optimize:\n  algorithm: slsqp\n" + section, "study.yaml"));
  // the opened loop's DAE has none; the message is optimize()'s own
  const StudyError e =
      error_of(moving + "method: opened-loop\noptimize:\n  algorithm: slsqp\n" + section);
  EXPECT_EQ(e.line(), 21);
  EXPECT_EQ(e.column(), 14);
  EXPECT_EQ(e.message().rfind("optimize.algorithm: ", 0), 0u) << e.what();
  EXPECT_NE(e.message().find("needs gradients"), std::string::npos) << e.what();
  EXPECT_NE(e.message().find("cobyla"), std::string::npos) << e.what();
  // without an algorithm key a free scene gets cobyla, a driven one slsqp
  const Study d = parse_study(moving + "optimize:\n" + section, "study.yaml");
  ASSERT_TRUE(d.optimize.has_value());
  EXPECT_EQ(d.optimize->options.algorithm, optimize::Algorithm::kCobyla);
  // a derivative-free method is fine
  EXPECT_NO_THROW(parse_study(moving + "optimize:\n  algorithm: cobyla\n" + section, "study.yaml"));
  // without the peaks key, a free scene's peaks are resolved between the samples, as a driven
  // scene's; `peaks: sampled` takes the samples'
  const std::string peak_section =
      "optimize:\n  objective: {Msh_max: 1}\n  variables: {counterweights: {crank: }}\n";
  const Study peak = parse_study(moving + peak_section, "study.yaml");
  EXPECT_TRUE(peak.optimize->resolve_peaks);
  EXPECT_TRUE(design_problem(peak).resolve_peaks);
  EXPECT_TRUE(parse_study(moving + peak_section + "  peaks: resolved\n", "study.yaml")
                  .optimize->resolve_peaks);
  const Study sampled = parse_study(moving + peak_section + "  peaks: sampled\n", "study.yaml");
  EXPECT_FALSE(sampled.optimize->resolve_peaks);
  EXPECT_FALSE(design_problem(sampled).resolve_peaks);
}

TEST(LoadStudy, OptimizeNeedsOriginalMetricsToNormaliseBy) {
  // kBase has no loads and starts at rest: nothing moves, every metric is 0
  expect_error(kBase +
                   "optimize:\n  algorithm: cobyla\n  objective: {Fsh_rms: 0, Msh_rms: 1}\n"
                   "  variables: {counterweights: {crank: }}\n",
               20, 27,
               "optimize.objective.Msh_rms: the original design's Msh_rms is 0 N m, too small to "
               "normalise by");
  // a driven scene the original cannot run through (the crank cannot turn fully)
  const std::string stuck =
      edit("  type: free\n  theta1: 1.0\n  duration: 5.0\n",
           "  type: driven\n  theta1: 1.5707963267948966\n  omega1: 6.283185307179586\n");
  const std::string text = stuck.substr(0, stuck.find("    length: 1.0\n")) + "    length: 2.5\n" +
                           stuck.substr(stuck.find("    length: 1.0\n") + 16);
  // refused before the optimize section is read: a driven scene needs a crank that turns fully
  // (it used to load, run to the first limit position and stop with exit code 3)
  expect_error(text, 15, 9,
               "scene.type: driven turns the crank through whole revolutions, but this linkage is "
               "rocker-crank");
  expect_error(text + kMinimal, 15, 9, "scene.type: driven turns the crank");
  // the paper's force-balanced linkage, driven: no shaking force to normalise by
  std::string balanced = driven();
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"    s: 0.6\n    sigma: 0.3\n",
                                            "    s: 0.83696749777390356\n"
                                            "    sigma: 2.8145330430599738\n"},
        {"s: 1.66, sigma: -0.4", "s: 3.2548589414457618, sigma: 0.15837131642962568"}}) {
    balanced.replace(balanced.find(from), from.size(), to);
  }
  const std::string section =
      "optimize:\n  objective: {Msh_rms: 1}\n  variables: {counterweights: {crank: }}\n";
  EXPECT_NO_THROW(parse_study(balanced + section, "study.yaml"));
  expect_error(balanced + section + "  constraints: {Fsh_max: 0.5}\n", 21, 17,
               "optimize.constraints.Fsh_max: the original design's Fsh_max is");
  // and the Pareto front's metrics
  expect_error(balanced + section + "  pareto: {first: Fsh_rms, second: Msh_rms}\n", 21, 19,
               "optimize.pareto.first: the original design's Fsh_rms is");
  expect_error(balanced + section + "  pareto: {first: Msh_rms, second: Fsh_max}\n", 21, 36,
               "optimize.pareto.second: the original design's Fsh_max is");
}

TEST(LoadStudy, OptimizeExamplesLoad) {
  for (const char* file :
       {"berkof-lowen-min-shaking-moment.yaml", "weighted-counterweights.yaml"}) {
    SCOPED_TRACE(file);
    const Study s = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + file);
    ASSERT_TRUE(s.optimize.has_value());
    EXPECT_TRUE(std::holds_alternative<core::DrivenScene>(s.scene));
    EXPECT_EQ(s.optimize->counterweights.size(), 2u);
  }
}

}  // namespace
}  // namespace bd::studies
