// Speed against accuracy (studies/bench/work_precision.hpp, `balance-design bench`): the quick
// work-precision study of the paper example writes one row per method (the four-bar's
// formulations and the general engine's truss and truss-dae), integrator and tolerance, with
// errors that shrink as the tolerance tightens and references by another method; a planar
// linkage's free scene gets rows for both routes of the general engine, referenced by the other
// route; the driven scenes' RMS converges spectrally with the samples per revolution (a planar
// scene over a duration: at first order); runs that stop early keep their rows and are counted;
// the report gets its section "Speed against accuracy".
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

#include "core/fourbar/model.hpp"
#include "core/input_error.hpp"
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/studies.hpp"
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

// The rows of a work-precision.csv by (method, integrator), in file order, and its columns.
struct FreeRows {
  std::map<std::string, std::size_t> col;
  std::map<std::pair<std::string, std::string>, std::vector<std::vector<std::string>>> of;
  const std::string& at(const std::vector<std::string>& row, const char* column) const {
    return row[col.at(column)];
  }
  double number_at(const std::vector<std::string>& row, const char* column) const {
    return number(at(row, column));
  }
};

FreeRows free_rows(const fs::path& file) {
  const report_support::Csv csv = report_support::read_csv(file);
  FreeRows r;
  for (std::size_t i = 0; i < csv.header.size(); ++i) r.col[csv.header[i]] = i;
  for (const auto& row : csv.rows) {
    EXPECT_EQ(row.size(), csv.header.size());
    r.of[{row[r.col["method"]], row[r.col["integrator"]]}].push_back(row);
  }
  return r;
}

// The final error falls as the tolerance tightens: each step lowers it, except where it is
// already below what the tolerances ask for (5e-11: the order-6 and -8 pairs, whose steps end at
// every sample, are that accurate at any tolerance; measured up to 7.2e-12, truss-dae by erk6,
// and up to 9.8e-12 in a full bench), with one non-monotone step allowed per method; over the
// whole range it falls by a factor >= 100, again unless it starts below that level.
constexpr double kBelowTolerances = 5e-11;
void expect_error_falls(const FreeRows& r, const std::vector<std::vector<std::string>>& rows,
                        const std::string& what) {
  int rises = 0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const double e = r.number_at(rows[k], "final_error");
    const double before = r.number_at(rows[k - 1], "final_error");
    if (!(e < before) && !(e < kBelowTolerances)) ++rises;
  }
  EXPECT_LE(rises, 1) << what;
  const double first = r.number_at(rows.front(), "final_error");
  const double last = r.number_at(rows.back(), "final_error");
  EXPECT_TRUE(last < 1e-2 * first || first < kBelowTolerances)
      << what << ": " << first << " -> " << last;
}

// ---------------------------------------------------------------------------------------------
// The quick bench of the paper example: 3 formulations x their integrators (8 ODE integrators
// each, IDA with the opened loop only) and the general engine's truss and truss-dae x the 8 ODE
// integrators, x tolerances 1e-4, 1e-7, 1e-10 = 75 + 48 = 123 rows, all completed. The general
// engine's rows are referenced by the dedicated closed form (mass-matrix), so they show the
// general engine next to the closed forms on the same study.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, QuickBenchOfThePaperExample) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  BenchOptions options = BenchOptions::quick();
  std::vector<std::string> progress;
  options.progress = [&](const std::string& line) { progress.push_back(line); };
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  EXPECT_EQ(result.csv, dir_ / "work-precision.csv");
  EXPECT_EQ(result.stopped_early(), 0u);
  EXPECT_EQ(progress.size(), 41u);  // one line per method and integrator
  EXPECT_NE(progress.front().find("bench: mass-matrix / cvode-adams"), std::string::npos)
      << progress.front();
  EXPECT_NE(progress.back().find("bench: truss-dae / erk8"), std::string::npos) << progress.back();

  // the file, read back: header, 123 rows in the order method, integrator, tolerance
  EXPECT_EQ(read(result.csv).substr(0, read(result.csv).find('\n')), kWorkPrecisionHeader);
  ASSERT_EQ(result.free_rows.size(), 123u);
  const FreeRows r = free_rows(result.csv);
  EXPECT_EQ(r.of.size(), 41u);
  EXPECT_EQ(r.of.count({"opened-loop", "ida"}), 1u);
  EXPECT_EQ(r.of.count({"mass-matrix", "ida"}), 0u);
  EXPECT_EQ(r.of.count({"truss", "ida"}), 0u);
  EXPECT_EQ(r.of.count({"truss-dae", "erk5"}), 1u);

  for (const auto& [method, rows] : r.of) {
    const std::string what = method.first + " / " + method.second;
    ASSERT_EQ(rows.size(), 3u) << what;
    const bool general = method.first == "truss" || method.first == "truss-dae";
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& row = rows[k];
      EXPECT_EQ(r.at(row, "status"), "completed") << what << ": " << r.at(row, "message");
      EXPECT_EQ(r.number_at(row, "tolerance"), options.tolerances[k]) << what;
      // a reference computed by a different method, at the reference tolerance: the general
      // engine's by the dedicated closed form
      EXPECT_NE(r.at(row, "reference_method"), r.at(row, "method")) << what;
      if (general) {
        EXPECT_EQ(r.at(row, "reference_method"), "mass-matrix") << what;
      }
      EXPECT_EQ(r.at(row, "reference_integrator"), "erk8") << what;
      EXPECT_EQ(r.number_at(row, "reference_tolerance"), 1e-14) << what;
      EXPECT_EQ(r.at(row, "samples"), "501") << what;
      EXPECT_GT(r.number_at(row, "cpu_time"), 0) << what;
      EXPECT_EQ(r.at(row, "repeats"), "1") << what;
      EXPECT_GT(r.number_at(row, "steps"), 0) << what;
      const double e = r.number_at(row, "final_error");
      ASSERT_TRUE(std::isfinite(e)) << what;
      EXPECT_NEAR(r.number_at(row, "digits"), e > 0 ? std::min(16.0, -std::log10(e)) : 16.0, 1e-12)
          << what;
      // the final error is at most the tolerance's level (x 1e3: global error over 50-500 000
      // steps, on angles and on coordinates divided by the 3 m coupler; measured at most 28 x,
      // the opened loop by IDA at 1e-10), and the sample error too
      EXPECT_LT(e, 1e3 * options.tolerances[k]) << what;
      EXPECT_LT(r.number_at(row, "max_error"), 1e3 * options.tolerances[k]) << what;
      EXPECT_LE(e, r.number_at(row, "max_error")) << what;  // the final time is a sample
    }
    expect_error_falls(r, rows, what);
    // The general engine at tolerance 1e-10 agrees with the closed form to 1e-7 whatever the
    // integrator: both compute the same motion (the truss route integrates the same equation in
    // theta1, the dae route every node coordinate), so their difference is integration error
    // of the order of the tolerance (measured at most 2.0e-9, truss-dae by cvode-bdf: 50 x
    // below the bound).
    if (general) {
      EXPECT_LT(r.number_at(rows.back(), "final_error"), 1e-7) << what;
      EXPECT_LT(r.number_at(rows.back(), "max_error"), 1e-7) << what;
    }
  }

  // the report's section, with the methods compared and a chart per method when gnuplot is there
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("<h2 id=\"speed-against-accuracy\">Speed against accuracy</h2>"),
            std::string::npos);
  EXPECT_NE(html.find("<a href=\"work-precision.csv\">"), std::string::npos);
  EXPECT_NE(html.find("of truss is mass-matrix"), std::string::npos);
  EXPECT_EQ(html.find("runs stopped before the end of the scene"), std::string::npos);
  if (!find_gnuplot().empty()) {
    for (const char* f :
         {"methods", "mass-matrix", "opened-loop", "complex-masses", "truss", "truss-dae"}) {
      EXPECT_NE(html.find(std::string("id=\"chart-work-precision-") + f + "\""), std::string::npos)
          << f;
    }
  }
  // the section comes before the data files
  EXPECT_LT(html.find("Speed against accuracy"), html.find("<h2>Data files</h2>"));
}

// ---------------------------------------------------------------------------------------------
// A planar linkage's free scene (the engine coasting on its flywheel, 5 turns in 0.1 s, 1001
// samples): both routes of the general engine, truss and truss-dae, x the 8 ODE integrators x
// tolerances 1e-4, 1e-7, 1e-10 = 48 rows, each referenced by the other route (erk8 at 1e-14:
// the two references agree to 1.2e-13). The error is on the link angles (the crank turns 31 rad)
// and the node coordinates and piston position divided by the rod's 0.14 m.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, QuickBenchOfAPlanarFreeScene) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank-free.yaml");
  const BenchOptions options = BenchOptions::quick();
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  ASSERT_EQ(result.free_rows.size(), 48u);
  const FreeRows r = free_rows(result.csv);
  ASSERT_EQ(r.of.size(), 16u);
  for (const char* route : {"truss", "truss-dae"}) {
    for (core::Integrator integrator : core::kIntegrators) {
      const std::string i = core::to_string(integrator);
      EXPECT_EQ(r.of.count({route, i}), integrator == core::Integrator::kIda ? 0u : 1u)
          << route << " / " << i;
    }
  }
  for (const auto& [method, rows] : r.of) {
    const std::string what = method.first + " / " + method.second;
    ASSERT_EQ(rows.size(), 3u) << what;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& row = rows[k];
      EXPECT_EQ(r.number_at(row, "tolerance"), options.tolerances[k]) << what;
      EXPECT_EQ(r.at(row, "reference_method"), method.first == "truss" ? "truss-dae" : "truss")
          << what;
      EXPECT_EQ(r.at(row, "reference_integrator"), "erk8") << what;
      // Heun-Euler on the DAE route at 1e-10 needs more than max_steps = 1e6 steps for the
      // 0.1 s (measured: stopped at t = 0.0397 s); it keeps its row and says so
      if (method == std::pair<std::string, std::string>{"truss-dae", "erk2"} && k == 2) {
        if (r.at(row, "status") != "completed") {
          EXPECT_EQ(r.at(row, "status"), "integrator-failed");
          EXPECT_NE(r.at(row, "message").find("max_steps"), std::string::npos);
          EXPECT_TRUE(std::isnan(r.number_at(row, "final_error")));
          EXPECT_LT(r.number_at(row, "samples"), 1001);
          EXPECT_GT(r.number_at(row, "max_error"), 0);  // on the samples it computed
        }
        continue;
      }
      EXPECT_EQ(r.at(row, "status"), "completed") << what << ": " << r.at(row, "message");
      EXPECT_EQ(r.at(row, "samples"), "1001") << what;
      const double e = r.number_at(row, "final_error");
      ASSERT_TRUE(std::isfinite(e)) << what;
      EXPECT_LE(e, r.number_at(row, "max_error")) << what;
    }
  }
  // CVODE Adams, both routes: the error falls with the tolerance, at least 30-fold per step of
  // 1e3 (measured 440 and 4600 x on truss, 800 and 1.1e5 x on truss-dae: above 30 x, not the
  // full 1e3, because the variable-order method's global error is not proportional to the
  // tolerance), and at 1e-10 it is below 1e-7 (measured 3.2e-9 truss, 4.4e-10 truss-dae; the
  // crank turns 31 rad, so relative to the motion that is 1e-10), and above 1e-13, what the
  // two references resolve (their difference 1.2e-13): it is the run's error, not the
  // reference's.
  for (const char* route : {"truss", "truss-dae"}) {
    const auto& rows = r.of.at({route, "cvode-adams"});
    const double e4 = r.number_at(rows[0], "final_error"), e7 = r.number_at(rows[1], "final_error"),
                 e10 = r.number_at(rows[2], "final_error");
    EXPECT_GT(e4 / e7, 30) << route << ": " << e4 << " -> " << e7;
    EXPECT_GT(e7 / e10, 30) << route << ": " << e7 << " -> " << e10;
    EXPECT_LT(e10, 1e-7) << route;
    EXPECT_GT(e10, 1e-13) << route;
  }
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("Speed against accuracy"), std::string::npos);
  EXPECT_NE(html.find("the reference of truss is truss-dae, of truss-dae is truss"),
            std::string::npos);
  if (!find_gnuplot().empty()) {
    for (const char* f : {"methods", "truss", "truss-dae"}) {
      EXPECT_NE(html.find(std::string("id=\"chart-work-precision-") + f + "\""), std::string::npos)
          << f;
    }
  }
  EXPECT_LT(html.find("Speed against accuracy"), html.find("<h2>Data files</h2>"));
}

// The driven rows by method and samples.
std::map<Method, std::map<int, const DrivenConvergenceRow*>> by_method(
    const std::vector<DrivenConvergenceRow>& rows) {
  std::map<Method, std::map<int, const DrivenConvergenceRow*>> of;
  for (const DrivenConvergenceRow& r : rows) of[r.method][r.samples] = &r;
  return of;
}

// Spectral convergence: each doubling from 4 to 16 samples gains more than the previous one by
// a factor > 10 (a power law would gain a constant factor), and at 360 samples both errors are
// below 1e-12, a thousand times the round-off measured there (<= 2e-15).
void expect_spectral(const std::map<int, const DrivenConvergenceRow*>& rows,
                     const std::string& what) {
  const DrivenConvergenceRow& at360 = *rows.at(360);
  EXPECT_LT(at360.Fsh_rms_error, 1e-12) << what;
  EXPECT_LT(at360.Msh_rms_error, 1e-12) << what;
  const double e4 = rows.at(4)->Fsh_rms_error, e8 = rows.at(8)->Fsh_rms_error,
               e16 = rows.at(16)->Fsh_rms_error;
  EXPECT_GT(e4 / e8, 5) << what;
  EXPECT_GT(e8 / e16, 10 * (e4 / e8)) << what;
}

// ---------------------------------------------------------------------------------------------
// The driven paper example: the RMS over evenly spaced samples of a revolution is the
// trapezoidal rule of a smooth periodic function, exact for its Fourier modes below the sample
// count, so its error falls geometrically with the samples until round-off. Measured relative
// errors (Fsh_rms / Msh_rms): 4.2e-2 / 3.6e-1 at 4 samples, 3.7e-6 / 4.3e-4 at 16, 1.3e-12 /
// 1.9e-10 at 32, <= 2e-15 from 48 on (a few ulps of sums of 4096 terms), the same for every
// method: the general engine (truss, referenced by mass-matrix) computes the same samples.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, DrivenRmsConvergesSpectrallyWithTheSamples) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  const BenchOptions options = BenchOptions::quick();
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  EXPECT_EQ(result.csv, dir_ / "driven-convergence.csv");
  const std::vector<DrivenConvergenceRow>& rows = result.driven_rows;
  ASSERT_EQ(rows.size(), 4 * options.samples.size());  // 3 formulations and truss
  for (const DrivenConvergenceRow& r : rows) {
    EXPECT_EQ(r.status, core::SimulationStatus::kCompleted) << r.message;
    EXPECT_NE(r.reference_method, r.method);
    if (r.method == Method::kTruss) {
      EXPECT_EQ(r.reference_method, Method::kMassMatrix);
    }
    EXPECT_EQ(r.reference_samples, 4096);
    EXPECT_GT(r.cpu_time, 0);
  }
  const auto of = by_method(rows);
  ASSERT_EQ(of.size(), 4u);
  ASSERT_EQ(of.count(Method::kTruss), 1u);
  for (const auto& [m, by_samples] : of) {
    const std::string what = to_string(m);
    expect_spectral(by_samples, what);
    EXPECT_GT(by_samples.at(360)->Fsh_rms, 100);  // 169.86 N: the RMS itself, not an error
    // the general engine's RMS at every sample count equals the closed form's: the same samples
    // of the same motion (measured to 3e-16 relative; 1e-12 allows the engine's Newton
    // positions, solved to 1e-15 of the linkage's size)
    for (const auto& [n, row] : by_samples) {
      EXPECT_NEAR(row->Fsh_rms, of.at(Method::kMassMatrix).at(n)->Fsh_rms, 1e-12 * row->Fsh_rms)
          << what << " " << n;
    }
  }
  const std::string csv = read(result.csv);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), kDrivenConvergenceHeader);
  EXPECT_NE(csv.find("\ntruss,360,mass-matrix,4096,completed,"), std::string::npos);
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("Speed against accuracy"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"driven-convergence.csv\">"), std::string::npos);
  EXPECT_NE(html.find("of truss is mass-matrix"), std::string::npos);
  if (!find_gnuplot().empty()) {
    EXPECT_NE(html.find("id=\"chart-driven-convergence-error\""), std::string::npos);
    EXPECT_NE(html.find("id=\"chart-driven-convergence-time\""), std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------------
// A planar linkage's driven revolution (the engine at 3000 rpm): truss rows only (a driven scene
// has no route), referenced by a 4096-sample truss revolution. Spectral too: measured Fsh_rms
// errors 4.9e-3, 7.2e-6, 4.9e-12 at 4, 8, 16 samples, <= 4e-16 from 24 on (Msh_rms: 3.2e-2,
// 4.8e-5, 3.5e-11, <= 1.2e-15): the slider-crank's motion has fewer harmonics than the paper
// four-bar's.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, PlanarDrivenRmsConvergesSpectrallyWithTheSamples) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank.yaml");
  const BenchOptions options = BenchOptions::quick();
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  ASSERT_EQ(result.driven_rows.size(), options.samples.size());
  for (std::size_t k = 0; k < result.driven_rows.size(); ++k) {
    const DrivenConvergenceRow& r = result.driven_rows[k];
    EXPECT_EQ(r.method, Method::kTruss);
    EXPECT_EQ(r.reference_method, Method::kTruss);
    EXPECT_EQ(r.samples, options.samples[k]);
    EXPECT_EQ(r.status, core::SimulationStatus::kCompleted) << r.message;
  }
  const auto of = by_method(result.driven_rows);
  expect_spectral(of.at(Method::kTruss), "truss");
  EXPECT_GT(of.at(Method::kTruss).at(360)->Fsh_rms, 1000);  // 3797 N
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("samples per revolution"), std::string::npos);
  if (!find_gnuplot().empty()) {
    EXPECT_NE(html.find("id=\"chart-driven-convergence-error\""), std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------------
// A planar driven scene over a duration: `samples` over it, both ends included. Not periodic, so
// the RMS is a mean whose ends carry a bias O(1/samples): each doubling halves the error
// (measured Fsh_rms error ratios 2.0-2.35 per doubling, e.g. 1.0e-2 at 16, 5.0e-3 at 32 and
// 1.8e-4 at 720 samples). Bounds 1.6-2.6: first order, neither stalled nor spectral.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, PlanarDrivenSceneOverADurationConvergesAtFirstOrder) {
  const Study study = parse_study(bd::testing::piston_driven_slider_crank(0.5, 101), "piston.yaml");
  const BenchOptions options = BenchOptions::quick();
  const BenchResult result = run_bench(study, dir_, options);
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  ASSERT_EQ(result.driven_rows.size(), options.samples.size());
  for (const DrivenConvergenceRow& r : result.driven_rows) {
    EXPECT_EQ(r.status, core::SimulationStatus::kCompleted) << r.message;
  }
  const auto of = by_method(result.driven_rows);
  const auto& rows = of.at(Method::kTruss);
  for (const auto& [n, m] : std::vector<std::pair<int, int>>{
           {8, 16}, {16, 32}, {32, 64}, {64, 128}, {180, 360}, {360, 720}}) {
    const double gain = rows.at(n)->Fsh_rms_error / rows.at(m)->Fsh_rms_error;
    EXPECT_GT(gain, 1.6) << n << " -> " << m;
    EXPECT_LT(gain, 2.6) << n << " -> " << m;
  }
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("samples over the duration"), std::string::npos);
  EXPECT_NE(html.find("converges like a power of the samples"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Runs that stop part-way keep their rows and are counted. A planar triple rocker (the
// four-bar of triple-rocker-free.yaml drawn as a planar linkage) swings from its crank at 1 rad/s
// into its limit position at t = 1.30 s (crank 1.553 rad): the truss route, reduced to the
// crank angle, stops there (a limit position: found by the root function, or where an explicit
// pair's stage lands beyond it), the truss-dae route goes through. The truss rows keep their
// samples up to the stop (65 of 201) and their error over them against truss-dae's reference
// (measured at most 5.9e-5 at tolerance 1e-6: integration error, bound 1e-3); truss-dae is
// referenced by itself, as the other route cannot follow the motion.
// ---------------------------------------------------------------------------------------------

constexpr const char* kPlanarTripleRocker =
    "name: planar-triple-rocker\n"
    "linkage:\n"
    "  type: planar\n"
    "  nodes:\n"
    "    A0: {at: [0, 0], ground: true}\n"
    "    A1: [2.0, 0]\n"
    "    A2: [2.75, 1.8540496217739157]\n"
    "    A3: {at: [3.5, 0], ground: true}\n"
    "  links:\n"
    "    crank:   {nodes: [A0, A1], mass: 1.0, e: 0.8, f: 0.1, inertia: 0.4}\n"
    "    coupler: {nodes: [A1, A2], mass: 1.5, e: 1.0, f: 0.0, inertia: 0.6}\n"
    "    rocker:  {nodes: [A2, A3], mass: 1.2, e: 0.9, f: -0.1, inertia: 0.5}\n"
    "  inputs:\n"
    "    crank: {link: crank}\n"
    "scene: {type: free, rates: [1.0], duration: 4.0, samples: 201}\n";

TEST_F(WorkPrecisionTest, APlanarFreeBenchKeepsTheRowsOfRunsStoppedAtALimitPosition) {
  const Study study = parse_study(kPlanarTripleRocker, "rocker.yaml");
  BenchOptions options = BenchOptions::quick();
  options.tolerances = {1e-6};
  std::vector<std::string> progress;
  options.progress = [&](const std::string& line) { progress.push_back(line); };
  const BenchResult result = run_bench(study, dir_, options);
  // the study's own run (auto) repeats itself on the DAE at the limit, and completes
  ASSERT_TRUE(result.run.ok()) << result.run.status().message;
  ASSERT_EQ(result.free_rows.size(), 16u);
  EXPECT_EQ(result.stopped_early(), 8u);
  for (const WorkPrecisionRow& row : result.free_rows) {
    const std::string what = std::string(to_string(row.method)) + " / " +
                             core::to_string(row.integrator) + ": " + row.message;
    if (row.method == Method::kTruss) {
      EXPECT_EQ(row.status, core::SimulationStatus::kSingular) << what;
      EXPECT_NE(row.message.find("limit position reached"), std::string::npos) << what;
      EXPECT_GE(row.samples, 60u) << what;
      EXPECT_LE(row.samples, 70u) << what;
      EXPECT_TRUE(std::isnan(row.final_error)) << what;
      EXPECT_TRUE(std::isnan(row.digits)) << what;
      EXPECT_GT(row.max_error, 0) << what;
      EXPECT_LT(row.max_error, 1e-3) << what;
      EXPECT_EQ(row.reference_method, Method::kTrussDae) << what;
      EXPECT_GT(row.cpu_time, 0) << what;
    } else {
      EXPECT_EQ(row.status, core::SimulationStatus::kCompleted) << what;
      EXPECT_EQ(row.samples, 201u) << what;
      EXPECT_EQ(row.reference_method, Method::kTrussDae) << what;
      EXPECT_LT(row.final_error, 1e-3) << what;
    }
  }
  // the file keeps every row with its status and message; the progress and the page say so
  const FreeRows r = free_rows(result.csv);
  EXPECT_EQ(r.of.size(), 16u);
  const auto& stopped = r.of.at({"truss", "cvode-adams"}).front();
  EXPECT_EQ(r.at(stopped, "status"), "singular");
  EXPECT_NE(r.at(stopped, "message").find("limit position reached at t = 1.2"), std::string::npos)
      << r.at(stopped, "message");
  EXPECT_EQ(r.at(stopped, "final_error"), "");
  ASSERT_EQ(progress.size(), 16u);
  EXPECT_NE(progress.front().find("bench: truss / cvode-adams"), std::string::npos);
  EXPECT_NE(progress.front().find("1e-06: singular;"), std::string::npos) << progress.front();
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("8 of 16 runs stopped before the end of the scene"), std::string::npos);
  EXPECT_NE(html.find("the first: truss / cvode-adams at 1e-06, singular: limit position"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// A planar driven scene that fails part-way: the piston driven past its top dead centre, where
// the linkage cannot be assembled (t = 0.92 s of 1.5 s). Every row keeps the RMS over the
// samples computed and says how it stopped; the errors are NaN (no complete reference); the
// study's own run stopped early too.
// ---------------------------------------------------------------------------------------------

TEST_F(WorkPrecisionTest, APlanarDrivenBenchKeepsTheRowsOfRunsThatCannotBeAssembled) {
  // the loader refuses a driven scene past the linkage's reach (the run would stop there): the
  // scene is lengthened after loading, as the library takes any scene
  Study study = parse_study(bd::testing::piston_driven_slider_crank(0.5, 101), "piston.yaml");
  std::get<core::planar::DrivenScene>(study.scene).duration = 1.5;
  BenchOptions options = BenchOptions::quick();
  options.samples = {16, 64, 360};
  const BenchResult result = run_bench(study, dir_, options);
  EXPECT_FALSE(result.run.ok());
  EXPECT_EQ(result.run.status().status, core::SimulationStatus::kAssemblyFailed);
  ASSERT_EQ(result.driven_rows.size(), 3u);
  EXPECT_EQ(result.stopped_early(), 3u);
  for (const DrivenConvergenceRow& row : result.driven_rows) {
    EXPECT_EQ(row.status, core::SimulationStatus::kAssemblyFailed) << row.message;
    EXPECT_NE(row.message.find("cannot be assembled at piston = 0.18"), std::string::npos)
        << row.message;
    EXPECT_TRUE(std::isfinite(row.Fsh_rms) && row.Fsh_rms > 0) << row.samples;
    EXPECT_TRUE(std::isnan(row.Fsh_rms_error));
    EXPECT_TRUE(std::isnan(row.Msh_rms_error));
  }
  const std::string csv = read(result.csv);
  EXPECT_NE(csv.find("\ntruss,64,truss,4096,assembly-failed,"), std::string::npos) << csv;
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("3 of 3 runs stopped before the end of the scene"), std::string::npos);
}

// the paper four-bar's driven study benched into `dir` (quick, at 8 and 360 samples): the
// options, for a bench after it
BenchOptions bench_driven(const fs::path& dir) {
  BenchOptions options = BenchOptions::quick();
  options.samples = {8, 360};
  run_bench(load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml"), dir, options);
  EXPECT_TRUE(fs::exists(dir / "driven-convergence.csv"));
  return options;
}

TEST_F(WorkPrecisionTest, ABenchRemovesEarlierMeasurementsOfTheOtherSceneType) {
  // a folder measured as driven, then benched with a free study: no stale driven rows in it
  BenchOptions options = bench_driven(dir_);
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

TEST_F(WorkPrecisionTest, ARunOfAnotherStudyRemovesTheFoldersMeasurements) {
  // a bench's measurements stay for a run of the same study file, and go with another study's:
  // its report would show another linkage's speed against accuracy
  bench_driven(dir_);
  run_study(load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml"), dir_);
  EXPECT_TRUE(fs::exists(dir_ / "driven-convergence.csv"));
  EXPECT_NE(read(dir_ / "report.html").find("driven-convergence.csv"), std::string::npos);
  run_study(load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank.yaml"), dir_);
  EXPECT_FALSE(fs::exists(dir_ / "driven-convergence.csv"));
  EXPECT_EQ(read(dir_ / "report.html").find("driven-convergence.csv"), std::string::npos);
}

TEST(WorkPrecision, SceneTypeAndOptionsAreChecked) {
  const Study free = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  const Study driven = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  EXPECT_THROW(work_precision(driven, BenchOptions::quick()), InputError);
  EXPECT_THROW(driven_convergence(free, BenchOptions::quick()), InputError);
  const Study planar_driven =
      load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank.yaml");
  EXPECT_THROW(work_precision(planar_driven, BenchOptions::quick()), InputError);
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

TEST(WorkPrecision, MethodsAndTheirReferencesByLinkageAndScene) {
  using M = Method;
  const Study free = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  const Study driven = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  const Study planar_free =
      load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank-free.yaml");
  const Study planar_driven =
      load_study(BD_SOURCE_DIR "/studies/examples/engine-slider-crank.yaml");
  EXPECT_EQ(bench_methods(free), (std::vector<M>{M::kMassMatrix, M::kOpenedLoop, M::kComplexMasses,
                                                 M::kTruss, M::kTrussDae}));
  EXPECT_EQ(bench_methods(driven),
            (std::vector<M>{M::kMassMatrix, M::kOpenedLoop, M::kComplexMasses, M::kTruss}));
  EXPECT_EQ(bench_methods(planar_free), (std::vector<M>{M::kTruss, M::kTrussDae}));
  EXPECT_EQ(bench_methods(planar_driven), (std::vector<M>{M::kTruss}));
  EXPECT_EQ(reference_methods(free, M::kMassMatrix), (std::vector<M>{M::kComplexMasses}));
  EXPECT_EQ(reference_methods(free, M::kComplexMasses), (std::vector<M>{M::kMassMatrix}));
  for (M m : {M::kOpenedLoop, M::kTruss, M::kTrussDae}) {
    EXPECT_EQ(reference_methods(free, m),
              (std::vector<M>{M::kMassMatrix, M::kComplexMasses, M::kOpenedLoop}))
        << to_string(m);
  }
  EXPECT_EQ(reference_methods(driven, M::kTruss), (std::vector<M>{M::kMassMatrix}));
  EXPECT_EQ(reference_methods(driven, M::kMassMatrix), (std::vector<M>{M::kComplexMasses}));
  EXPECT_EQ(reference_methods(planar_free, M::kTruss), (std::vector<M>{M::kTrussDae, M::kTruss}));
  EXPECT_EQ(reference_methods(planar_free, M::kTrussDae),
            (std::vector<M>{M::kTruss, M::kTrussDae}));
  EXPECT_EQ(reference_methods(planar_driven, M::kTruss), (std::vector<M>{M::kTruss}));
  // a four-bar with counter-rotating inertias: the general engine models them as balance shafts
  const Study with_discs = balanced_study(
      load_study(BD_SOURCE_DIR "/studies/examples/berkof-inline-moment-balanced.yaml"));
  ASSERT_TRUE(core::has_counter_rotations(with_discs.fourbar()));
  std::vector<M> all = {M::kMassMatrix, M::kOpenedLoop, M::kComplexMasses, M::kTruss};
  if (is_free(with_discs.scene)) all.push_back(M::kTrussDae);
  EXPECT_EQ(bench_methods(with_discs), all);
}

TEST(WorkPrecision, CsvWritesNanAsEmptyAndQuotesMessages) {
  WorkPrecisionRow r;
  r.method = Method::kTrussDae;
  r.reference_method = Method::kTruss;
  r.tolerance = 1e-10;
  r.final_error = NAN;
  r.digits = NAN;
  r.max_error = 0.125;
  r.status = core::SimulationStatus::kSingular;
  r.message = "singular position at t = 1 s, theta1 = 2 rad: \"quoted\"";
  const std::string csv = work_precision_csv({r});
  EXPECT_NE(csv.find("\ntruss-dae,cvode-adams,1e-10,truss,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",singular,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",,,0.125,\"singular position at t = 1 s, theta1 = 2 rad: \"\"quoted\"\"\"\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",1e-10,"), std::string::npos) << csv;  // "%.17g": 1e-10 reads back exactly
}

TEST(WorkPrecision, NoSectionWithoutMeasurements) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  EXPECT_EQ(work_precision_section(study, fs::temp_directory_path() / "bd-no-such-folder", ""), "");
}

}  // namespace
}  // namespace bd::studies
