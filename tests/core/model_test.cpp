// make_fourbar validation messages and the model helpers.
#include "core/fourbar/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/input_error.hpp"
#include "core/fourbar/samples.hpp"

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
  EXPECT_EQ(error_of(m), "rocker.inertia must be >= 0 kg m^2, got -0.5");
  m = samples::paper_fourbar();
  m.frame_length = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of(m), "frame must be > 0 m, got nan");
  m = samples::paper_fourbar();
  m.loads.coupler.moment = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error_of(m), "loads.coupler.moment must be finite N m, got inf");
  EXPECT_EQ(error_of(samples::paper_fourbar()), "");
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
