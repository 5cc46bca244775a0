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

}  // namespace
}  // namespace bd::studies
