// The study runner: timeseries.csv and summary.json follow the v1 output contract (exact header,
// one row per sample, %.17g round-trip), files are written atomically, and a simulation that
// stops early still leaves its samples and a summary saying why.
#include "studies/run/runner.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/method.hpp"
#include "tests/support/csv.hpp"
#include "tests/support/json_view.hpp"
#include "tests/support/models.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

// a fresh directory for one test, removed afterwards
class RunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_runner_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

using bd::testing::read;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<double> fields_of(const std::string& line) {
  std::vector<double> v;
  std::istringstream in(line);
  for (std::string f; std::getline(in, f, ',');) {
    char* end = nullptr;
    v.push_back(std::strtod(f.c_str(), &end));
    EXPECT_EQ(*end, '\0') << "not a number: " << f;
  }
  return v;
}

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// every value of every row equals the sample bit for bit (%.17g round-trips a double)
void expect_rows_match(const std::vector<std::string>& lines, const core::Trajectory& tr) {
  ASSERT_EQ(lines.size(), tr.samples.size() + 1);
  for (std::size_t i = 0; i < tr.samples.size(); ++i) {
    const std::vector<double> row = fields_of(lines[i + 1]);
    ASSERT_EQ(row.size(), 32u) << "row " << i;
    const core::DynamicsSample& d = tr.samples[i];
    const core::FourBarState& s = d.state;
    const double expected[] = {tr.t[i],   s.theta1,  s.theta2,  s.theta3,  s.omega1,  s.omega2,
                               s.omega3,  s.alpha1,  s.alpha2,  s.alpha3,  d.RA0.x(), d.RA0.y(),
                               d.RA3.x(), d.RA3.y(), d.Fsh.x(), d.Fsh.y(), d.Msh,     d.tau,
                               d.Fsh_inertial.x(), d.Fsh_inertial.y(), d.Msh_inertial,
                               d.Fsh_static.x(), d.Fsh_static.y(), d.Msh_static,
                               d.RC1.x(), d.RC1.y(), d.RC3.x(), d.RC3.y(),
                               d.FA1.x(), d.FA1.y(), d.FA2.x(), d.FA2.y()};
    for (std::size_t k = 0; k < std::size(expected); ++k) {
      EXPECT_EQ(row[k], expected[k]) << "row " << i << " column " << k;
    }
  }
}

TEST_F(RunnerTest, FreeSceneWritesTheContractFiles) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  const fs::path out = dir_ / "nested" / "out";  // created by run_study
  const RunResult r = run_study(study, out);
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  EXPECT_EQ(r.timeseries, out / "timeseries.csv");
  EXPECT_EQ(r.summary, out / "summary.json");
  EXPECT_EQ(r.method.formulation, choose_method(study).formulation);
  EXPECT_EQ(r.method.reason, choose_method(study).reason);

  // nothing but the final files (the study's copy among them): no temporary left behind
  EXPECT_EQ(names_in(out), (std::set<std::string>{"report.html", "study.yaml", "summary.json",
                                                  "timeseries.csv"}));
  EXPECT_EQ(read(out / "study.yaml"), read(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml"));

  const std::vector<std::string> lines = lines_of(read(r.timeseries));
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0],
            "t,theta1,theta2,theta3,omega1,omega2,omega3,alpha1,alpha2,alpha3,RA0x,RA0y,RA3x,"
            "RA3y,Fshx,Fshy,Msh,tau,Fshx_inertial,Fshy_inertial,Msh_inertial,Fshx_static,"
            "Fshy_static,Msh_static,RC1x,RC1y,RC3x,RC3y,FA1x,FA1y,FA2x,FA2y");
  EXPECT_EQ(lines.size(), 502u);  // header + 501 samples
  expect_rows_match(lines, r.trajectory);
  EXPECT_EQ(fields_of(lines[1])[0], 0.0);
  EXPECT_EQ(fields_of(lines.back())[0], 5.0);
  EXPECT_EQ(fields_of(lines[1])[1], 1.0);  // theta1 at t = 0

  const std::string json = bd::testing::json_view(read(r.summary));
  for (const char* key : {"\"study\": \"paper-fourbar\"",
                          "\"method\"",
                          "\"used\": \"mass-matrix\"",
                          "\"reason\"",
                          "\"scene\": {\"type\": \"free\"",
                          "\"duration\": 5",
                          "\"samples\": 501",
                          "\"status\"",
                          "\"message\"",
                          "\"ok\": true",
                          "\"steps\"",
                          "\"rhs_evaluations\"",
                          "\"metrics\"",
                          "\"Fsh_rms\"",
                          "\"Fsh_max\"",
                          "\"Msh_rms\"",
                          "\"Msh_max\"",
                          "\"tau_rms\"",
                          "\"tau_max\"",
                          "\"RA0_max\"",
                          "\"RA3_max\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " missing in\n" << json;
  }
  // metrics printed with %.17g
  char buf[64];
  std::snprintf(buf, sizeof buf, "\"Fsh_max\": %.17g", r.metrics.Fsh_max);
  EXPECT_NE(json.find(buf), std::string::npos) << buf;
  EXPECT_GT(r.metrics.Fsh_max, 0.0);
}

TEST_F(RunnerTest, DrivenSceneWritesOneRowPerSampleAndSaysWhyNoIntegrator) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  const std::vector<std::string> lines = lines_of(read(r.timeseries));
  EXPECT_EQ(lines.size(), 361u);  // header + 360 samples, periodic end excluded
  expect_rows_match(lines, r.trajectory);
  EXPECT_NE(r.method.reason.find("nothing integrated"), std::string::npos) << r.method.reason;
  const std::string json = bd::testing::json_view(read(r.summary));
  EXPECT_NE(json.find("\"scene\": {\"type\": \"driven\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"revolutions\": 1"), std::string::npos) << json;
  EXPECT_NE(json.find("\"numerics\": \"none: inverse dynamics at each sample\""), std::string::npos)
      << json;
  EXPECT_GT(r.metrics.tau_max, 0.0);
  EXPECT_EQ(names_in(dir_),
            (std::set<std::string>{"harmonics.csv", "report.html", "study.yaml", "summary.json",
                                   "timeseries.csv"}));
}

TEST_F(RunnerTest, RunningAgainReplacesTheFiles) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  run_study(study, dir_);
  const std::string first = read(dir_ / "timeseries.csv");
  run_study(study, dir_);
  EXPECT_EQ(read(dir_ / "timeseries.csv"), first);
  EXPECT_EQ(names_in(dir_),
            (std::set<std::string>{"harmonics.csv", "report.html", "study.yaml", "summary.json",
                                   "timeseries.csv"}));
}

TEST_F(RunnerTest, SimulationStoppedEarlyKeepsItsSamplesAndSaysWhy) {
  // crank 2.5 on frame 3.2 with rocker 2: the crank cannot turn fully, so driving it from
  // pi/2 reaches an angle where the loop cannot close
  Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  study.fourbar().crank = core::link_from_polar(2.5, 2.1, 0.6, 0.3, 1.1);
  std::get<core::DrivenScene>(study.scene).theta1 = M_PI / 2;
  const RunResult r = run_study(study, dir_);
  ASSERT_FALSE(r.ok());
  EXPECT_FALSE(r.trajectory.samples.empty());
  EXPECT_LT(r.trajectory.samples.size(), 360u);
  const std::vector<std::string> lines = lines_of(read(r.timeseries));
  expect_rows_match(lines, r.trajectory);
  const std::string json = bd::testing::json_view(read(r.summary));
  EXPECT_NE(json.find("\"ok\": false"), std::string::npos) << json;
  EXPECT_NE(json.find(nlohmann::json(r.trajectory.message).dump()), std::string::npos) << json;
  EXPECT_NE(json.find(std::string("\"status\": \"") + core::to_string(r.trajectory.status)),
            std::string::npos);
  EXPECT_EQ(names_in(dir_),
            (std::set<std::string>{"report.html", "study.yaml", "summary.json", "timeseries.csv"}));
}

TEST_F(RunnerTest, InvalidSceneCreatesNothing) {
  Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  std::get<core::DrivenScene>(study.scene).omega1 = 0.0;  // core rejects it
  const fs::path out = dir_ / "never";
  EXPECT_THROW(run_study(study, out), InputError);
  EXPECT_FALSE(fs::exists(out));
}

// ---- balance studies ----

// (driven scenes: with the harmonic orders of both designs)
const std::set<std::string> kBalanceFiles = {
    "balanced-timeseries.csv", "balanced.yaml", "comparison.csv", "harmonics.csv", "report.html",
    "study.yaml",              "summary.json",  "timeseries.csv"};

// the value of `"key": ` in the JSON text after `from` (a number or null)
std::string json_value(const std::string& json, const std::string& key, std::size_t from = 0) {
  const std::string k = "\"" + key + "\": ";
  const auto at = json.find(k, from);
  if (at == std::string::npos) return "missing";
  const auto begin = at + k.size();
  return json.substr(begin, json.find_first_of(",\n}", begin) - begin);
}

TEST_F(RunnerTest, MomentBalanceStudyWritesBothDesignsAndTheComparison) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/berkof-inline-moment-balanced.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  ASSERT_TRUE(r.balanced.has_value());
  const BalancedRun& b = *r.balanced;
  ASSERT_TRUE(b.trajectory.ok()) << b.trajectory.message;
  EXPECT_EQ(names_in(dir_), kBalanceFiles);
  EXPECT_EQ(b.timeseries, dir_ / "balanced-timeseries.csv");
  EXPECT_EQ(b.study_file, dir_ / "balanced.yaml");
  EXPECT_EQ(b.comparison, dir_ / "comparison.csv");
  EXPECT_EQ(b.method.formulation, choose_method(balanced_study(study)).formulation);

  // timeseries.csv is the original's, balanced-timeseries.csv the balanced design's
  expect_rows_match(lines_of(read(r.timeseries)), r.trajectory);
  const std::vector<std::string> rows = lines_of(read(b.timeseries));
  EXPECT_EQ(rows[0], kTimeseriesHeader);
  expect_rows_match(rows, b.trajectory);

  // shaking force and moment vanish to round-off, measured against the original's
  EXPECT_GT(r.metrics.Fsh_max, 100.0);
  EXPECT_LT(b.metrics.Fsh_max, 1e-12 * r.metrics.Fsh_max);
  EXPECT_LT(b.metrics.Msh_max, 1e-12 * r.metrics.Msh_max);
  EXPECT_GT(b.metrics.tau_max, r.metrics.tau_max);  // the price: discs to accelerate
}

TEST_F(RunnerTest, ComparisonCsvHasEveryMetricBeforeAfterAndRatio) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  EXPECT_EQ(names_in(dir_), kBalanceFiles);
  const std::vector<std::string> lines = lines_of(read(r.balanced->comparison));
  ASSERT_EQ(lines.size(), 19u);
  EXPECT_EQ(lines[0], "metric,before,after,ratio");
  const char* names[] = {"Fsh_rms",       "Fsh_max",       "Msh_rms",       "Msh_max",
                         "tau_rms",       "tau_max",       "RA0_rms",       "RA0_max",
                         "RA3_rms",       "RA3_max",       "Fsh_total_rms", "Fsh_total_max",
                         "Msh_total_rms", "Msh_total_max", "FA1_max",       "FA2_max",
                         "added_mass",    "added_inertia"};
  auto values = [](const core::Metrics& m, double mass, double inertia) {
    return std::vector<double>{m.Fsh_rms,       m.Fsh_max,       m.Msh_rms,       m.Msh_max,
                               m.tau_rms,       m.tau_max,       m.RA0_rms,       m.RA0_max,
                               m.RA3_rms,       m.RA3_max,       m.Fsh_total_rms, m.Fsh_total_max,
                               m.Msh_total_rms, m.Msh_total_max, m.FA1_max,       m.FA2_max,
                               mass,            inertia};
  };
  const core::Metrics& a = r.metrics;
  const core::Metrics& z = r.balanced->metrics;
  const std::vector<double> before = values(r.metrics, 0.0, 0.0);
  const std::vector<double> after =
      values(r.balanced->metrics, study.balance->added_mass, study.balance->added_inertia);
  for (std::size_t i = 0; i < std::size(names); ++i) {
    const std::string& line = lines[i + 1];
    const auto comma = line.find(',');
    EXPECT_EQ(line.substr(0, comma), names[i]);
    const std::vector<double> v =
        fields_of(line.substr(comma + 1) + (line.back() == ',' ? "0" : ""));
    ASSERT_EQ(v.size(), 3u) << line;
    EXPECT_EQ(v[0], before[i]) << line;  // %.17g: bit for bit
    EXPECT_EQ(v[1], after[i]) << line;
    if (before[i] == 0) {
      EXPECT_EQ(line.back(), ',') << "ratio must be empty: " << line;
    } else {
      EXPECT_EQ(v[2], after[i] / before[i]) << line;
    }
  }
  // RA0_rms, RA3_rms: RMS of the magnitudes over the samples
  double sq0 = 0, sq3 = 0;
  for (const core::DynamicsSample& d : r.trajectory.samples) {
    sq0 += d.RA0.squaredNorm();
    sq3 += d.RA3.squaredNorm();
  }
  const double n = static_cast<double>(r.trajectory.samples.size());
  EXPECT_NEAR(a.RA0_rms, std::sqrt(sq0 / n), 1e-13 * a.RA0_rms);
  EXPECT_NEAR(a.RA3_rms, std::sqrt(sq3 / n), 1e-13 * a.RA3_rms);
  // force balanced: the shaking force is gone, |RA0| = |RA3| since RA0 + RA3 = 0
  EXPECT_LT(z.Fsh_max, 1e-12 * a.Fsh_max);
  EXPECT_NEAR(z.RA0_rms, z.RA3_rms, 1e-12 * z.RA0_rms);
  EXPECT_GT(study.balance->added_mass, 0.0);
}

TEST_F(RunnerTest, SummaryJsonExtendsTheContractWithTheBalancedDesign) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/berkof-inline-moment-balanced.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const std::string json = bd::testing::json_view(read(r.summary));
  // the v1 keys, for the original design
  for (const char* key : {"\"study\": \"berkof-inline-moment-balanced\"", "\"method\"",
                          "\"scene\": {\"type\": \"driven\"", "\"ok\": true", "\"metrics\"",
                          "\"RA0_max\"", "\"RA0_rms\"", "\"RA3_rms\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " missing in\n" << json;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "\"Fsh_max\": %.17g", r.metrics.Fsh_max);
  EXPECT_LT(json.find(buf), json.find("\"balance\"")) << "metrics are the original's";
  // the balance section
  for (const char* key : {"\"balance\": {",
                          "\"force\": \"full\"",
                          "\"moment\": \"full\"",
                          "\"counterweights\": [",
                          "{\"link\": \"crank\", \"shape\": \"point\", \"mass\": ",
                          "\"position\": [",
                          "\"distance\": ",
                          "\"radius\": ",
                          "\"thickness\": ",
                          "\"counter_rotations\": [",
                          "{\"link\": \"rocker\", \"inertia\": ",
                          "\"at\": [",
                          "\"added_mass\": ",
                          "\"added_inertia\": ",
                          "\"force_balanced\": true",
                          "\"moment_balanced\": true",
                          "\"conditions\": [",
                          "{\"name\": \"force.crank\", \"residual\": ",
                          "\"holds\": true",
                          "\"balanced_run\": {",
                          "\"study\": \"berkof-inline-moment-balanced-balanced\"",
                          "\"balanced_metrics\": {",
                          "\"reduction\": {"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " missing in\n" << json;
  }
  EXPECT_EQ(json.find("\"holds\": false"), std::string::npos) << json;
  std::snprintf(buf, sizeof buf, "%.17g", study.balance->added_mass);
  EXPECT_EQ(json_value(json, "added_mass"), buf);
  // reduction = balanced / original, per metric
  const auto red = json.find("\"reduction\"");
  std::snprintf(buf, sizeof buf, "%.17g", r.balanced->metrics.tau_max / r.metrics.tau_max);
  EXPECT_EQ(json_value(json, "tau_max", red), buf);
  std::snprintf(buf, sizeof buf, "%.17g", r.balanced->metrics.RA3_rms / r.metrics.RA3_rms);
  EXPECT_EQ(json_value(json, "RA3_rms", red), buf);
  std::snprintf(buf, sizeof buf, "%.17g", r.balanced->metrics.Msh_max);
  EXPECT_EQ(json_value(json, "Msh_max", json.find("\"balanced_metrics\"")), buf);
  EXPECT_EQ(json.back(), '\n');
  EXPECT_EQ(json[json.size() - 2], '}');
}

TEST_F(RunnerTest, ZeroOriginalMetricGivesNullReductionAndEmptyRatio) {
  // a free scene has no drive torque: tau is 0 before and after
  const std::string text =
      read(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml") + "balance: {force: full}\n";
  const Study study = parse_study(text, "free.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.trajectory.message << " / " << r.balanced->trajectory.message;
  const std::string json = bd::testing::json_view(read(r.summary));
  const auto red = json.find("\"reduction\"");
  EXPECT_EQ(json_value(json, "tau_rms", red), "null");
  EXPECT_EQ(json_value(json, "tau_max", red), "null");
  EXPECT_NE(json_value(json, "Fsh_rms", red), "null");
  const std::string csv = read(r.balanced->comparison);
  EXPECT_NE(csv.find("\ntau_rms,0,0,\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nadded_mass,0,"), std::string::npos) << csv;
}

TEST_F(RunnerTest, BalancedYamlLoadsBackToTheSynthesisedDesignAndReproducesItsRun) {
  for (const char* example :
       {"berkof-inline-moment-balanced.yaml", "paper-fourbar-driven-force-balanced.yaml"}) {
    SCOPED_TRACE(example);
    const Study study = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + example);
    const fs::path out = dir_ / example;
    const RunResult r = run_study(study, out);
    ASSERT_TRUE(r.ok());
    const std::string text = read(r.balanced->study_file);
    EXPECT_EQ(text.rfind("# The balanced design of study '" + study.name + "'", 0), 0u) << text;
    EXPECT_EQ(text.find("balance:"), std::string::npos) << "no balance section:\n" << text;

    // the same model (balanced.yaml writes every number exactly; design_files_test.cpp checks
    // the samples byte for byte, this the model's every value)
    const Study back = load_study(r.balanced->study_file.string());
    EXPECT_EQ(back.name, study.name + "-balanced");
    EXPECT_FALSE(back.balance.has_value());
    bd::testing::expect_same_model(study.balance->model, back.fourbar());

    // and running it reproduces balanced-timeseries.csv (to the last bit: design_files_test.cpp;
    // here to 1e-12 of each column's scale)
    const RunResult again = run_study(back, out / "again");
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again.method.formulation, r.balanced->method.formulation);
    bd::testing::expect_same_numbers(again.timeseries, r.balanced->timeseries, 1e-12);
  }
}

TEST_F(RunnerTest, BalanceStudyStoppedEarlyKeepsEveryFile) {
  // the crank (2.5) cannot turn fully: both designs stop where the loop cannot close
  Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  study.fourbar().crank = core::link_from_polar(2.5, 2.1, 0.6, 0.3, 1.1);
  study.balance = balance::balance_design(study.fourbar(), study.balance->request);
  std::get<core::DrivenScene>(study.scene).theta1 = M_PI / 2;
  const RunResult r = run_study(study, dir_);
  EXPECT_FALSE(r.ok());
  ASSERT_TRUE(r.balanced.has_value());
  EXPECT_FALSE(r.balanced->trajectory.ok());
  EXPECT_FALSE(r.balanced->trajectory.samples.empty());
  std::set<std::string> files = kBalanceFiles;  // no whole revolution: no harmonic orders
  files.erase("harmonics.csv");
  EXPECT_EQ(names_in(dir_), files);
  expect_rows_match(lines_of(read(r.balanced->timeseries)), r.balanced->trajectory);
  const std::string json = bd::testing::json_view(read(r.summary));
  const auto run = json.find("\"balanced_run\"");
  ASSERT_NE(run, std::string::npos);
  EXPECT_EQ(json_value(json, "ok", run), "false");
  EXPECT_NE(json.find(nlohmann::json(r.balanced->trajectory.message).dump(), run),
            std::string::npos);
}

// ---- optimize studies ----

// (driven scenes: with the original's harmonic orders)
const std::set<std::string> kOptimizeFiles = {
    "comparison.csv", "harmonics.csv", "optimized-timeseries.csv", "optimized.yaml",
    "report.html",    "study.yaml",    "summary.json",             "timeseries.csv"};

// the driven paper linkage (paper-fourbar-driven.yaml) with an optimize section appended
Study driven_with(const std::string& optimize_section, const std::string& name) {
  return parse_study(
      read(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml") + optimize_section, name);
}

TEST_F(RunnerTest, OptimizeStudyWritesTheOptimumAndTheComparison) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/berkof-lowen-min-shaking-moment.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.optimized->result.message;
  ASSERT_TRUE(r.optimized.has_value());
  const OptimizedRun& o = *r.optimized;
  EXPECT_TRUE(o.found());
  EXPECT_FALSE(o.failed());
  EXPECT_EQ(names_in(dir_), kOptimizeFiles);
  EXPECT_EQ(o.timeseries, dir_ / "optimized-timeseries.csv");
  EXPECT_EQ(o.study_file, dir_ / "optimized.yaml");
  EXPECT_EQ(o.comparison, dir_ / "comparison.csv");
  EXPECT_TRUE(o.pareto_file.empty());
  EXPECT_EQ(o.method.formulation,
            choose_method(optimized_study(study, o.result.design)).formulation);

  // timeseries.csv is the original's, optimized-timeseries.csv the optimum's
  expect_rows_match(lines_of(read(r.timeseries)), r.trajectory);
  const std::vector<std::string> rows = lines_of(read(o.timeseries));
  EXPECT_EQ(rows[0], kTimeseriesHeader);
  expect_rows_match(rows, o.trajectory);

  // verified by a second formulation
  EXPECT_NE(o.result.verified_with, design_problem(study).formulation);
  EXPECT_LE(o.result.verification_error, 1e-9);

  // force balanced (the equalities hold), and no worse in Msh_rms than the textbook
  // force balance (point masses at l1 and l3), which is one of the feasible designs
  EXPECT_LT(o.metrics.Fsh_max, 1e-6 * r.metrics.Fsh_max);
  const balance::BalancedDesign textbook =
      balance::balance_design(study.fourbar(), balance::BalanceRequest{});
  const core::Trajectory t = core::simulate_driven(
      textbook.model, std::get<core::DrivenScene>(study.scene), core::SimulateOptions{});
  const core::Metrics m = core::metrics(t);
  EXPECT_LT(o.metrics.Msh_rms, m.Msh_rms * (1 + 1e-6));
  // the metrics simulated in the scene are those the optimiser evaluated
  EXPECT_NEAR(o.metrics.Msh_rms, o.result.metrics.Msh_rms, 1e-9 * r.metrics.Msh_rms);

  // comparison.csv: the same rows as a balance study's, for the optimum
  const std::vector<std::string> lines = lines_of(read(o.comparison));
  ASSERT_EQ(lines.size(), 19u);
  EXPECT_EQ(lines[0], "metric,before,after,ratio");
  const std::vector<ComparisonRow> cmp = comparison(study, r);
  ASSERT_EQ(cmp.size(), 18u);
  EXPECT_EQ(cmp[2].metric, "Msh_rms");
  EXPECT_EQ(cmp[2].before, r.metrics.Msh_rms);
  EXPECT_EQ(cmp[2].after, o.metrics.Msh_rms);
  EXPECT_EQ(cmp[16].metric, "added_mass");
  EXPECT_EQ(cmp[16].after, added_mass(study.fourbar(), o.result.design));
  EXPECT_EQ(cmp[17].metric, "added_inertia");
  char buf[128];
  std::snprintf(buf, sizeof buf, "Msh_rms,%.17g,%.17g,%.17g", r.metrics.Msh_rms, o.metrics.Msh_rms,
                o.metrics.Msh_rms / r.metrics.Msh_rms);
  EXPECT_EQ(lines[3], buf);
  EXPECT_EQ(lines[17].rfind("added_mass,0,", 0), 0u) << lines[17];
}

TEST_F(RunnerTest, OptimizeSummaryJsonExtendsTheContract) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/weighted-counterweights.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.optimized->result.message;
  const OptimizedRun& o = *r.optimized;
  const std::string json = bd::testing::json_view(read(r.summary));
  for (const char* key : {"\"study\": \"weighted-counterweights\"",
                          "\"metrics\": {",
                          "\"optimize\": {",
                          "\"algorithm\": \"slsqp\"",
                          "\"formulation\": ",
                          "\"terms\": [",
                          "{\"metric\": \"tau_rms\", \"weight\": 1}",
                          "\"force_balance\": false",
                          "\"limits\": []",
                          "\"termination\": ",
                          "\"message\": ",
                          "\"iterations\": ",
                          "\"evaluations\": ",
                          "\"seconds\": ",
                          "\"objective\": ",
                          "\"constraint_violation\": ",
                          "\"variables\": [",
                          "{\"name\": ",
                          "\"counterweights\": [",
                          "{\"link\": \"crank\", \"shape\": \"point\", \"mass\": ",
                          "{\"link\": \"rocker\", \"shape\": \"disc\", \"mass\": ",
                          "\"added_mass\": ",
                          "\"added_inertia\": ",
                          "\"verified_with\": ",
                          "\"verification_error\": ",
                          "\"brief_report\": ",
                          "\"optimized_run\": {",
                          "\"study\": \"weighted-counterweights-optimized\"",
                          "\"optimized_metrics\": {",
                          "\"reduction\": {"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " missing in\n" << json;
  }
  EXPECT_EQ(json.find("\"balance\""), std::string::npos);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", o.result.objective);
  EXPECT_EQ(json_value(json, "objective", json.find("\"optimize\"")), buf);
  std::snprintf(buf, sizeof buf, "%.17g", o.result.verification_error);
  EXPECT_EQ(json_value(json, "verification_error"), buf);
  EXPECT_LE(o.result.verification_error, 1e-9);
  std::snprintf(buf, sizeof buf, "%.17g", o.metrics.Fsh_rms / r.metrics.Fsh_rms);
  EXPECT_EQ(json_value(json, "Fsh_rms", json.find("\"reduction\"")), buf);
  std::snprintf(buf, sizeof buf, "%.17g", o.metrics.tau_max);
  EXPECT_EQ(json_value(json, "tau_max", json.find("\"optimized_metrics\"")), buf);
  // every variable by name, in the order of x
  ASSERT_EQ(static_cast<std::size_t>(o.result.x.size()), o.variable_names.size());
  EXPECT_EQ(o.design_variables, 6);  // mass, distance, angle per counterweight
  for (std::size_t k = 0; k < o.variable_names.size(); ++k) {
    EXPECT_NE(json.find(nlohmann::json(o.variable_names[k]).dump()), std::string::npos)
        << o.variable_names[k];
  }
  // the weighted sum went down from 3 (each term is 1 for the original)
  EXPECT_LT(o.result.objective, 3.0);
  EXPECT_EQ(json.back(), '\n');
  EXPECT_EQ(json[json.size() - 2], '}');
}

TEST_F(RunnerTest, OptimizedYamlLoadsBackToTheOptimumAndReproducesItsRun) {
  for (const char* example :
       {"berkof-lowen-min-shaking-moment.yaml", "weighted-counterweights.yaml"}) {
    SCOPED_TRACE(example);
    const Study study = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + example);
    const fs::path out = dir_ / example;
    const RunResult r = run_study(study, out);
    ASSERT_TRUE(r.ok());
    const OptimizedRun& o = *r.optimized;
    const std::string text = read(o.study_file);
    EXPECT_EQ(text.rfind("# The optimised design of study '" + study.name + "'", 0), 0u) << text;
    EXPECT_EQ(text.find("optimize:"), std::string::npos) << "no optimize section:\n" << text;
    EXPECT_NE(text.find("counterweight of "), std::string::npos) << text;

    // the same model (every number written exactly)
    const Study back = load_study(o.study_file.string());
    EXPECT_EQ(back.name, study.name + "-optimized");
    EXPECT_FALSE(back.optimize.has_value());
    bd::testing::expect_same_model(o.result.design, back.fourbar());

    // running it reproduces optimized-timeseries.csv to 1e-12 of each column's scale
    const RunResult again = run_study(back, out / "again");
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again.method.formulation, o.method.formulation);
    bd::testing::expect_same_numbers(again.timeseries, o.timeseries, 1e-12);
  }
}

// An optimum without counterweights (weighing the added mass three times against the peak
// shaking force, none pays: the original design is the optimum) writes none as data, only the
// header's words; before, optimized.yaml listed both with mass 0 at a position.
// A force-only balance lists the moment conditions too, each marked as not asked for: a
// designer read their `holds: false` as failures of the balance
TEST_F(RunnerTest, AForceBalanceMarksTheMomentConditionsAsNotAsked) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const nlohmann::json j = nlohmann::json::parse(read(r.summary));
  const nlohmann::json& conditions = j.at("balance").at("conditions");
  int force = 0, moment = 0, moment_failing = 0;
  for (const nlohmann::json& c : conditions) {
    const bool is_force = c.at("name").get<std::string>().starts_with("force.");
    EXPECT_EQ(c.at("asked").get<bool>(), is_force) << c.dump();
    if (is_force) {
      ++force;
      EXPECT_TRUE(c.at("holds").get<bool>()) << c.dump();
    } else {
      ++moment;
      if (!c.at("holds").get<bool>()) ++moment_failing;
    }
  }
  EXPECT_EQ(force, 2);
  EXPECT_EQ(moment, 4);
  EXPECT_GT(moment_failing, 0);  // this coupler is no Berkof coupler
}

TEST_F(RunnerTest, AnOptimumWithoutCounterweightsWritesNone) {
  const Study study = parse_study(
      bd::testing::edited_example("weighted-counterweights.yaml",
                                  {{"  samples: 360", "  samples: 36"},
                                   {"    Fsh_rms: 1.0\n    Msh_rms: 1.0\n    tau_rms: 1.0\n",
                                    "    Fsh_max: 1.0\n    added_mass: 3.0\n"}}),
      "apex.yaml");
  const RunResult r = run_study(study, dir_ / "apex");
  ASSERT_TRUE(r.ok());
  const OptimizedRun& o = *r.optimized;
  ASSERT_EQ(o.result.termination, optimize::Termination::kConverged) << o.result.message;
  EXPECT_TRUE(o.result.global) << o.result.optimality;
  const std::string text = read(o.study_file);
  EXPECT_NE(text.find("The crank carries no counterweight"), std::string::npos) << text;
  EXPECT_NE(text.find("The rocker carries no counterweight"), std::string::npos) << text;
  EXPECT_EQ(text.find("counterweights:"), std::string::npos) << text;
  const Study back = load_study(o.study_file.string());
  bd::testing::expect_same_model(study.fourbar(), back.fourbar());
  // summary.json's variables: each counterweight's mass 0, and no position for it (the solver's
  // x and y there are no design)
  const std::string json = bd::testing::json_view(read(r.summary));
  for (const char* link : {"crank", "rocker"}) {
    const std::string from = std::string(link) == "crank" ? "A0" : "A3";
    EXPECT_NE(json.find("{\"name\": \"" + std::string(link) +
                        " counterweight mass [kg]\", \"value\": 0}"),
              std::string::npos)
        << json;
    for (const char* axis : {"x", "y"}) {
      EXPECT_NE(json.find("{\"name\": \"" + std::string(link) + " counterweight " + axis +
                          " from " + from +
                          " in link axes [m]\", \"value\": null, \"note\": \"no counterweight "
                          "(its mass is 0): no position\"}"),
                std::string::npos)
          << json;
    }
  }
}

// A free scene through limit positions runs on the opened loop, the one closed form that passes
// them; the optimum is then verified on the general planar engine's DAE route, which passes them
// too (the mass matrix, the optimiser's usual second formulation, stops at the first one).
TEST_F(RunnerTest, AFreeOptimumThroughLimitPositionsIsVerifiedOnTheGeneralEngine) {
  const Study study = parse_study(
      bd::testing::edited_example(
          "triple-rocker-free.yaml",
          {{"  duration: 20.0", "  duration: 10.0"},
           {"  samples: 2001", "  samples: 101"},
           {"\nmethod: auto",
            "\nmethod: auto\n"
            "optimize:\n"
            "  objective: {Fsh_rms: 1.0}\n"
            "  variables: {counterweights: {crank: {mass_max: 3.0, distance_max: 1.0}}}\n"
            "  algorithm: cobyla\n"
            "  max_evaluations: 10\n"}}),
      "limits.yaml");
  const RunResult r = run_study(study, dir_ / "limits");
  ASSERT_TRUE(r.ok()) << r.trajectory.message;
  ASSERT_TRUE(r.optimized.has_value());
  const optimize::OptimizeResult& o = r.optimized->result;
  EXPECT_EQ(r.method.formulation, core::Formulation::kOpenedLoop);
  EXPECT_TRUE(o.verified_on_general_engine) << o.message;
  EXPECT_EQ(o.verified_by(), "truss-dae");
  // the two routes agree to their integration tolerance (the study's 1e-10 relative)
  EXPECT_LE(o.verification_error, 1e-7) << o.message;
  const std::string summary = read(dir_ / "limits" / "summary.json");
  EXPECT_NE(summary.find("\"verified_with\": \"truss-dae\""), std::string::npos);
}

TEST_F(RunnerTest, ParetoFrontIsWrittenPointByPoint) {
  const Study study = driven_with(
      "optimize:\n"
      "  objective: {Fsh_rms: 1}\n"
      "  variables:\n"
      "    counterweights: {crank: {mass_max: 10}, rocker: {mass_max: 10}}\n"
      "  pareto: {first: Fsh_rms, second: Msh_rms, points: 3}\n",
      "pareto.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.optimized->result.message;
  const OptimizedRun& o = *r.optimized;
  std::set<std::string> files = kOptimizeFiles;
  files.insert("pareto.csv");
  files.erase("study.yaml");  // a study from text: no file to copy
  EXPECT_EQ(names_in(dir_), files);
  EXPECT_EQ(o.pareto_file, dir_ / "pareto.csv");
  ASSERT_EQ(o.pareto.size(), 3u);
  const std::vector<std::string> lines = lines_of(read(o.pareto_file));
  ASSERT_EQ(lines.size(), 4u);
  std::string header = "epsilon,Fsh_rms,Msh_rms,termination,verification_error";
  for (int k = 0; k < o.design_variables; ++k) header += "," + o.variable_names[k];
  EXPECT_EQ(lines[0], header);
  for (std::size_t i = 0; i < 3; ++i) {
    const optimize::ParetoPoint& p = o.pareto[i];
    SCOPED_TRACE(lines[i + 1]);
    ASSERT_TRUE(p.result.ok()) << p.result.message;
    char buf[256];
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%s,%.17g", p.epsilon,
                  p.result.metrics.Fsh_rms, p.result.metrics.Msh_rms,
                  optimize::to_string(p.result.termination), p.result.verification_error);
    EXPECT_EQ(lines[i + 1].rfind(buf, 0), 0u);
    EXPECT_LE(p.result.verification_error, 1e-9);
    // Msh_rms within its bound, epsilon x the original's
    EXPECT_LE(p.result.metrics.Msh_rms, p.epsilon * r.metrics.Msh_rms * (1 + 1e-6));
  }
  // a trade-off: the tighter the bound on Msh_rms, the larger the least Fsh_rms
  EXPECT_GT(o.pareto[0].epsilon, o.pareto[2].epsilon);
  EXPECT_LE(o.pareto[0].result.metrics.Fsh_rms, o.pareto[2].result.metrics.Fsh_rms * (1 + 1e-6));
  EXPECT_NE(bd::testing::json_view(read(r.summary))
                .find("\"pareto\": {\"first\": \"Fsh_rms\", \"second\": \"Msh_rms\", "
                      "\"points\": 3}"),
            std::string::npos);
}

TEST_F(RunnerTest, InfeasibleOptimizationKeepsTheOriginalAndSaysWhy) {
  // a full force balance needs far more than 0.01 kg of counterweight
  const Study study = driven_with(
      "optimize:\n"
      "  objective: {Msh_rms: 1}\n"
      "  constraints: {force_balance: true}\n"
      "  variables:\n"
      "    counterweights: {crank: {mass_max: 0.01}, rocker: {mass_max: 0.01}}\n",
      "infeasible.yaml");
  const RunResult r = run_study(study, dir_);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.stopped_early());
  ASSERT_TRUE(r.optimized.has_value());
  EXPECT_TRUE(r.optimized->failed());
  EXPECT_FALSE(r.optimized->found());
  EXPECT_EQ(r.optimized->result.termination, optimize::Termination::kInfeasible);
  EXPECT_NE(r.optimized->result.message.find("force balance"), std::string::npos)
      << r.optimized->result.message;
  EXPECT_EQ(names_in(dir_),
            (std::set<std::string>{"harmonics.csv", "report.html", "summary.json",
                                   "timeseries.csv"}));
  expect_rows_match(lines_of(read(r.timeseries)), r.trajectory);
  const std::string json = bd::testing::json_view(read(r.summary));
  EXPECT_NE(json.find("\"termination\": \"infeasible\""), std::string::npos) << json;
  EXPECT_NE(json.find(nlohmann::json(r.optimized->result.message).dump()), std::string::npos)
      << json;
  EXPECT_EQ(json.find("\"optimized_run\""), std::string::npos) << json;
  EXPECT_EQ(json.find("\"optimized_metrics\""), std::string::npos) << json;
  const std::string file = read(r.summary);  // valid JSON, ending in a newline
  EXPECT_TRUE(nlohmann::json::accept(file)) << file;
  EXPECT_EQ(file.back(), '\n');
}

TEST_F(RunnerTest, OptimizationIsNotRunWhenTheOriginalStopsEarly) {
  Study study = driven_with(
      "optimize:\n"
      "  objective: {Msh_rms: 1}\n"
      "  variables: {counterweights: {crank: }}\n",
      "stops.yaml");
  study.fourbar().crank = core::link_from_polar(2.5, 2.1, 0.6, 0.3, 1.1);
  std::get<core::DrivenScene>(study.scene).theta1 = M_PI / 2;
  const RunResult r = run_study(study, dir_);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.stopped_early());
  ASSERT_TRUE(r.optimized.has_value());
  EXPECT_FALSE(r.optimized->failed());
  EXPECT_EQ(r.optimized->result.termination, optimize::Termination::kNotRun);
  EXPECT_NE(r.optimized->result.message.find("not run"), std::string::npos);
  EXPECT_EQ(names_in(dir_),
            (std::set<std::string>{"report.html", "summary.json", "timeseries.csv"}));
}

TEST(SummaryJson, MessagesWithQuotesLineBreaksAndUtf8ReadBack) {
  // a study name and message as a user or the core may write them: JSON escaping is the
  // library's, so summary.json parses back to the same text
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  RunResult r = compute_study(study);
  r.trajectory.message = std::string("a \"quoted\" \\ line\nbreak\t\x01 θ1 = 1 rad");
  const nlohmann::json j = nlohmann::json::parse(summary_json(study, r));
  EXPECT_EQ(j["message"].get<std::string>(), r.trajectory.message);
  EXPECT_EQ(j["study"].get<std::string>(), study.name);
}

}  // namespace
}  // namespace bd::studies
