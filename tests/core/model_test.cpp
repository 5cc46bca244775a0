// make_fourbar validation messages and the model helpers.
#include "core/fourbar/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"

namespace bd::core {
namespace {

std::string error_of(const FourBar& m) {
  try {
    make_fourbar(m);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Model, RejectsNonPhysicalValuesWithNamedMessages) {
  FourBar m = samples::paper_fourbar();
  m.coupler.mass = -1.2;
  EXPECT_EQ(error_of(m), "coupler.mass must be > 0 kg, got -1.2");
  m = samples::paper_fourbar();
  m.crank.length = 0;
  EXPECT_EQ(error_of(m), "crank.length must be > 0 m, got 0");
  m = samples::paper_fourbar();
  m.rocker.inertia = -0.5;
  EXPECT_EQ(error_of(m), "rocker.inertia must be >= 0 kg m², got -0.5");
  m = samples::paper_fourbar();
  m.frame_length = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of(m), "frame must be > 0 m, got nan");
  m = samples::paper_fourbar();
  m.loads.coupler.moment = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error_of(m), "loads.coupler.moment must be finite N m, got inf");
  EXPECT_EQ(error_of(samples::paper_fourbar()), "");
}

// make_fourbar's complaint names the value by its path in the FourBar (field and index), so a
// caller that knows where each value came from can point at it without reading the message.
void expect_field(const FourBar& m, const std::string& field, int index, const std::string& text) {
  try {
    make_fourbar(m);
    ADD_FAILURE() << "no bd::InputError; expected " << field;
  } catch (const InputError& e) {
    ASSERT_TRUE(e.field().has_value()) << e.what();
    EXPECT_EQ(e.field()->field, field) << e.what();
    EXPECT_EQ(e.field()->index, index) << e.what();
    EXPECT_EQ(e.field()->text(), e.what());
    EXPECT_EQ(std::string(e.what()), text);
  }
}

TEST(Model, RejectionsNameTheFieldAndIndex) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  FourBar m = samples::paper_fourbar();
  m.frame_length = 0;
  expect_field(m, "frame", -1, "frame must be > 0 m, got 0");
  m = samples::paper_fourbar();
  m.coupler.f = nan;
  expect_field(m, "coupler.f", -1, "coupler.f must be finite m, got nan");
  m = samples::paper_fourbar();
  m.loads.crank.force.x() = nan;
  expect_field(m, "loads.crank.force", 0, "loads.crank.force[0] must be finite N, got nan");
  m = samples::paper_fourbar();
  m.loads.gravity.y() = std::numeric_limits<double>::infinity();
  expect_field(m, "loads.gravity", 1, "loads.gravity[1] must be finite m/s², got inf");
  m = samples::paper_fourbar();
  m.counter_rotations.rocker.inertia = -1;
  expect_field(m, "counter_rotations.rocker.inertia", -1,
               "counter_rotations.rocker.inertia must be >= 0 kg m², got -1");
  m = samples::paper_fourbar();
  m.counter_rotations.crank.at.y() = nan;
  expect_field(m, "counter_rotations.crank.at", 1,
               "counter_rotations.crank.at[1] must be finite m, got nan");
  m = samples::paper_fourbar();
  m.counter_rotations.rocker = {0.5, Vec2(m.frame_length, 0)};
  expect_field(m, "counter_rotations.rocker", -1,
               "counter_rotations.rocker: distance of the shaft from the link's pivot must be > "
               "0 m, got 0");
  m = samples::paper_fourbar();
  m.branch = static_cast<Branch>(0);
  expect_field(m, "branch", -1, "branch must be +1 or -1");
}

TEST(Model, PolarAndCartesianCentreOfMassAgree) {
  const Link l = link_from_polar(3.0, 3.0, 1.45, 0.4, 3.1);
  EXPECT_NEAR(l.e, 1.45 * std::cos(0.4), 1e-15);
  EXPECT_NEAR(l.f, 1.45 * std::sin(0.4), 1e-15);
  EXPECT_NEAR(l.s(), 1.45, 1e-15);
  EXPECT_NEAR(l.sigma(), 0.4, 1e-15);
}

TEST(Model, LinkAccessors) {
  const FourBar m = samples::paper_fourbar();
  EXPECT_EQ(link(m, 2).length, 3.0);
  EXPECT_STREQ(link_name(3), "rocker");
  EXPECT_DOUBLE_EQ(total_mass(m), 2.1 + 3.0 + 2.2);
  EXPECT_EQ(link_load(m, 1).moment, 0.37);
}

}  // namespace
}  // namespace bd::core
