// The study runner: timeseries.csv and summary.json follow the v1 output contract (exact header,
// one row per sample, %.17g round-trip), files are written atomically, and a simulation that
// stops early still leaves its samples and a summary saying why.
#include "studies/runner.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "studies/load_study.hpp"

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

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

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
    ASSERT_EQ(row.size(), 18u) << "row " << i;
    const core::DynamicsSample& d = tr.samples[i];
    const core::FourBarState& s = d.state;
    const double expected[] = {tr.t[i],   s.theta1,  s.theta2,  s.theta3,  s.omega1,  s.omega2,
                               s.omega3,  s.alpha1,  s.alpha2,  s.alpha3,  d.RA0.x(), d.RA0.y(),
                               d.RA3.x(), d.RA3.y(), d.Fsh.x(), d.Fsh.y(), d.Msh,     d.tau};
    for (std::size_t k = 0; k < 18; ++k) {
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

  // nothing but the two final files: no temporary left behind
  EXPECT_EQ(names_in(out), (std::set<std::string>{"summary.json", "timeseries.csv"}));

  const std::vector<std::string> lines = lines_of(read(r.timeseries));
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0],
            "t,theta1,theta2,theta3,omega1,omega2,omega3,alpha1,alpha2,alpha3,RA0x,RA0y,RA3x,"
            "RA3y,Fshx,Fshy,Msh,tau");
  EXPECT_EQ(lines.size(), 502u);  // header + 501 samples
  expect_rows_match(lines, r.trajectory);
  EXPECT_EQ(fields_of(lines[1])[0], 0.0);
  EXPECT_EQ(fields_of(lines.back())[0], 5.0);
  EXPECT_EQ(fields_of(lines[1])[1], 1.0);  // theta1 at t = 0

  const std::string json = read(r.summary);
  for (const char* key : {"\"study\": \"paper-fourbar\"",
                          "\"method\"",
                          "\"used\": \"complex-masses\"",
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
  EXPECT_NE(r.method.reason.find("no integrator: kinetostatics per sample"), std::string::npos);
  const std::string json = read(r.summary);
  EXPECT_NE(json.find("\"scene\": {\"type\": \"driven\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"revolutions\": 1"), std::string::npos) << json;
  EXPECT_NE(json.find("no integrator: kinetostatics per sample"), std::string::npos) << json;
  EXPECT_GT(r.metrics.tau_max, 0.0);
  EXPECT_EQ(names_in(dir_), (std::set<std::string>{"summary.json", "timeseries.csv"}));
}

TEST_F(RunnerTest, RunningAgainReplacesTheFiles) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  run_study(study, dir_);
  const std::string first = read(dir_ / "timeseries.csv");
  run_study(study, dir_);
  EXPECT_EQ(read(dir_ / "timeseries.csv"), first);
  EXPECT_EQ(names_in(dir_), (std::set<std::string>{"summary.json", "timeseries.csv"}));
}

TEST_F(RunnerTest, SimulationStoppedEarlyKeepsItsSamplesAndSaysWhy) {
  // crank 2.5 on frame 3.2 with rocker 2: the crank cannot turn fully, so driving it from
  // pi/2 reaches an angle where the loop cannot close
  Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  study.model.crank = core::link_from_polar(2.5, 2.1, 0.6, 0.3, 1.1);
  std::get<core::DrivenScene>(study.scene).theta1 = M_PI / 2;
  const RunResult r = run_study(study, dir_);
  ASSERT_FALSE(r.ok());
  EXPECT_FALSE(r.trajectory.samples.empty());
  EXPECT_LT(r.trajectory.samples.size(), 360u);
  const std::vector<std::string> lines = lines_of(read(r.timeseries));
  expect_rows_match(lines, r.trajectory);
  const std::string json = read(r.summary);
  EXPECT_NE(json.find("\"ok\": false"), std::string::npos) << json;
  EXPECT_NE(json.find(json_string(r.trajectory.message)), std::string::npos) << json;
  EXPECT_NE(json.find(std::string("\"status\": \"") + core::to_string(r.trajectory.status)),
            std::string::npos);
  EXPECT_EQ(names_in(dir_), (std::set<std::string>{"summary.json", "timeseries.csv"}));
}

TEST_F(RunnerTest, InvalidSceneCreatesNothing) {
  Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  std::get<core::DrivenScene>(study.scene).omega1 = 0.0;  // core rejects it
  const fs::path out = dir_ / "never";
  EXPECT_THROW(run_study(study, out), InputError);
  EXPECT_FALSE(fs::exists(out));
}

TEST(JsonString, EscapesWhatJsonRequires) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json_string("l1\nl2\tx\r"), "\"l1\\nl2\\tx\\r\"");
  EXPECT_EQ(json_string(std::string("\x01\x1f", 2)), "\"\\u0001\\u001f\"");
  EXPECT_EQ(json_string("θ1 = 1 rad"), "\"θ1 = 1 rad\"");  // UTF-8 passes through
}

}  // namespace
}  // namespace bd::studies
