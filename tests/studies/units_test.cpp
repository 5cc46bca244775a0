// Values with units: converted on reading to exactly the SI number a person would write (the
// factors are exact or the defined ones: 1 in = 0.0254 m, 1 lb = 0.45359237 kg, g0 = 9.80665
// m/s²), listed in the study's units_read and summary.json; a plain number stays SI; a unit the
// quantity cannot take is an error at the value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <numbers>
#include <string>

#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/study_errors.hpp"

namespace bd {
namespace {

std::string fourbar(const std::string& theta1, const std::string& omega1,
                    const std::string& crank_length, const std::string& crank_mass) {
  return "name: u\n"
         "linkage:\n"
         "  type: fourbar\n"
         "  frame: 3.2\n"
         "  branch: 1\n"
         "  crank:   {length: " + crank_length + ", mass: " + crank_mass +
         ", s: 0.6, sigma: 0.3, inertia: 1.1}\n"
         "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}\n"
         "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
         "scene:\n"
         "  type: driven\n"
         "  theta1: " + theta1 + "\n"
         "  omega1: " + omega1 + "\n";
}

TEST(Units, ValuesWithUnitsEqualTheirSiNumbers) {
  const studies::Study si =
      studies::parse_study(fourbar("1.5707963267948966", "31.415926535897931", "1.0", "0.0021"),
                           "u.yaml");
  const studies::Study units =
      studies::parse_study(fourbar("90 deg", "300 rpm", "1000 mm", "2.1 g"), "u.yaml");
  const auto& a = std::get<core::DrivenScene>(si.scene);
  const auto& b = std::get<core::DrivenScene>(units.scene);
  EXPECT_EQ(b.theta1, a.theta1);  // 90·π/180 rounds to the double nearest π/2
  EXPECT_DOUBLE_EQ(b.omega1, 300 * 2 * std::numbers::pi / 60);
  EXPECT_EQ(units.fourbar().crank.length, 1.0);
  EXPECT_DOUBLE_EQ(units.fourbar().crank.mass, 0.0021);
  EXPECT_TRUE(si.units_read.empty());
  ASSERT_EQ(units.units_read.size(), 4u);
  EXPECT_EQ(units.units_read[0].rfind("linkage.crank.length: 1000 mm = 1 m", 0), 0u)
      << units.units_read[0];
  // summary.json says what was read
  const studies::RunResult r = studies::compute_study(units);
  const std::string json = studies::summary_json(units, r);
  EXPECT_NE(json.find("scene.theta1: 90 deg = 1.5707963267948966 rad"), std::string::npos) << json;
}

// the spellings of a crank speed people write: RPM as rpm, Hz as turns per second; a value in
// the SI unit itself is read but is no conversion to list
TEST(Units, SpeedsInRpmOrHzAndSiUnitsWrittenOut) {
  const studies::Study rpm =
      studies::parse_study(fourbar("0", "300 RPM", "1 m", "2.1 kg"), "u.yaml");
  const studies::Study hz = studies::parse_study(fourbar("0", "5 Hz", "1.0", "2.1"), "u.yaml");
  const studies::Study plain =
      studies::parse_study(fourbar("0", "300 rpm", "1.0", "2.1"), "u.yaml");
  EXPECT_EQ(std::get<core::DrivenScene>(rpm.scene).omega1,
            std::get<core::DrivenScene>(plain.scene).omega1);
  EXPECT_DOUBLE_EQ(std::get<core::DrivenScene>(hz.scene).omega1, 10 * std::numbers::pi);
  ASSERT_EQ(rpm.units_read.size(), 1u);  // not "1 m = 1 m" nor "2.1 kg = 2.1 kg"
  EXPECT_EQ(rpm.units_read[0].rfind("scene.omega1: 300 RPM = ", 0), 0u) << rpm.units_read[0];
  EXPECT_EQ(rpm.fourbar().crank.length, 1.0);
  EXPECT_EQ(rpm.fourbar().crank.mass, 2.1);
}

// the SI number of units_read is the shortest text that reads back as the value used: 50 mm is
// "0.05 m", not 0.050000000000000003 (checked against the fewest printf digits that read back)
TEST(Units, UnitsReadGivesTheShortestExactNumber) {
  const studies::Study s =
      studies::parse_study(fourbar("90 deg", "60 rpm", "50 mm", "2.1 g"), "u.yaml");
  ASSERT_EQ(s.units_read.size(), 4u);
  EXPECT_EQ(s.units_read[0], "linkage.crank.length: 50 mm = 0.05 m");
  const double used[] = {s.fourbar().crank.length, s.fourbar().crank.mass,
                         std::get<core::DrivenScene>(s.scene).theta1,
                         std::get<core::DrivenScene>(s.scene).omega1};
  for (const std::string& line : s.units_read) {
    const std::size_t eq = line.find(" = ");
    ASSERT_NE(eq, std::string::npos) << line;
    const std::string number = line.substr(eq + 3, line.rfind(' ') - eq - 3);
    const double v = std::stod(number);
    EXPECT_NE(std::find(std::begin(used), std::end(used), v), std::end(used)) << line;
    std::string fewest;
    for (int digits = 1; digits <= 17; ++digits) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.*g", digits, v);
      if (std::strtod(buf, nullptr) == v) {
        fewest = buf;
        break;
      }
    }
    EXPECT_EQ(number, fewest) << line;
  }
}

TEST(Units, AUnitTheQuantityCannotTakeIsAnErrorAtTheValue) {
  testing::expect_study_error(fourbar("90 mm", "1", "1.0", "2.1"), "u.yaml", 11, 11,
                              "scene.theta1: unit 'mm' is not one of rad, deg, °, rev");
}

}  // namespace
}  // namespace bd
