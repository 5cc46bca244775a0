// The text of numbers written to data files: text::exact() must give the very bytes of printf's
// "%.17g" (its documented form, what earlier files hold) and read back as the same double.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/number_text.hpp"

namespace bd::text {
namespace {

std::string printf_17g(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

TEST(NumberText, ExactIsPrintfs17gByteForByte) {
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 0.05, 0.1, 1.0 / 3, 2.0 / 3, 100.0, 1e16,
                                1e17, 123456789012345678.0, 1e-5, 1e-4, 9.999999999999999e-5,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::min(),
                                std::numeric_limits<double>::denorm_min(),
                                std::numeric_limits<double>::epsilon(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
  for (int e = -320; e <= 308; ++e) values.push_back(std::pow(10.0, e));
  // doubles of every exponent: random bit patterns (NaNs aside), and numbers a run writes
  std::mt19937_64 rng(17);
  for (int i = 0; i < 200000; ++i) {
    const double v = std::bit_cast<double>(rng());
    if (!std::isnan(v)) values.push_back(v);
  }
  std::uniform_real_distribution<double> u(-1e4, 1e4);
  for (int i = 0; i < 100000; ++i) values.push_back(u(rng));
  int differ = 0;
  for (const double v : values) {
    const std::string got = exact(v);
    if (got != printf_17g(v) && ++differ <= 10) ADD_FAILURE() << got << " != " << printf_17g(v);
    if (std::isfinite(v)) {
      EXPECT_EQ(std::strtod(got.c_str(), nullptr), v) << got;
    }
    fmt::memory_buffer out;
    append_exact(out, v);
    EXPECT_EQ(std::string(out.data(), out.size()), got);
  }
  EXPECT_EQ(differ, 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(exact(nan), printf_17g(nan));
}

}  // namespace
}  // namespace bd::text
