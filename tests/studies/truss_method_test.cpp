// A four-bar study run with `method: truss` or `truss-dae` goes through the general planar
// engine and comes back as a four-bar's run: the same samples, metrics and files as the
// dedicated closed form (method: mass-matrix), to round-off in driven scenes and to the
// integration tolerance in free ones. The engines share no code (core/fourbar/ and core/planar/
// are kept apart by tests/check_layering.sh), so the agreement checks the mapping of the run
// (studies/run/simulation.cpp) as well as the general engine.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

// every quantity of a sample, in the order of timeseries.csv (after t)
std::vector<double> quantities(const core::DynamicsSample& s) {
  const core::FourBarState& x = s.state;
  return {x.theta1, x.theta2, x.theta3, x.omega1, x.omega2, x.omega3, x.alpha1, x.alpha2,
          x.alpha3, s.RA0.x(), s.RA0.y(), s.RA3.x(), s.RA3.y(), s.Fsh.x(), s.Fsh.y(), s.Msh, s.tau};
}

// the largest difference of each quantity over the run, relative to its largest magnitude over
// the reference run (1 where a quantity is 0 throughout), and the worst of them
double worst_relative_difference(const core::Trajectory& a, const core::Trajectory& reference) {
  EXPECT_EQ(a.samples.size(), reference.samples.size());
  const std::size_t n = std::min(a.samples.size(), reference.samples.size());
  const std::size_t width = quantities(reference.samples.front()).size();
  std::vector<double> scale(width, 0.0), diff(width, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(a.t[i], reference.t[i]);
    const std::vector<double> qa = quantities(a.samples[i]), qr = quantities(reference.samples[i]);
    for (std::size_t k = 0; k < width; ++k) {
      scale[k] = std::max(scale[k], std::abs(qr[k]));
      diff[k] = std::max(diff[k], std::abs(qa[k] - qr[k]));
    }
  }
  double worst = 0;
  for (std::size_t k = 0; k < width; ++k) worst = std::max(worst, diff[k] / std::max(scale[k], 1.0));
  return worst;
}

Study with_method(const char* example, Method method, double tolerance = 0) {
  Study s = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + example);
  s.method = method;
  if (tolerance > 0) s.tolerance = tolerance;
  return s;
}

// Driven: inverse dynamics per sample on both engines, no integration: round-off apart. The
// general engine's samples are exact to round-off (tests/core/planar/fourbar_on_truss_test.cpp
// holds it to 1e-12 against the closed form at random instants); the same bound here.
TEST(TrussMethod, DrivenFourBarRunsOnTheGeneralEngineAsTheClosedForm) {
  const RunResult truss = compute_study(with_method("paper-fourbar-driven.yaml", Method::kTruss));
  const RunResult closed =
      compute_study(with_method("paper-fourbar-driven.yaml", Method::kMassMatrix));
  ASSERT_TRUE(truss.ok()) << truss.status().message;
  ASSERT_TRUE(closed.ok());
  EXPECT_EQ(truss.method.method, Method::kTruss);
  EXPECT_TRUE(truss.method.general_engine());
  EXPECT_FALSE(truss.method.reason.empty());
  const double worst = worst_relative_difference(truss.trajectory, closed.trajectory);
  std::printf("driven, truss against mass-matrix: %.2e\n", worst);
  EXPECT_LE(worst, 1e-12);
  // the metrics, from the same table
  ASSERT_EQ(truss.metric_list.size(), closed.metric_list.size());
  for (std::size_t k = 0; k < closed.metric_list.size(); ++k) {
    EXPECT_EQ(truss.metric_list[k].name, closed.metric_list[k].name);
    EXPECT_NEAR(truss.metric_list[k].value, closed.metric_list[k].value,
                1e-12 * std::max(1.0, std::abs(closed.metric_list[k].value)))
        << closed.metric_list[k].name;
  }
}

// Free: both engines integrate with CVODE Adams at tolerance 1e-12 (absolute 1e-14), each with
// its own error control. The reduced route integrates the same equation in θ1 as the closed
// form, so the two take the same steps and differ by round-off in the right-hand side (measured
// 2.6e-14); the DAE route integrates every node coordinate with its own steps and differs by
// the integration errors (measured 2.8e-10; the closed form delivers ~11 correct digits here,
// docs/performance.md). 1e-9 of each quantity's scale bounds both.
TEST(TrussMethod, FreeFourBarOnBothRoutesAgreesWithTheClosedFormToTheTolerance) {
  const RunResult closed =
      compute_study(with_method("paper-fourbar.yaml", Method::kMassMatrix, 1e-12));
  ASSERT_TRUE(closed.ok());
  for (Method m : {Method::kTruss, Method::kTrussDae}) {
    const RunResult truss = compute_study(with_method("paper-fourbar.yaml", m, 1e-12));
    ASSERT_TRUE(truss.ok()) << truss.status().message;
    EXPECT_EQ(truss.method.method, m);
    const double worst = worst_relative_difference(truss.trajectory, closed.trajectory);
    std::printf("free, %s against mass-matrix: %.2e\n", m == Method::kTruss ? "truss" : "truss-dae",
                worst);
    EXPECT_LE(worst, 1e-9) << (m == Method::kTruss ? "truss" : "truss-dae");
    // and not by accident: the integrations are independent, so they are not equal
    EXPECT_GT(worst, 0.0);
  }
}

// The files: a four-bar run on the general engine writes the four-bar's timeseries.csv (the
// same header) and says its method in summary.json.
TEST(TrussMethod, FourBarFilesKeepTheirColumnsOnTheGeneralEngine) {
  const fs::path dir = fs::temp_directory_path() / ("bd_truss_method_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const RunResult r = run_study(with_method("paper-fourbar-driven.yaml", Method::kTruss), dir);
  ASSERT_TRUE(r.ok());
  const std::string csv = bd::testing::read(dir / "timeseries.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), kTimeseriesHeader);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 361);  // header and 360 samples
  const std::string summary = bd::testing::read(dir / "summary.json");
  EXPECT_NE(summary.find("\"truss\""), std::string::npos) << summary.substr(0, 400);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bd::studies
