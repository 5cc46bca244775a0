// run_sweep(): the sweep.csv columns, one row per point equal to the study run on its own, the
// same file whatever the number of threads, failing points as rows, and resuming an interrupted
// sweep to the same bytes as an uninterrupted run.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/sweep/sweep.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;
namespace rs = report_support;

// the driven paper linkage, unloaded (lines 1-9); a test appends its sections
const std::string kDriven =
    "name: driven\n"
    "linkage:\n"
    "  type: fourbar\n"
    "  frame: 3.2\n"
    "  branch: 1\n"
    "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
    "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
    "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
    "scene: {type: driven, theta1: 0.0, omega1: 6.283185307179586, samples: 90}\n";

// a 3 x 3 grid of the coupler's mass and centre-of-mass distance
const std::string kGrid3x3 =
    "sweep:\n"
    "  parameters:\n"
    "    - {path: linkage.coupler.mass, from: 1.0, to: 5.0, count: 3}\n"
    "    - {path: linkage.coupler.s, values: [0.5, 1.45, 2.5]}\n";

// the paper's loaded linkage in free motion over 20 s: a few milliseconds a point, so a sweep
// of many points runs long enough to be stopped midway
std::string free_sweep(int count) {
  return bd::testing::paper_free_lhs_sweep(count, "  seed: 7\n");
}

using bd::testing::read;

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

SweepOptions quiet(int threads = 0) {
  SweepOptions o;
  o.threads = threads;
  return o;
}

class SweepRunner : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(BD_BINARY_DIR) / "test-output" / "sweep_runner" / test->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // the sweep's report without charts: gnuplot's time is not what these tests are about
    ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  }
  fs::path dir_;
};

TEST_F(SweepRunner, ColumnsOfAPlainABalanceAndAnOptimizeStudy) {
  const std::vector<std::string> metrics = {
      "Fsh_rms", "Fsh_max", "Msh_rms",       "Msh_max",       "tau_rms",       "tau_max",
      "RA0_rms", "RA0_max", "RA3_rms",       "RA3_max",       "Fsh_total_rms", "Fsh_total_max",
      "Msh_total_rms",      "Msh_total_max", "FA1_max",       "FA2_max"};
  std::vector<std::string> plain = {"point", "linkage.coupler.mass", "linkage.coupler.s"};
  plain.insert(plain.end(), metrics.begin(), metrics.end());
  std::vector<std::string> balanced = plain, optimized = plain;
  for (const std::string& m : metrics) balanced.push_back("balanced_" + m);
  for (const std::string& m : metrics) optimized.push_back("optimized_" + m);
  for (auto* c : {&plain, &balanced, &optimized}) {
    if (c != &plain) c->insert(c->end(), {"added_mass", "added_inertia"});
    c->insert(c->end(), {"status", "message"});
  }

  EXPECT_EQ(sweep_columns(parse_study(kDriven + kGrid3x3, "s.yaml")), plain);
  EXPECT_EQ(sweep_columns(parse_study(kDriven + "balance: {force: full}\n" + kGrid3x3, "s.yaml")),
            balanced);
  EXPECT_EQ(sweep_columns(parse_study(kDriven +
                                          "optimize:\n"
                                          "  objective: {Msh_rms: 1}\n"
                                          "  constraints: {force_balance: true}\n"
                                          "  variables: {counterweights: {crank: , rocker: }}\n" +
                                          kGrid3x3,
                                      "s.yaml")),
            optimized);
  // a study without a sweep: the metrics alone
  std::vector<std::string> none = {"point"};
  none.insert(none.end(), metrics.begin(), metrics.end());
  none.insert(none.end(), {"status", "message"});
  EXPECT_EQ(sweep_columns(parse_study(kDriven, "s.yaml")), none);
}

TEST_F(SweepRunner, EachRowIsThePointsStudyRunOnItsOwn) {
  const Study study = parse_study(kDriven + "balance: {force: full}\n" + kGrid3x3, "s.yaml");
  const SweepResult r = run_sweep(study, dir_, quiet(2));
  EXPECT_EQ(r.points, 9);
  EXPECT_EQ(r.done, 9);
  EXPECT_EQ(r.resumed, 0);
  EXPECT_EQ(r.failed, 0);
  EXPECT_FALSE(r.interrupted);
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.csv, dir_ / "sweep.csv");
  EXPECT_EQ(r.summary, dir_ / "sweep.json");

  const std::vector<std::string> rows = lines(read(r.csv));
  ASSERT_EQ(rows.size(), 10u);
  const std::vector<std::string> columns = sweep_columns(study);
  EXPECT_EQ(csv_fields(rows[0]), columns);
  const auto points = sweep_points(*study.sweep);
  ASSERT_EQ(points.size(), 9u);
  for (std::size_t i = 0; i < points.size(); ++i) {
    SCOPED_TRACE("point " + std::to_string(i));
    const std::vector<std::string> f = csv_fields(rows[i + 1]);
    ASSERT_EQ(f.size(), columns.size());
    // the same computation as a run of the point's study: the same numbers, bit for bit
    const Study at = point_study(study, points[i]);
    const RunResult one = compute_study(at);
    std::vector<double> expected;
    for (const core::Metrics& m : {one.metrics, one.balanced->metrics}) {
      expected.insert(expected.end(),
                      {m.Fsh_rms, m.Fsh_max, m.Msh_rms, m.Msh_max, m.tau_rms, m.tau_max,
                       m.RA0_rms, m.RA0_max, m.RA3_rms, m.RA3_max, m.Fsh_total_rms,
                       m.Fsh_total_max, m.Msh_total_rms, m.Msh_total_max, m.FA1_max, m.FA2_max});
    }
    expected.push_back(at.balance->added_mass);
    expected.push_back(at.balance->added_inertia);
    EXPECT_EQ(f[0], std::to_string(i));
    EXPECT_EQ(f[1], number(points[i][0]));
    EXPECT_EQ(f[2], number(points[i][1]));
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(f[3 + k], number(expected[k])) << columns[3 + k];
    }
    EXPECT_EQ(f[columns.size() - 2], "ok");
    EXPECT_EQ(f[columns.size() - 1], "");
  }
  // the grid: first parameter slowest; the values as given
  EXPECT_EQ(csv_fields(rows[4])[1], "3");
  EXPECT_EQ(csv_fields(rows[4])[2], "0.5");
  EXPECT_EQ(csv_fields(rows[9])[2], "2.5");

  // run_study() of a point writes what compute_study() computes
  const Study at = point_study(study, points[4]);
  const RunResult written = run_study(at, dir_ / "point-4");
  EXPECT_EQ(number(written.metrics.Msh_rms), csv_fields(rows[5])[5]);
  EXPECT_TRUE(fs::exists(dir_ / "point-4" / "summary.json"));

  // sweep.json: the design and the counts
  const rs::Json j = rs::parse_json(read(r.summary), "sweep.json");
  EXPECT_EQ(rs::text(j, "study"), "driven");
  EXPECT_EQ(rs::text(j, "source"), "s.yaml");
  EXPECT_EQ(rs::text(j, "fingerprint").size(), 16u);
  EXPECT_EQ(rs::text(j, "design"), "grid");
  EXPECT_EQ(rs::text(j, "points"), "9");
  EXPECT_EQ(rs::text(j, "threads"), "2");
  EXPECT_EQ(rs::text(j, "status"), "complete");
  EXPECT_EQ(rs::text(j, "done"), "9");
  EXPECT_EQ(rs::text(j, "resumed"), "0");
  EXPECT_EQ(rs::text(j, "failed"), "0");
  const rs::Json* params = rs::member(j, "parameters");
  ASSERT_TRUE(params && params->size() == 2);
  const rs::Json& first = (*params)[0];
  EXPECT_EQ(rs::text(first, "path"), "linkage.coupler.mass");
  EXPECT_EQ(rs::text(first, "scale"), "linear");
  EXPECT_EQ(first["from"].get<double>(), 1.0);
  EXPECT_EQ(first["to"].get<double>(), 5.0);
  ASSERT_EQ(first["values"].size(), 3u);
  EXPECT_EQ(first["values"][1].get<double>(), 3.0);
  // a values list: from and to are its least and greatest
  EXPECT_EQ((*params)[1]["from"].get<double>(), 0.5);
  EXPECT_EQ((*params)[1]["to"].get<double>(), 2.5);
}

// A planar sweep's page names each swept value in an engineer's words with its unit (the input
// by its name, in its unit), gives the best values their units, and the shaking moment's point.
TEST_F(SweepRunner, APlanarSweepsPageNamesItsParametersAndUnits) {
  const Study study = parse_study(bd::testing::engine_study(12) +
                                      "sweep:\n"
                                      "  parameters:\n"
                                      "    - {path: linkage.point_masses.B, values: [0.3, 0.5]}\n"
                                      "    - {path: \"scene.speeds[0]\", values: [100, 200]}\n",
                                  "e.yaml");
  ASSERT_EQ(run_sweep(study, dir_, quiet(1)).done, 4);
  const std::string html = sweep_report_html(study, dir_, "");
  EXPECT_NE(html.find("<th>point mass at B [kg]<br><code>linkage.point_masses.B</code></th>"),
            std::string::npos);
  EXPECT_NE(html.find("<th>speed of input crank [rad/s]<br><code>scene.speeds[0]</code></th>"),
            std::string::npos);
  EXPECT_NE(html.find("<tr><th>Msh_rms</th><td class=\"n\" title=\""), std::string::npos);
  const std::size_t msh = html.find("<tr><th>Msh_rms</th>");
  EXPECT_NE(html.find("</td><td>N m</td>", msh), std::string::npos);
  // the design's table gives each parameter's unit
  EXPECT_NE(html.find("<tr><td><code>scene.speeds[0]</code></td><td>rad/s</td>"),
            std::string::npos);
  // the points' table names its metrics' units
  EXPECT_NE(html.find("<th>Fsh_rms [N]</th><th>Msh_rms [N m]</th>"), std::string::npos);
  // the four-bar's A0 is no point of this linkage: its moment is about the origin
  EXPECT_EQ(html.find("about A0"), std::string::npos);
}

// A planar linkage with a balance section sweeps alike: its own metrics, the balanced design's
// after them under balanced_, and each row the point's study run on its own, bit for bit.
TEST_F(SweepRunner, APlanarBalanceStudySweepsItsOwnMetrics) {
  const Study study = parse_study(bd::testing::engine_study(36) +
                                      "balance:\n"
                                      "sweep:\n"
                                      "  parameters:\n"
                                      "    - {path: linkage.point_masses.B, values: [0.3, 0.5]}\n",
                                  "e.yaml");
  const std::vector<std::string> columns = sweep_columns(study);
  ASSERT_GT(columns.size(), 6u);
  EXPECT_EQ(columns[2], "Fsh_rms");
  const auto balanced = std::find(columns.begin(), columns.end(), "balanced_Fsh_rms");
  ASSERT_NE(balanced, columns.end());
  EXPECT_NE(std::find(columns.begin(), columns.end(), "balanced_Rpiston_max"), columns.end());
  const SweepResult r = run_sweep(study, dir_, quiet(1));
  EXPECT_EQ(r.done, 2);
  EXPECT_EQ(r.failed, 0);
  const std::vector<std::string> rows = lines(read(r.csv));
  ASSERT_EQ(rows.size(), 3u);
  const auto points = sweep_points(*study.sweep);
  for (std::size_t i = 0; i < 2; ++i) {
    const std::vector<std::string> f = csv_fields(rows[i + 1]);
    ASSERT_EQ(f.size(), columns.size());
    const RunResult one = compute_study(point_study(study, points[i]));
    ASSERT_TRUE(one.balanced && one.balanced->design);
    std::vector<double> expected;
    for (const MetricList* list : {&one.metric_list, &one.balanced->metric_list}) {
      for (const MetricValue& m : *list) expected.push_back(m.value);
    }
    expected.push_back(one.balanced->design->added_mass);
    expected.push_back(one.balanced->design->added_inertia);
    ASSERT_EQ(expected.size() + 4, columns.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(f[2 + k], number(expected[k])) << columns[2 + k];
    }
    EXPECT_EQ(f[columns.size() - 2], "ok");
  }
}

TEST_F(SweepRunner, OneThreadAndTwoThreadsWriteTheSameFile) {
  const Study grid = parse_study(kDriven + "balance: {force: full}\n" + kGrid3x3, "s.yaml");
  run_sweep(grid, dir_ / "grid-1", quiet(1));
  run_sweep(grid, dir_ / "grid-2", quiet(2));
  EXPECT_EQ(read(dir_ / "grid-1" / "sweep.csv"), read(dir_ / "grid-2" / "sweep.csv"));
  // free motion: the points take different times, so two threads finish them out of order
  const Study free = parse_study(free_sweep(24), "free.yaml");
  run_sweep(free, dir_ / "free-1", quiet(1));
  run_sweep(free, dir_ / "free-2", quiet(2));
  const std::string one = read(dir_ / "free-1" / "sweep.csv");
  EXPECT_EQ(lines(one).size(), 25u);
  EXPECT_EQ(one, read(dir_ / "free-2" / "sweep.csv"));
}

TEST_F(SweepRunner, IpoptPointsOnTwoThreadsGiveTheRowsOfOne) {
  // Debian 12's Ipopt (3.11) calls MUMPS, which is not thread-safe: unserialised, two points
  // solved at once crashed (a Fortran runtime error in dmumps_load.F, a segmentation fault) or
  // gave other numbers. compute_study() holds a lock around each Ipopt solve.
  const Study study = parse_study(kDriven +
                                      "optimize:\n"
                                      "  algorithm: ipopt\n"
                                      "  objective: {Msh_rms: 1}\n"
                                      "  constraints: {force_balance: true}\n"
                                      "  variables:\n"
                                      "    counterweights: {crank: {mass_max: 10, distance_max: 1},"
                                      " rocker: {mass_max: 10, distance_max: 2}}\n"
                                      "    links: {coupler: {mass: [2, 4], inertia: [1, 8]}}\n"
                                      "sweep:\n"
                                      "  parameters:\n"
                                      "    - {path: linkage.crank.mass, from: 1.0, to: 4.0, "
                                      "count: 8}\n",
                                  "ipopt.yaml");
  const SweepResult one = run_sweep(study, dir_ / "one", quiet(1));
  const SweepResult two = run_sweep(study, dir_ / "two", quiet(2));
  EXPECT_EQ(one.failed, 0);
  EXPECT_EQ(two.failed, 0);
  EXPECT_EQ(read(dir_ / "one" / "sweep.csv"), read(dir_ / "two" / "sweep.csv"));
}

TEST_F(SweepRunner, PointsThatCannotRunAreRowsAndTheSweepGoesOn) {
  // a coupler of 0.1 m cannot reach across |A1A3| = 2.2 m at theta1 = 0 (bad input); one of
  // 1.5 m assembles there but not over the whole turn (bad input too: a driven crank must turn
  // fully); -1 kg is bad input
  const Study study = parse_study(kDriven +
                                      "sweep:\n"
                                      "  parameters:\n"
                                      "    - {path: linkage.coupler.length, values: [0.1, 1.5, "
                                      "3.0]}\n"
                                      "    - {path: linkage.coupler.mass, values: [-1, 3]}\n",
                                  "bad.yaml");
  const SweepResult r = run_sweep(study, dir_, quiet(2));
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.failed, 5);
  const std::vector<std::string> rows = lines(read(r.csv));
  ASSERT_EQ(rows.size(), 7u);
  const auto points = sweep_points(*study.sweep);
  const std::size_t n = sweep_columns(study).size();
  const char* expected[] = {"bad-input", "bad-input", "bad-input",
                            "bad-input", "bad-input", "ok"};
  for (std::size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE("point " + std::to_string(i));
    const std::vector<std::string> f = csv_fields(rows[i + 1]);
    ASSERT_EQ(f.size(), n);
    EXPECT_EQ(f[n - 2], expected[i]);
    if (f[n - 2] == "bad-input") {
      // the loader's own message for the point's study, every metric empty
      std::string what;
      try {
        point_study(study, points[i]);
      } catch (const StudyError& e) {
        what = e.what();
      }
      ASSERT_FALSE(what.empty());
      EXPECT_EQ(f[n - 1], what);
      // the place: the swept mass's value, or the scene's theta1 where the loop cannot close
      EXPECT_EQ(what.rfind(i % 2 == 0 ? "bad.yaml:7:32: " : "bad.yaml:9:", 0), 0u) << what;
      for (std::size_t k = 3; k < n - 2; ++k) EXPECT_EQ(f[k], "") << k;
    }
  }
  // -1 kg: the mass's message; 0.1 m: the assembly's
  EXPECT_NE(csv_fields(rows[1]).back().find("linkage.coupler.mass must be > 0 kg, got -1"),
            std::string::npos)
      << rows[1];
  EXPECT_NE(csv_fields(rows[2]).back().find("cannot be assembled"), std::string::npos) << rows[2];
  // 1.5 m: the crank cannot turn fully, said at scene.type
  EXPECT_NE(csv_fields(rows[4]).back().find("scene.type: driven turns the crank"),
            std::string::npos)
      << rows[4];
  // the message is quoted CSV text
  EXPECT_NE(rows[1].find(",bad-input,\"bad.yaml:7:"), std::string::npos) << rows[1];
  const rs::Json j = rs::parse_json(read(r.summary), "sweep.json");
  EXPECT_EQ(rs::text(j, "failed"), "5");
}

TEST_F(SweepRunner, NoOptimumIsARowWithTheOptimisersMessage) {
  // a full force balance needs far more than 0.01 kg of counterweight on each side
  const Study study = parse_study(kDriven +
                                      "optimize:\n"
                                      "  objective: {Msh_rms: 1}\n"
                                      "  constraints: {force_balance: true}\n"
                                      "  variables:\n"
                                      "    counterweights: {crank: {mass_max: 0.01}, rocker: "
                                      "{mass_max: 0.01}}\n"
                                      "sweep:\n"
                                      "  parameters:\n"
                                      "    - {path: linkage.coupler.mass, values: [2, 3]}\n",
                                  "opt.yaml");
  const SweepResult r = run_sweep(study, dir_, quiet());
  EXPECT_EQ(r.failed, 2);
  const std::vector<std::string> rows = lines(read(r.csv));
  ASSERT_EQ(rows.size(), 3u);
  const std::size_t n = sweep_columns(study).size();
  const auto points = sweep_points(*study.sweep);
  for (std::size_t i = 0; i < 2; ++i) {
    const std::vector<std::string> f = csv_fields(rows[i + 1]);
    ASSERT_EQ(f.size(), n);
    EXPECT_EQ(f[n - 2], "no-optimum");
    const RunResult alone = compute_study(point_study(study, points[i]));
    ASSERT_TRUE(alone.optimized && alone.optimized->failed());
    std::string message = alone.optimized->result.message;
    for (char& c : message) c = c == '\n' ? ' ' : c;
    EXPECT_EQ(f[n - 1], message);
    EXPECT_NE(f[n - 1].find("force balance"), std::string::npos) << f[n - 1];
    EXPECT_EQ(f[2], number(alone.metrics.Fsh_rms));  // the original's metrics are there
    EXPECT_EQ(f[11], number(alone.metrics.RA3_max));
    EXPECT_EQ(f[17], number(alone.metrics.FA2_max));
    for (std::size_t k = 18; k < n - 2; ++k) EXPECT_EQ(f[k], "") << k;  // the optimum's not
  }
}

TEST_F(SweepRunner, ResumeCompletesACutShortFileToTheSameBytes) {
  const Study study = parse_study(free_sweep(30), "free.yaml");
  run_sweep(study, dir_ / "full", quiet());
  const std::string full = read(dir_ / "full" / "sweep.csv");
  const std::vector<std::string> rows = lines(full);
  ASSERT_EQ(rows.size(), 31u);

  // the first 11 lines (header and 10 rows) and half of the next: as a kill can leave it
  for (const bool cut : {true, false}) {
    const fs::path part = dir_ / (cut ? "cut" : "whole-lines");
    fs::create_directories(part);
    std::string text;
    for (int i = 0; i < 11; ++i) text += rows[static_cast<std::size_t>(i)] + "\n";
    if (cut) text += rows[11].substr(0, rows[11].size() / 2);
    write(part / "sweep.csv", text);
    fs::copy_file(dir_ / "full" / "sweep.json", part / "sweep.json");

    SweepOptions o = quiet();
    o.resume = true;
    const SweepResult r = run_sweep(study, part, o);
    EXPECT_EQ(r.resumed, 10);
    EXPECT_EQ(r.done, 30);
    EXPECT_TRUE(r.complete());
    EXPECT_EQ(read(part / "sweep.csv"), full) << part;
    const rs::Json j = rs::parse_json(read(part / "sweep.json"), "sweep.json");
    EXPECT_EQ(rs::text(j, "status"), "complete");
    EXPECT_EQ(rs::text(j, "resumed"), "10");
    EXPECT_EQ(rs::text(j, "done"), "30");
  }

  // resuming a complete sweep runs nothing and keeps the file
  SweepOptions o = quiet();
  o.resume = true;
  const SweepResult again = run_sweep(study, dir_ / "full", o);
  EXPECT_EQ(again.resumed, 30);
  EXPECT_EQ(read(dir_ / "full" / "sweep.csv"), full);
  // --resume where there is nothing yet starts the sweep
  const SweepResult fresh = run_sweep(study, dir_ / "fresh", o);
  EXPECT_EQ(fresh.resumed, 0);
  EXPECT_EQ(read(dir_ / "fresh" / "sweep.csv"), full);
}

TEST_F(SweepRunner, ResumeRefusesAnotherDesignOrAlteredRows) {
  const Study study = parse_study(kDriven + kGrid3x3, "s.yaml");
  run_sweep(study, dir_ / "full", quiet());
  const std::string full = read(dir_ / "full" / "sweep.csv");
  const std::vector<std::string> rows = lines(full);
  auto partial = [&](const std::string& name, std::vector<std::string> kept) {
    const fs::path p = dir_ / name;
    fs::create_directories(p);
    std::string text;
    for (const std::string& line : kept) text += line + "\n";
    write(p / "sweep.csv", text);
    fs::copy_file(dir_ / "full" / "sweep.json", p / "sweep.json");
    return p;
  };
  SweepOptions resume = quiet();
  resume.resume = true;
  auto message = [&](const Study& s, const fs::path& p, const SweepOptions& o) {
    try {
      run_sweep(s, p, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };

  // another design: the study file's text differs (a fourth value)
  const Study other =
      parse_study(kDriven +
                      "sweep:\n  parameters:\n"
                      "    - {path: linkage.coupler.mass, from: 1.0, to: 5.0, count: 4}\n"
                      "    - {path: linkage.coupler.s, values: [0.5, 1.45, 2.5]}\n",
                  "s.yaml");
  fs::path p = partial("other", {rows.begin(), rows.begin() + 4});
  std::string m = message(other, p, resume);
  EXPECT_EQ(m.rfind(p.string() + " holds a sweep of another study or design: the study file "
                                 "differs (fingerprint ",
                    0),
            0u)
      << m;
  EXPECT_NE(m.find("; remove the folder to start over"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_EQ(lines(read(p / "sweep.csv")).size(), 4u);  // untouched

  // a sweep.json of another design beside this study's rows
  p = partial("json", {rows.begin(), rows.begin() + 4});
  std::string json = read(p / "sweep.json");
  json.replace(json.find("\"points\": 9"), 11, "\"points\": 8");
  write(p / "sweep.json", json);
  m = message(study, p, resume);
  EXPECT_NE(m.find("holds a sweep of another study or design: points 9, was 8"), std::string::npos)
      << m;

  // a row whose values are not the design's
  std::vector<std::string> altered(rows.begin(), rows.begin() + 5);
  altered[2].replace(altered[2].find(",1.45,"), 6, ",1.46,");
  p = partial("altered", altered);
  m = message(study, p, resume);
  EXPECT_EQ(m, (p / "sweep.csv").string() +
                   ": row 2 is not point 1 of this design (its parameter 2 is 1.46, the design's "
                   "1.45); remove the folder to start over")
      << m;
  // a row out of place
  std::vector<std::string> swapped(rows.begin(), rows.begin() + 5);
  std::swap(swapped[2], swapped[3]);
  p = partial("swapped", swapped);
  m = message(study, p, resume);
  EXPECT_NE(m.find("row 2 is not point 1 of this design (its point is '2')"), std::string::npos)
      << m;

  // an unfinished sweep is not overwritten without --resume
  p = partial("unfinished", {rows.begin(), rows.begin() + 4});
  m = message(study, p, quiet());
  EXPECT_EQ(m, p.string() +
                   " holds an unfinished sweep (3 of 9 points): pass --resume to continue it, or "
                   "remove the folder to start over");
  EXPECT_EQ(lines(read(p / "sweep.csv")).size(), 4u);
  // another study's unfinished sweep: --resume would be refused, so the message does not offer it
  m = message(other, p, quiet());
  EXPECT_EQ(
      m.rfind(p.string() + " holds an unfinished sweep (3 of 9 points) of another study (", 0), 0u)
      << m;
  EXPECT_NE(m.find("): remove the folder to start over, or write this sweep elsewhere with --out"),
            std::string::npos)
      << m;
  EXPECT_EQ(lines(read(p / "sweep.csv")).size(), 4u);
  // a finished one is replaced
  EXPECT_EQ(message(study, dir_ / "full", quiet()), "no error");
  EXPECT_EQ(read(dir_ / "full" / "sweep.csv"), full);

  // a single run of the base study into a sweep's folder: refused while the sweep is unfinished
  // (its rows kept, no file of the run written), replacing it once finished; and a sweep into a
  // single run's folder leaves none of the run's files: a folder never holds two studies' files
  Study plain = study;
  plain.sweep.reset();
  try {
    run_study(plain, p);
    ADD_FAILURE() << "a single run overwrote an unfinished sweep";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              p.string() +
                  " holds an unfinished sweep (3 of 9 points): continue it with "
                  "`balance-design run " +
                  study.source + " --out " + p.string() +
                  " --resume`, or write this run elsewhere with --out");
    EXPECT_FALSE(study.source.empty());  // the sweep's study file, as sweep.json names it
  }
  EXPECT_EQ(lines(read(p / "sweep.csv")).size(), 4u);
  EXPECT_FALSE(fs::exists(p / "summary.json"));
  EXPECT_FALSE(fs::exists(p / "timeseries.csv"));
  {
    // where sweep.json names its study file, the advice names it too
    const fs::path named = dir_ / "named";
    fs::create_directories(named);
    std::ofstream(named / "sweep.json")
        << R"({"study": "s", "source": "studies/my-sweep.yaml", "points": 9})";
    std::ofstream(named / "sweep.csv") << "point,status\n";
    try {
      run_study(plain, named);
      ADD_FAILURE() << "a single run overwrote an unfinished sweep";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("(0 of 9 points): continue it with `balance-design "
                                           "run studies/my-sweep.yaml --out "),
                std::string::npos)
          << e.what();
    }
  }
  run_study(plain, dir_ / "full");
  EXPECT_FALSE(fs::exists(dir_ / "full" / "sweep.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "full" / "sweep.json"));
  EXPECT_TRUE(fs::exists(dir_ / "full" / "summary.json"));
  run_sweep(study, dir_ / "full", quiet());
  EXPECT_EQ(read(dir_ / "full" / "sweep.csv"), full);
  for (const char* name : kRunFiles) {
    if (std::string_view(name) != "study.yaml") {
      EXPECT_FALSE(fs::exists(dir_ / "full" / name)) << name;
    }
  }
}

TEST_F(SweepRunner, StopKeepsAPrefixAndResumeCompletesIt) {
  const Study study = parse_study(free_sweep(300), "free.yaml");
  run_sweep(study, dir_ / "full", quiet(2));
  const std::string full = read(dir_ / "full" / "sweep.csv");
  ASSERT_EQ(lines(full).size(), 301u);

  // one thread, a few milliseconds a point: the stop, once three rows are written, comes long
  // before the end
  std::atomic<bool> stop{false}, running{true};
  const fs::path csv = dir_ / "stopped" / "sweep.csv";
  std::thread watcher([&] {
    while (running.load() && !stop.load()) {
      if (lines(read(csv)).size() >= 4) stop = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  SweepOptions o = quiet(1);
  o.stop = &stop;
  const SweepResult r = run_sweep(study, dir_ / "stopped", o);
  running = false;
  watcher.join();
  ASSERT_TRUE(r.interrupted) << "the sweep ended before the stop";
  EXPECT_FALSE(r.complete());
  EXPECT_GE(r.done, 3);
  EXPECT_LT(r.done, 300);
  const std::string stopped = read(csv);
  EXPECT_EQ(lines(stopped).size(), static_cast<std::size_t>(r.done) + 1);
  EXPECT_EQ(full.compare(0, stopped.size(), stopped), 0) << "not the beginning of the sweep";
  const rs::Json j = rs::parse_json(read(dir_ / "stopped" / "sweep.json"), "sweep.json");
  EXPECT_EQ(rs::text(j, "status"), "interrupted");
  EXPECT_EQ(rs::text(j, "done"), std::to_string(r.done));

  // without --resume the unfinished sweep is refused; with it, completed to the same bytes
  EXPECT_THROW(run_sweep(study, dir_ / "stopped", quiet(2)), InputError);
  SweepOptions resume = quiet(2);
  resume.resume = true;
  const SweepResult rest = run_sweep(study, dir_ / "stopped", resume);
  EXPECT_EQ(rest.resumed, r.done);
  EXPECT_TRUE(rest.complete());
  EXPECT_EQ(read(csv), full);
}

}  // namespace
}  // namespace bd::studies
