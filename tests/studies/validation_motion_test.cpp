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

// a tab in the indentation: named as such at its line and column, not yaml-cpp's "illegal map
// value"
TEST(ValidationMotion, TabInIndentationIsNamedAtItsPlace) {
  std::string text = kTripleRocker;
  text.replace(text.find("  type: driven"), 2, "\t");
  testing::expect_study_error(text, "t.yaml", 10, 1, "tabs are not allowed in YAML indentation");
}

}  // namespace
}  // namespace bd
