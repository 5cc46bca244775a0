// Validation that knows the motion: a driven scene of a four-bar whose crank cannot turn fully is
// an input error at scene.type (it would stop at the first limit position), with the linkage's
// class and the limit positions, which the check computes from the lengths alone and this test
// from the loop's closure by bisection.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/fourbar/kinematics.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/study_errors.hpp"

namespace bd {
namespace {

const std::string kTripleRocker =
    "name: t\n"
    "linkage:\n"
    "  type: fourbar\n"
    "  frame: 3.5\n"
    "  branch: 1\n"
    "  crank:   {length: 2.0, mass: 1.0, e: 0.8, f: 0.1,  inertia: 0.4}\n"
    "  coupler: {length: 2.0, mass: 1.5, e: 1.0, f: 0.0,  inertia: 0.6}\n"
    "  rocker:  {length: 2.0, mass: 1.2, e: 0.9, f: -0.1, inertia: 0.5}\n"
    "scene:\n"
    "  type: driven\n"
    "  omega1: 1.0\n";

TEST(ValidationMotion, DrivenSceneOfACrankThatCannotTurnIsAnErrorAtSceneType) {
  testing::expect_study_error(kTripleRocker, "t.yaml", 10, 9,
                              "scene.type: driven turns the crank through whole revolutions, but "
                              "this linkage is non-Grashof");
  // the limit position it names: where the loop stops closing, found by bisection on the pose
  const studies::StudyError e = testing::study_error_of(kTripleRocker, "t.yaml");
  core::FourBar fb;
  fb.frame_length = 3.5;
  fb.crank = {2.0, 1.0, 0.8, 0.1, 0.4};
  fb.coupler = {2.0, 1.5, 1.0, 0.0, 0.6};
  fb.rocker = {2.0, 1.2, 0.9, -0.1, 0.5};
  double closes = 0.0, open = 3.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (closes + open);
    (core::solve_position(fb, mid) ? closes : open) = mid;
  }
  char limit[32];
  std::snprintf(limit, sizeof limit, "%.6g", closes);
  EXPECT_NE(e.message().find(std::string("±") + limit), std::string::npos)
      << e.message() << " (limit " << limit << ")";
  // free, it runs (through the limit positions)
  std::string free = kTripleRocker;
  free.replace(free.find("type: driven"), 12, "type: free");
  free += "  duration: 1.0\n";
  EXPECT_NO_THROW(studies::parse_study(free, "t.yaml"));
}

// A change-point linkage (shortest + longest = the other two: a parallelogram) turns fully, but at
// the crank angles where its links fold into one line the loop closes two ways (on as drawn, or
// crossed): driven through them, the run followed the crossed twin without a word. An input
// error at scene.type, naming the fold angles, which this test finds from the poses: there the
// transmission sine sin(theta3 - theta2) vanishes.
TEST(ValidationMotion, DrivenChangePointLinkageIsAnErrorAtSceneType) {
  std::string parallelogram = kTripleRocker;
  parallelogram.replace(parallelogram.find("frame: 3.5"), 10, "frame: 3.0");
  parallelogram.replace(parallelogram.find("crank:   {length: 2.0"), 21, "crank:   {length: 1.0");
  parallelogram.replace(parallelogram.find("coupler: {length: 2.0"), 21, "coupler: {length: 3.0");
  parallelogram.replace(parallelogram.find("rocker:  {length: 2.0"), 21, "rocker:  {length: 1.0");
  testing::expect_study_error(parallelogram, "p.yaml", 10, 9,
                              "scene.type: driven turns the crank through whole revolutions, but "
                              "this linkage is change-point");
  const std::string message = testing::study_error_of(parallelogram, "p.yaml").message();
  EXPECT_NE(message.find("theta1 = 3.14159, 0 rad"), std::string::npos) << message;
  core::FourBar fb;
  fb.frame_length = 3.0;
  fb.crank = {1.0, 1.0, 0.8, 0.1, 0.4};
  fb.coupler = {3.0, 1.5, 1.0, 0.0, 0.6};
  fb.rocker = {1.0, 1.2, 0.9, -0.1, 0.5};
  for (double fold : {0.0, M_PI}) {
    const auto near = core::solve_position(fb, fold + 1e-10);
    const auto away = core::solve_position(fb, fold + 0.5);
    ASSERT_TRUE(near && away);
    EXPECT_LT(std::abs(std::sin(near->theta3 - near->theta2)), 1e-3) << fold;
    EXPECT_GT(std::abs(std::sin(away->theta3 - away->theta2)), 0.1) << fold;
  }
  // the crank three per mille shorter: a crank-rocker, which runs
  std::string crank_rocker = parallelogram;
  crank_rocker.replace(crank_rocker.find("crank:   {length: 1.0"), 21, "crank:   {length: 0.997");
  EXPECT_NO_THROW(studies::parse_study(crank_rocker, "p.yaml"));
}

// a tab in the indentation: named as such at its line and column, not yaml-cpp's "illegal map
// value"
TEST(ValidationMotion, TabInIndentationIsNamedAtItsPlace) {
  std::string text = kTripleRocker;
  text.replace(text.find("  type: driven"), 2, "\t");
  testing::expect_study_error(text, "t.yaml", 10, 1, "tabs are not allowed in YAML indentation");
}

}  // namespace
}  // namespace bd
