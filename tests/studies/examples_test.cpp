// Every shipped example study runs as is: users start from them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/sweep/sweep.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

// each test writes under its own name: ctest runs the tests of this file in parallel
RunResult run_example(const std::string& file) {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "examples" / test->name() / file;
  fs::remove_all(out);
  return run_study(load_study(std::string(BD_SOURCE_DIR) + "/studies/examples/" + file), out);
}

TEST(Examples, EveryExampleRunsToTheEnd) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(BD_SOURCE_DIR) / "studies/examples")) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    const Study study = load_study(entry.path().string());
    if (study.sweep) {
      // a sweep runs point by point: every point of a shipped example runs to the end
      const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "examples" /
                           "EveryExampleRunsToTheEnd" / entry.path().filename();
      fs::remove_all(out);
      SweepOptions options;
      const SweepResult s = run_sweep(study, out, options);
      EXPECT_TRUE(s.complete()) << entry.path();
      EXPECT_EQ(s.failed, 0) << entry.path() << ": see " << s.csv;
      continue;
    }
    const RunResult r = run_example(entry.path().filename().string());
    EXPECT_TRUE(r.ok()) << entry.path() << ": " << r.status().message
                        << (r.optimized ? " / " + r.optimized->message() : "");
  }
  EXPECT_GE(count, 5);
}

// a number quoted in the docs equals `value` to the digits it shows (half a unit of its last)
void expect_quoted(const std::string& quoted, double value, const std::string& what) {
  const std::size_t point = quoted.find('.');
  const int decimals = point == std::string::npos ? 0 : static_cast<int>(quoted.size() - point - 1);
  EXPECT_LE(std::abs(std::stod(quoted) - value), 0.5 * std::pow(10.0, -decimals) * (1 + 1e-9))
      << what << ": the docs quote " << quoted << ", the run gives " << value;
}

// The numbers docs/study-format.md quotes of the examples are the runs' numbers, to the digits
// it shows: paper-fourbar's metrics, berkof-lowen-min-shaking-moment's evaluations and its
// comparison (its rows that are not round-off).
TEST(Examples, TheFormatDocumentQuotesTheRunsNumbers) {
  const std::string doc = bd::testing::read(fs::path(BD_SOURCE_DIR) / "docs/study-format.md");
  const RunResult free = run_example("paper-fourbar.yaml");
  ASSERT_TRUE(free.ok());
  int quoted = 0;
  for (const MetricValue& m : free.metric_list) {
    const std::regex number("\\b" + m.name + " = ([0-9.]+) N");
    std::smatch q;
    if (!std::regex_search(doc, q, number)) continue;
    expect_quoted(q[1].str(), m.value, "paper-fourbar " + m.name);
    ++quoted;
  }
  EXPECT_GE(quoted, 8);

  const Study study = load_study(std::string(BD_SOURCE_DIR) +
                                 "/studies/examples/berkof-lowen-min-shaking-moment.yaml");
  const RunResult r = run_example("berkof-lowen-min-shaking-moment.yaml");
  ASSERT_TRUE(r.optimized && r.optimized->found());
  std::smatch q;
  ASSERT_TRUE(std::regex_search(
      doc, q,
      std::regex("For `berkof-lowen-min-shaking-moment.yaml` \\(SLSQP, ([0-9]+) evaluations")));
  EXPECT_EQ(std::stoi(q[1].str()), r.optimized->result.evaluations);
  // the comparison block after it
  const std::size_t from = doc.find("metric,before,after,ratio", q.position());
  const std::string block = doc.substr(from, doc.find("```", from) - from);
  std::istringstream lines(block);
  std::string line;
  int rows = 0;
  for (const ComparisonRow& row : comparison(study, r)) {
    const std::regex quoted_row("\n" + row.metric + ",([^,\n]*),([^,\n]*),");
    if (!std::regex_search(block, q, quoted_row)) continue;
    ++rows;
    for (const auto& [text, value] : {std::pair{q[1].str(), row.before}, {q[2].str(), row.after}}) {
      if (text.find('e') != std::string::npos) {  // round-off: its size only
        EXPECT_LT(std::abs(value), 1e-12) << row.metric;
        continue;
      }
      expect_quoted(text, value, "berkof-lowen " + row.metric);
    }
  }
  EXPECT_GE(rows, 7);
}

TEST(Examples, OptimumsAreVerifiedByASecondFormulation) {
  for (const char* file :
       {"berkof-lowen-min-shaking-moment.yaml", "weighted-counterweights.yaml"}) {
    SCOPED_TRACE(file);
    const RunResult r = run_example(file);
    ASSERT_TRUE(r.optimized.has_value());
    const optimize::OptimizeResult& o = r.optimized->result;
    ASSERT_TRUE(r.ok()) << o.message;
    EXPECT_EQ(o.termination, optimize::Termination::kConverged) << o.message;
    EXPECT_NE(o.verified_with, r.method.formulation);
    EXPECT_LE(o.verification_error, 1e-9) << o.brief_report();
    // every term of the objective is 1 for the original: the optimum must do better than the
    // weights' sum, or (Berkof-Lowen) meet the force balance the original does not
    EXPECT_LT(r.optimized->metrics.Fsh_rms, r.metrics.Fsh_rms);
  }
  // the force balance holds: the shaking force vanishes to round-off
  const RunResult b = run_example("berkof-lowen-min-shaking-moment.yaml");
  EXPECT_LT(b.optimized->metrics.Fsh_max, 1e-9 * b.metrics.Fsh_max);
  const RunResult w = run_example("weighted-counterweights.yaml");
  const core::Metrics& a = w.metrics;
  const core::Metrics& z = w.optimized->metrics;
  EXPECT_LT(z.Fsh_rms / a.Fsh_rms + z.Msh_rms / a.Msh_rms + z.tau_rms / a.tau_rms, 3.0);
  // the objective reported is the weighted sum of the re-simulated optimum's normalised metrics
  // (the linear form, not a sum of squares): the smoothing sqrt(r² + ε²) of optimize/nlp.hpp
  // puts it at most ε Σ w = 3e-6 above, and ~1e-12 here where no term vanishes; 1e-9 relative
  // covers the verification's round-off
  const core::Metrics& v = w.optimized->result.verified;
  const double f = v.Fsh_rms / a.Fsh_rms + v.Msh_rms / a.Msh_rms + v.tau_rms / a.tau_rms;
  EXPECT_NEAR(w.optimized->result.objective, f, 1e-9 * f);
  const double f_b = b.optimized->result.verified.Msh_rms / b.metrics.Msh_rms;
  EXPECT_NEAR(b.optimized->result.objective, f_b, 1e-9 * f_b);
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
