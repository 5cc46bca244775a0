// Every shipped example study runs as is (STYLE.md: "Each studies/examples/*.yaml runs as is").
#include <gtest/gtest.h>

#include <filesystem>

#include "studies/load_study.hpp"
#include "studies/runner.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

// each test writes under its own name: ctest runs the tests of this file in parallel
RunResult run_example(const std::string& file) {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path out =
      fs::path(BD_BINARY_DIR) / "test-output" / "examples" / test->name() / file;
  fs::remove_all(out);
  return run_study(load_study(std::string(BD_SOURCE_DIR) + "/studies/examples/" + file), out);
}

TEST(Examples, EveryExampleRunsToTheEnd) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(BD_SOURCE_DIR) / "studies/examples")) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    const RunResult r = run_example(entry.path().filename().string());
    EXPECT_TRUE(r.ok()) << entry.path() << ": " << r.trajectory.message;
  }
  EXPECT_GE(count, 5);
}

TEST(Examples, TripleRockerSwingsThroughItsLimitPositions) {
  const RunResult r = run_example("triple-rocker-free.yaml");
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  EXPECT_EQ(r.method.formulation, core::Formulation::kOpenedLoop);
  const auto& s = r.trajectory.samples;
  ASSERT_EQ(s.size(), 2001u);
  // the crank turns back at each limit position (|theta1| = 1.55294 rad) and never passes it
  int reversals = 0;
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {
    const double before = s[i].state.theta1 - s[i - 1].state.theta1;
    const double after = s[i + 1].state.theta1 - s[i].state.theta1;
    if (before * after < 0) ++reversals;
    EXPECT_LE(std::abs(s[i].state.theta1), 1.5529383) << "sample " << i;
  }
  EXPECT_GE(reversals, 6);
}

}  // namespace
}  // namespace bd::studies
