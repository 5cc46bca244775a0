// Speed against accuracy (studies/work_precision.hpp, `balance-design bench`): the quick
// work-precision study of the paper example writes one row per formulation, integrator and
// tolerance, with errors that shrink as the tolerance tightens and references by another
// formulation; the driven scene's RMS converges spectrally with the samples per revolution; the
// report gets its section "Speed against accuracy".
#include "studies/bench/work_precision.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

using bd::testing::read;

class WorkPrecisionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_work_precision_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

double number(const std::string& field) { return field.empty() ? NAN : std::stod(field); }

// ---------------------------------------------------------------------------------------------
// The quick bench of the paper example: 3 formulations x their integrators (8 ODE integrators
// each, IDA with the opened loop only) x tolerances 1e-4, 1e-7, 1e-10 = 75 rows, all completed.
// Errors shrink with the tolerance for every method: each tightening by 1e3 lowers the final
// error, except where it already sits at the reference's level (the order-6 and -8 pairs, whose
// steps end at every sample 0.01 s apart, are accurate to 1e-14 at any tolerance; measured
// 1e-14 ... 1e-16, bound 1e-12), and one non-monotone step per method is allowed.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, QuickBenchOfThePaperExample) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  BenchOptions options = BenchOptions::quick();
  std::vector<std::string> progress;
  options.progress = [&](const std::string& line) { progress.push_back(line); };
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.trajectory.message;
  EXPECT_EQ(result.csv, dir_ / "work-precision.csv");
  EXPECT_EQ(progress.size(), 25u);  // one line per method
  EXPECT_NE(progress.front().find("bench: mass-matrix / cvode-adams"), std::string::npos)
      << progress.front();

  // the file, read back: header, 75 rows in the order formulation, integrator, tolerance
  const report_support::Csv csv = report_support::read_csv(result.csv);
  EXPECT_EQ(read(result.csv).substr(0, read(result.csv).find('\n')), kWorkPrecisionHeader);
  ASSERT_EQ(csv.rows.size(), 75u);
  ASSERT_EQ(result.free_rows.size(), 75u);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < csv.header.size(); ++i) col[csv.header[i]] = i;
  std::map<std::pair<std::string, std::string>, std::vector<std::vector<std::string>>> methods;
  for (const auto& row : csv.rows) {
    ASSERT_EQ(row.size(), csv.header.size());
    methods[{row[col["formulation"]], row[col["integrator"]]}].push_back(row);
  }
  EXPECT_EQ(methods.size(), 25u);
  EXPECT_EQ(methods.count({"opened-loop", "ida"}), 1u);
  EXPECT_EQ(methods.count({"mass-matrix", "ida"}), 0u);

  for (const auto& [method, rows] : methods) {
    const std::string what = method.first + " / " + method.second;
    ASSERT_EQ(rows.size(), 3u) << what;
    int rises = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& row = rows[k];
      EXPECT_EQ(row[col["status"]], "completed") << what << ": " << row[col["message"]];
      EXPECT_EQ(number(row[col["tolerance"]]), options.tolerances[k]) << what;
      // a reference computed by a different formulation, at the reference tolerance
      EXPECT_NE(row[col["reference_formulation"]], row[col["formulation"]]) << what;
      EXPECT_EQ(row[col["reference_integrator"]], "erk8") << what;
      EXPECT_EQ(number(row[col["reference_tolerance"]]), 1e-14) << what;
      EXPECT_EQ(row[col["samples"]], "501") << what;
      EXPECT_GT(number(row[col["cpu_time"]]), 0) << what;
      EXPECT_EQ(row[col["repeats"]], "1") << what;
      EXPECT_GT(number(row[col["steps"]]), 0) << what;
      const double e = number(row[col["final_error"]]);
      ASSERT_TRUE(std::isfinite(e)) << what;
      EXPECT_NEAR(number(row[col["digits"]]), e > 0 ? std::min(16.0, -std::log10(e)) : 16.0, 1e-12)
          << what;
      // the final error is at most the tolerance's level (x 1e3: global error over 50-500 000
      // steps, relative to angles of 0.16-1.5 rad; measured at most 170 x, IDA at 1e-10) and
      // the sample error is of the same order (measured at most 30 x)
      EXPECT_LT(e, 1e3 * options.tolerances[k]) << what;
      EXPECT_LT(number(row[col["max_error"]]), 1e3 * options.tolerances[k]) << what;
      if (k > 0) {
        const double before = number(rows[k - 1][col["final_error"]]);
        if (!(e < before) && !(e < 1e-12)) ++rises;
      }
    }
    EXPECT_LE(rises, 1) << what;
    // over the whole range the error falls by a factor >= 100 unless at the reference's level
    const double first = number(rows.front()[col["final_error"]]);
    const double last = number(rows.back()[col["final_error"]]);
    EXPECT_TRUE(last < 1e-2 * first || last < 1e-12) << what << ": " << first << " -> " << last;
  }

  // the report's section, with a chart per formulation when gnuplot is there
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("<h2 id=\"speed-against-accuracy\">Speed against accuracy</h2>"),
            std::string::npos);
  EXPECT_NE(html.find("<a href=\"work-precision.csv\">"), std::string::npos);
  if (!find_gnuplot().empty()) {
    for (const char* f : {"mass-matrix", "opened-loop", "complex-masses"}) {
      EXPECT_NE(html.find(std::string("id=\"chart-work-precision-") + f + "\""), std::string::npos)
          << f;
    }
  }
  // the section comes before the data files
  EXPECT_LT(html.find("Speed against accuracy"), html.find("<h2>Data files</h2>"));
}

// ---------------------------------------------------------------------------------------------
// The driven paper example: the RMS over evenly spaced samples of a revolution is the
// trapezoidal rule of a smooth periodic function, exact for its Fourier modes below the sample
// count, so its error falls geometrically with the samples until round-off. Measured relative
// errors (Fsh_rms / Msh_rms): 4.2e-2 / 3.6e-1 at 4 samples, 3.7e-6 / 4.3e-4 at 16, 1.3e-12 /
// 1.9e-10 at 32, <= 1.4e-15 from 48 on (a few ulps of sums of 4096 terms). At 360 samples the
// bound is 1e-12, a thousand times the measured round-off.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, DrivenRmsConvergesSpectrallyWithTheSamples) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  const BenchOptions options = BenchOptions::quick();
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.trajectory.message;
  EXPECT_EQ(result.csv, dir_ / "driven-convergence.csv");
  const std::vector<DrivenConvergenceRow>& rows = result.driven_rows;
  ASSERT_EQ(rows.size(), 3 * options.samples.size());
  std::map<core::Formulation, std::map<int, const DrivenConvergenceRow*>> of;
  for (const DrivenConvergenceRow& r : rows) {
    EXPECT_EQ(r.status, core::SimulationStatus::kCompleted) << r.message;
    EXPECT_NE(r.reference_formulation, r.formulation);
    EXPECT_EQ(r.reference_samples, 4096);
    EXPECT_GT(r.cpu_time, 0);
    of[r.formulation][r.samples] = &r;
  }
  for (const auto& [f, by_samples] : of) {
    const std::string what = core::to_string(f);
    const DrivenConvergenceRow& at360 = *by_samples.at(360);
    EXPECT_LT(at360.Fsh_rms_error, 1e-12) << what;
    EXPECT_LT(at360.Msh_rms_error, 1e-12) << what;
    // spectral: each doubling from 4 to 32 samples gains more than the previous one (a power
    // law would gain a constant factor); measured Fsh_rms gains 14, 830, 3.0e6
    const double e4 = by_samples.at(4)->Fsh_rms_error, e8 = by_samples.at(8)->Fsh_rms_error,
                 e16 = by_samples.at(16)->Fsh_rms_error, e32 = by_samples.at(32)->Fsh_rms_error;
    EXPECT_GT(e4 / e8, 5) << what;
    EXPECT_GT(e8 / e16, 10 * (e4 / e8)) << what;
    EXPECT_GT(e16 / e32, 10 * (e8 / e16)) << what;
    EXPECT_GT(at360.Fsh_rms, 100);  // 169.86 N: the RMS itself, not an error
  }
  const std::string csv = read(result.csv);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), kDrivenConvergenceHeader);
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("Speed against accuracy"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"driven-convergence.csv\">"), std::string::npos);
  if (!find_gnuplot().empty()) {
    EXPECT_NE(html.find("id=\"chart-driven-convergence-error\""), std::string::npos);
    EXPECT_NE(html.find("id=\"chart-driven-convergence-time\""), std::string::npos);
  }
}

TEST_F(WorkPrecisionTest, ABenchRemovesEarlierMeasurementsOfTheOtherSceneType) {
  // a folder measured as driven, then benched with a free study: no stale driven rows in it
  const Study driven = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  BenchOptions options = BenchOptions::quick();
  options.samples = {8, 360};
  run_bench(driven, dir_, options);
  ASSERT_TRUE(fs::exists(dir_ / "driven-convergence.csv"));
  Study free = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  auto& scene = std::get<core::FreeScene>(free.scene);
  scene.duration = 0.5;
  scene.samples = 11;
  options.tolerances = {1e-6};
  run_bench(free, dir_, options);
  EXPECT_FALSE(fs::exists(dir_ / "driven-convergence.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "work-precision.csv"));
  const std::string html = read(dir_ / "report.html");
  EXPECT_EQ(html.find("driven-convergence.csv"), std::string::npos);
}

TEST(WorkPrecision, SceneTypeAndOptionsAreChecked) {
  const Study free = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  const Study driven = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  EXPECT_THROW(work_precision(driven, BenchOptions::quick()), InputError);
  EXPECT_THROW(driven_convergence(free, BenchOptions::quick()), InputError);
  BenchOptions o;
  EXPECT_EQ(o.validate(), "");
  EXPECT_EQ(o.tolerances.size(), 11u);
  EXPECT_EQ(o.tolerances.front(), 1e-3);
  EXPECT_EQ(o.tolerances.back(), 1e-13);
  EXPECT_EQ(o.repeats, 5);
  o.repeats = 0;
  EXPECT_EQ(o.validate(), "repeats must be >= 1, got 0");
  o = {};
  o.tolerances = {1e-6, 2.0};
  EXPECT_EQ(o.validate(), "every tolerance must be > 0 and < 1, got 2");
  try {
    work_precision(free, o);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "bench: every tolerance must be > 0 and < 1, got 2");
  }
  o = {};
  o.samples = {0};
  EXPECT_EQ(o.validate(), "every samples count must be >= 1, got 0");
  EXPECT_EQ(BenchOptions::quick().tolerances, (std::vector<double>{1e-4, 1e-7, 1e-10}));
  EXPECT_EQ(BenchOptions::quick().repeats, 1);
}

TEST(WorkPrecision, CsvWritesNanAsEmptyAndQuotesMessages) {
  WorkPrecisionRow r;
  r.tolerance = 1e-10;
  r.final_error = NAN;
  r.digits = NAN;
  r.max_error = 0.125;
  r.status = core::SimulationStatus::kSingular;
  r.message = "singular position at t = 1 s, theta1 = 2 rad: \"quoted\"";
  const std::string csv = work_precision_csv({r});
  EXPECT_NE(csv.find(",singular,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",,,0.125,\"singular position at t = 1 s, theta1 = 2 rad: \"\"quoted\"\"\"\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",1e-10,"), std::string::npos) << csv;  // "%.17g": 1e-10 reads back exactly
}

TEST(WorkPrecision, NoSectionWithoutMeasurements) {
  EXPECT_EQ(work_precision_section(fs::temp_directory_path() / "bd-no-such-folder", ""), "");
}

}  // namespace
}  // namespace bd::studies
