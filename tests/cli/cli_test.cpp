// The balance-design executable: exit codes, the one-line error on stderr, outputs where asked
// and nothing written for bad input. Needs the executable built (target balance-design).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>

#include "tests/support/csv.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/text.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kExe = BD_BINARY_DIR "/bin/balance-design";
const std::string kExamples = BD_SOURCE_DIR "/studies/examples";

using bd::testing::quote;

using bd::testing::read;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kExe)) << kExe << " not built (cmake --build build --target "
                                  << "balance-design)";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_cli_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // runs `balance-design ARGS` in dir_, keeping stdout and stderr; returns the exit code
  int run(const std::string& args) {
    const std::string cmd = "cd " + quote(dir_.string()) + " && " + quote(kExe) + " " + args +
                            " >" + quote((dir_ / "stdout.txt").string()) + " 2>" +
                            quote((dir_ / "stderr.txt").string());
    const int status = std::system(cmd.c_str());
    out_ = read(dir_ / "stdout.txt");
    err_ = read(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.txt");
    fs::remove(dir_ / "stderr.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }

  fs::path dir_;
  std::string out_, err_;
};

TEST_F(CliTest, RunWritesTheOutputsAndExitsZero) {
  EXPECT_EQ(run("run " + quote(kExamples + "/paper-fourbar-driven.yaml") + " --out res"), 0)
      << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  EXPECT_TRUE(fs::exists(dir_ / "res" / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "res" / "summary.json"));
  EXPECT_NE(out_.find("mass-matrix (auto: "), std::string::npos) << out_;
  EXPECT_NE(out_.find("timeseries.csv"), std::string::npos) << out_;
}

TEST_F(CliTest, ShorthandUsesTheDefaultOutputDirectory) {
  EXPECT_EQ(run(quote(kExamples + "/paper-fourbar.yaml")), 0) << err_;
  const fs::path out = dir_ / "results" / "paper-fourbar";
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_NE(read(out / "summary.json").find("\"study\": \"paper-fourbar\""), std::string::npos);
}

TEST_F(CliTest, BadInputExitsTwoWithOneLineAndWritesNothing) {
  write("bad.yaml",
        "name: bad\n"
        "linkage:\n"
        "  type: fourbar\n"
        "  frame: 3.2\n"
        "  branch: 1\n"
        "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: -1, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
        "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
        "scene: {type: free, duration: 1}\n");
  EXPECT_EQ(run("bad.yaml --out res"), 2);
  EXPECT_EQ(err_, "bad.yaml:7:32: linkage.coupler.mass must be > 0 kg, got -1\n");
  EXPECT_FALSE(fs::exists(dir_ / "res"));
  EXPECT_FALSE(fs::exists(dir_ / "results"));

  // the default directory is not created either
  EXPECT_EQ(run("run bad.yaml"), 2);
  EXPECT_FALSE(fs::exists(dir_ / "results"));

  // a YAML syntax error
  write("syntax.yaml", "name: x\nlinkage: {frame: 3.2\n");
  EXPECT_EQ(run("syntax.yaml --out res"), 2);
  EXPECT_EQ(err_.rfind("syntax.yaml:", 0), 0u) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_FALSE(fs::exists(dir_ / "res"));

  // a missing file
  EXPECT_EQ(run("missing.yaml --out res"), 2);
  EXPECT_EQ(err_, "missing.yaml: cannot open the study file\n");
  EXPECT_FALSE(fs::exists(dir_ / "res"));
}

TEST_F(CliTest, BadCommandLineExitsTwo) {
  EXPECT_EQ(run(""), 2);
  EXPECT_EQ(run("run"), 2);
  EXPECT_EQ(run("a.yaml b.yaml"), 2);
  EXPECT_EQ(run("run a.yaml --bogus"), 2);
}

TEST_F(CliTest, SimulationStoppedEarlyExitsThreeAndKeepsResults) {
  // a driven crank that cannot turn fully is refused before it runs (exit 2, at scene.type)
  write("rocks.yaml",
        "name: rocks\n"
        "linkage:\n"
        "  type: fourbar\n"
        "  frame: 3.2\n"
        "  branch: 1\n"
        "  crank:   {length: 2.5, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
        "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
        "scene: {type: driven, theta1: 1.5707963267948966, omega1: 6.283185307179586}\n");
  EXPECT_EQ(run("validate rocks.yaml"), 2);
  EXPECT_EQ(err_.rfind("rocks.yaml:9:15: scene.type: driven turns the crank through whole "
                       "revolutions, but this linkage is rocker-crank",
                       0),
            0u)
      << err_;
  // a parallelogram (a change-point linkage): its crank turns fully, but at theta1 = 0 and pi
  // its links fold into one line, where the loop closes two ways: refused before it runs too
  write("folds.yaml",
        "name: folds\n"
        "linkage:\n"
        "  type: fourbar\n"
        "  frame: 3.0\n"
        "  branch: 1\n"
        "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
        "  rocker:  {length: 1.0, mass: 2.2, s: 0.66, sigma: -0.4, inertia: 2.1}\n"
        "scene: {type: driven, theta1: 1.5707963267948966, omega1: 6.283185307179586}\n");
  EXPECT_EQ(run("folds.yaml --out res"), 2) << err_;
  EXPECT_EQ(err_.rfind("folds.yaml:9:15: scene.type: driven turns the crank through whole "
                       "revolutions, but this linkage is change-point",
                       0),
            0u)
      << err_;
  EXPECT_FALSE(fs::exists(dir_ / "res" / "timeseries.csv"));
  // a free triple rocker on the mass matrix, whose reduced equation in theta1 cannot pass a limit
  // position: the run stops at the first one (exit 3), keeping the samples before
  std::string stops = bd::testing::read(fs::path(kExamples) / "triple-rocker-free.yaml");
  stops.replace(stops.find("\nmethod: auto"), 13, "\nmethod: mass-matrix");
  write("stops.yaml", stops);
  EXPECT_EQ(run("stops.yaml --out res"), 3) << err_;
  // its metrics say they cover part of the run only
  const std::string csv = bd::testing::read(dir_ / "res" / "timeseries.csv");
  const auto rows = static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n') - 1);
  EXPECT_GT(rows, 1u);
  EXPECT_LT(rows, 2001u);
  EXPECT_NE(out_.find("  partial  the metrics below cover only the motion up to the stop: the "
                      "RMS values its " +
                      std::to_string(rows) + " samples, the peaks up to the stop itself"),
            std::string::npos)
      << out_;
  EXPECT_NE(read(dir_ / "res" / "summary.json").find("\"metrics_partial\": true"),
            std::string::npos);
  // and so does the report's metrics table, at its column
  EXPECT_NE(read(dir_ / "res" / "report.html")
                .find("<th>original<br><span class=\"bad\">partial: the motion up to the "
                      "stop</span></th>"),
            std::string::npos);
  EXPECT_EQ(err_.rfind("stops.yaml: simulation stopped early: ", 0), 0u) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_NE(err_.find("theta1"), std::string::npos) << err_;
  EXPECT_NE(read(dir_ / "res" / "summary.json").find("\"ok\": false"), std::string::npos);
}

// A run that stops before its first sample has no metrics: "none" on the terminal, null in
// summary.json, not zeros as if the linkage shook nothing. The triple rocker started free exactly
// at its limit position (the crank angle where |A1 - A3| = coupler + rocker, by the law of
// cosines) on the mass matrix, whose reduced equation in theta1 is singular there.
TEST_F(CliTest, ARunStoppedBeforeItsFirstSampleHasNoMetrics) {
  std::string text = bd::testing::read(fs::path(kExamples) / "triple-rocker-free.yaml");
  const double limit = std::acos((2.0 * 2.0 + 3.5 * 3.5 - 4.0 * 4.0) / (2 * 2.0 * 3.5));
  char theta1[64];
  std::snprintf(theta1, sizeof theta1, "theta1: %.17g", limit);
  text.replace(text.find("theta1: 0.0"), 11, theta1);
  text.replace(text.find("\nmethod: auto"), 13, "\nmethod: mass-matrix");
  write("limit.yaml", text);
  EXPECT_EQ(run("limit.yaml --out res"), 3) << err_;
  EXPECT_NE(out_.find("  samples  0, "), std::string::npos) << out_;
  EXPECT_NE(out_.find("  metrics  none: the run stopped before its first sample"),
            std::string::npos)
      << out_;
  EXPECT_EQ(out_.find("rms 0 N"), std::string::npos) << out_;
  const std::string summary = read(dir_ / "res" / "summary.json");
  EXPECT_NE(summary.find("\"Fsh_rms\": null"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"RA0_max\": null"), std::string::npos) << summary;
  EXPECT_TRUE(fs::exists(dir_ / "res" / "report.html"));
}

// a non-Grashof four-bar on the general engine (crank 0.5, coupler 0.335, rocker 0.35, frame
// 0.3: s + l = 0.8 > p + q = 0.685), drawn with its crank at pi/2; its crank reaches a limit
// position near 2.02 rad, where |A1 - A3| = coupler + rocker. The scene is appended.
const std::string kNonGrashofPlanar =
    "name: rocks\n"
    "linkage:\n"
    "  type: planar\n"
    "  nodes:\n"
    "    A0: {at: [0, 0], ground: true}\n"
    "    A3: {at: [0.3, 0], ground: true}\n"
    "    A1: [0, 0.5]\n"
    "    A2: [0.3, 0.35]\n"
    "  links:\n"
    "    crank: {nodes: [A0, A1], mass: 1.0, e: 0.1, f: 0, inertia: 0.002}\n"
    "    coupler: {nodes: [A1, A2], mass: 1.0, e: 0.1, f: 0, inertia: 0.002}\n"
    "    rocker: {nodes: [A3, A2], mass: 1.0, e: 0.1, f: 0, inertia: 0.002}\n"
    "  inputs:\n"
    "    crank: {link: crank}\n";

TEST_F(CliTest, PlanarSimulationStoppedEarlyNamesWhereItStopped) {
  // a free non-Grashof four-bar on the general engine's reduced route (method: truss), which
  // cannot pass a limit position: the run stops at the first one (exit 3), keeping the samples
  // before (its crank, turning from pi/2, reaches it near 2.02 rad; the driven scene of this
  // linkage is refused below)
  write("limit.yaml", kNonGrashofPlanar +
                          "scene: {type: free, duration: 0.5, rates: [6.283185307179586]}\n"
                          "method: truss\n");
  EXPECT_EQ(run("limit.yaml --out res"), 3) << err_;
  // the planar run's own message (not the empty four-bar trajectory's), naming where
  EXPECT_EQ(err_.rfind("limit.yaml: simulation stopped early: ", 0), 0u) << err_;
  EXPECT_NE(err_.find("crank = 2.0"), std::string::npos) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_TRUE(fs::exists(dir_ / "res" / "timeseries.csv"));
}

TEST_F(CliTest, PlanarDrivenInputThatCannotTurnFullyIsRefusedAtSceneType) {
  // a non-Grashof four-bar on the general engine (crank 0.5, coupler 0.335, rocker 0.35, frame
  // 0.3: s + l = 0.8 > p + q = 0.685): its crank reaches a limit position near 2.02 rad, where
  // |A1 - A3| = coupler + rocker; a driven scene is refused before it runs, a free one is not
  const std::string linkage = kNonGrashofPlanar;
  write("rocks.yaml", linkage + "scene:\n  type: driven\n  speeds: [6.283185307179586]\n");
  for (const char* command : {"validate rocks.yaml", "rocks.yaml --out res"}) {
    EXPECT_EQ(run(command), 2) << command << ": " << err_;
    EXPECT_EQ(err_.rfind("rocks.yaml:16:9: scene.type: driven turns the inputs through whole "
                         "revolutions, but the linkage cannot be assembled at crank = 2.02",
                         0),
              0u)
        << err_;
    EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  }
  EXPECT_FALSE(fs::exists(dir_ / "res" / "timeseries.csv"));
  // the angle named is the first of the 360 samples past the limit position, where
  // |A1 - A3| = coupler + rocker; by the law of cosines in the triangle A0 A1 A3 the crank's
  // angle from A0->A3 is then acos((0.5^2 + 0.3^2 - d^2) / (2 0.5 0.3)); it starts at pi/2 and
  // turns positively
  const double d = std::hypot(0.3, 0.15) + 0.35;
  const double limit = std::acos((0.25 + 0.09 - d * d) / 0.3);
  const std::size_t at = err_.find("crank = ");
  ASSERT_NE(at, std::string::npos) << err_;
  const double named = std::stod(err_.substr(at + 8));
  EXPECT_GT(named, limit);
  EXPECT_LE(named, limit + 2 * std::numbers::pi / 360) << limit;
  write("free.yaml", linkage + "scene: {type: free, duration: 0.5, rates: [6.283185307179586]}\n");
  EXPECT_EQ(run("validate free.yaml"), 0) << err_;
}

TEST_F(CliTest, BalanceStudyPrintsTheComparisonAndWritesItsFiles) {
  EXPECT_EQ(run(quote(kExamples + "/berkof-inline-moment-balanced.yaml") + " --out res"), 0)
      << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  for (const char* file : {"timeseries.csv", "summary.json", "balanced-timeseries.csv",
                           "balanced.yaml", "comparison.csv"}) {
    EXPECT_TRUE(fs::exists(dir_ / "res" / file)) << file;
    EXPECT_NE(out_.find(file), std::string::npos) << file << " not in\n" << out_;
  }
  for (const char* text : {"balance  force full, moment full", "counterweight (point)",
                           "counter-rotation J = ", "metric", "before", "after", "ratio", "Fsh_rms",
                           "Msh_max", "tau_max", "RA3_max", "added_mass", "added_inertia"}) {
    EXPECT_NE(out_.find(text), std::string::npos) << text << " not in\n" << out_;
  }
  // the written balanced design runs as a study of its own and reproduces the balanced run
  // (balanced.yaml gives every number exactly; the outputs are checked here to 1e-12)
  EXPECT_EQ(run("res/balanced.yaml --out again"), 0) << err_;
  bd::testing::expect_same_numbers(dir_ / "again" / "timeseries.csv",
                                   dir_ / "res" / "balanced-timeseries.csv", 1e-12);
}

TEST_F(CliTest, ImpossibleBalanceIsBadInputAtTheMomentKey) {
  // the paper's coupler is not a Berkof coupler: no moment balance by counter-rotations
  write("moment.yaml",
        "name: moment\n"
        "linkage:\n"
        "  type: fourbar\n"
        "  frame: 3.2\n"
        "  branch: 1\n"
        "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
        "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
        "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
        "scene: {type: driven, omega1: 1}\n"
        "balance: {force: full, moment: full}\n");
  EXPECT_EQ(run("moment.yaml --out res"), 2);
  EXPECT_EQ(err_.rfind("moment.yaml:10:32: balance.moment: full is not possible: ", 0), 0u) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_FALSE(fs::exists(dir_ / "res"));
}

// the driven paper linkage, unloaded, with an optimize section appended (from line 10)
const std::string kDrivenPaper =
    "name: opt\n"
    "linkage:\n"
    "  type: fourbar\n"
    "  frame: 3.2\n"
    "  branch: 1\n"
    "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
    "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
    "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
    "scene: {type: driven, omega1: 6.283185307179586}\n";

TEST_F(CliTest, OptimizeStudyPrintsTheOptimumAndWritesItsFiles) {
  EXPECT_EQ(run(quote(kExamples + "/berkof-lowen-min-shaking-moment.yaml") + " --out res"), 0)
      << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  for (const char* file : {"timeseries.csv", "summary.json", "optimized-timeseries.csv",
                           "optimized.yaml", "comparison.csv"}) {
    EXPECT_TRUE(fs::exists(dir_ / "res" / file)) << file;
    EXPECT_NE(out_.find(file), std::string::npos) << file << " not in\n" << out_;
  }
  EXPECT_FALSE(fs::exists(dir_ / "res" / "pareto.csv"));
  for (const char* text : {"optimize slsqp: minimise 1 x Msh_rms", "subject to full force balance",
                           "converged", "counterweight ", "verified with ", "metric", "before",
                           "after", "ratio", "Msh_rms", "added_mass"}) {
    EXPECT_NE(out_.find(text), std::string::npos) << text << " not in\n" << out_;
  }
  // the written optimum runs as a study of its own and reproduces the optimum's run
  EXPECT_EQ(run("res/optimized.yaml --out again"), 0) << err_;
  bd::testing::expect_same_numbers(dir_ / "again" / "timeseries.csv",
                                   dir_ / "res" / "optimized-timeseries.csv", 1e-12);
}

TEST_F(CliTest, NoOptimumExitsFourAndKeepsTheOriginal) {
  // a full force balance needs far more than 0.01 kg of counterweight on each side
  write("infeasible.yaml", kDrivenPaper +
                               "optimize:\n"
                               "  objective: {Msh_rms: 1}\n"
                               "  constraints: {force_balance: true}\n"
                               "  variables:\n"
                               "    counterweights: {crank: {mass_max: 0.01}, rocker: {mass_max: "
                               "0.01}}\n");
  EXPECT_EQ(run("infeasible.yaml --out res"), 4) << err_;
  EXPECT_EQ(err_.rfind("infeasible.yaml: no optimum (infeasible): ", 0), 0u) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_NE(err_.find("force balance"), std::string::npos)
      << "names the binding constraint: " << err_;
  EXPECT_TRUE(fs::exists(dir_ / "res" / "timeseries.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "res" / "optimized.yaml"));
  EXPECT_FALSE(fs::exists(dir_ / "res" / "comparison.csv"));
  const std::string summary = read(dir_ / "res" / "summary.json");
  EXPECT_NE(summary.find("\"termination\": \"infeasible\""), std::string::npos) << summary;
  EXPECT_NE(out_.find("infeasible"), std::string::npos) << out_;
}

TEST_F(CliTest, BadOptimizeSectionIsBadInputWithItsPlace) {
  write("bad-opt.yaml", kDrivenPaper +
                            "optimize:\n"
                            "  objective: {Msh_avg: 1}\n"
                            "  variables: {counterweights: {crank: }}\n");
  EXPECT_EQ(run("bad-opt.yaml --out res"), 2);
  EXPECT_EQ(err_.rfind("bad-opt.yaml:11:15: unknown metric 'Msh_avg' in optimize.objective; "
                       "expected one of Fsh_rms, ",
                       0),
            0u)
      << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_FALSE(fs::exists(dir_ / "res"));

  write("both.yaml", kDrivenPaper + "balance: {force: full}\n" +
                         "optimize:\n"
                         "  objective: {Msh_rms: 1}\n"
                         "  variables: {counterweights: {crank: }}\n");
  EXPECT_EQ(run("both.yaml --out res"), 2);
  EXPECT_EQ(err_.rfind("both.yaml:11:1: a study has a balance section or an optimize section, "
                       "not both",
                       0),
            0u)
      << err_;
}

TEST_F(CliTest, ValidateChecksAndWritesNothing) {
  EXPECT_EQ(run("validate " + quote(kExamples + "/paper-fourbar-driven-force-balanced.yaml")), 0)
      << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  EXPECT_NE(
      out_.find(": ok (study paper-fourbar-driven-force-balanced, driven scene, method auto)"),
      std::string::npos)
      << out_;
  EXPECT_EQ(out_.find('\n'), out_.size() - 1) << out_;
  EXPECT_TRUE(fs::is_empty(dir_));  // nothing written, not even results/

  write("bad.yaml", "name: bad\nlinkage: {type: fourbar, frame: 3.2, bogus: 1}\n");
  EXPECT_EQ(run("validate bad.yaml"), 2);
  EXPECT_TRUE(out_.empty()) << out_;
  EXPECT_EQ(err_.rfind("bad.yaml:", 0), 0u) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  EXPECT_EQ(run("validate missing.yaml"), 2);
  EXPECT_EQ(err_, "missing.yaml: cannot open the study file\n");
  EXPECT_EQ(run("validate"), 2);
}

TEST_F(CliTest, RunWritesTheReportAndReportRebuildsIt) {
  EXPECT_EQ(run("run " + quote(kExamples + "/paper-fourbar-driven.yaml") + " --out res"), 0)
      << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  ASSERT_TRUE(fs::exists(dir_ / "res" / "report.html"));
  EXPECT_NE(out_.find("report.html"), std::string::npos) << out_;
  const std::string first = read(dir_ / "res" / "report.html");
  fs::remove(dir_ / "res" / "report.html");

  EXPECT_EQ(run("report res"), 0) << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  EXPECT_NE(out_.find("wrote res/report.html"), std::string::npos) << out_;
  EXPECT_EQ(read(dir_ / "res" / "report.html"), first);

  // without gnuplot the page is still written, and says the charts need it
  EXPECT_EQ(run("report res BD_GNUPLOT_UNUSED"), 2);  // one folder only
  EXPECT_EQ(std::system(("cd " + quote(dir_.string()) + " && BD_GNUPLOT=/nonexistent " +
                         quote(kExe) + " report res >/dev/null 2>&1")
                            .c_str()),
            0);
  EXPECT_NE(read(dir_ / "res" / "report.html").find("The charts need gnuplot"), std::string::npos);
}

TEST_F(CliTest, AReportThatCannotBeWrittenIsOneWarningLineAndTheRunSucceeds) {
  const std::string cmd = "cd " + quote(dir_.string()) + " && BD_GNUPLOT=/bin/false " +
                          quote(kExe) + " " + quote(kExamples + "/paper-fourbar-driven.yaml") +
                          " --out res >out.txt 2>err.txt";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::string err = read(dir_ / "err.txt");
  EXPECT_EQ(err.rfind("balance-design: warning: report.html not written: gnuplot failed", 0), 0u)
      << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line: " << err;
  EXPECT_TRUE(fs::exists(dir_ / "res" / "summary.json"));
  EXPECT_FALSE(fs::exists(dir_ / "res" / "report.html"));
}

TEST_F(CliTest, ReportNeedsTheFolderOfARun) {
  fs::create_directories(dir_ / "empty");
  EXPECT_EQ(run("report empty"), 2);
  EXPECT_EQ(err_, "empty: no summary.json here: not the output folder of a run\n");
  EXPECT_FALSE(fs::exists(dir_ / "empty" / "report.html"));

  // a summary whose study file is gone
  fs::create_directories(dir_ / "orphan");
  write("orphan/summary.json", "{\n  \"study\": \"x\",\n  \"source\": \"gone.yaml\"\n}\n");
  EXPECT_EQ(run("report orphan"), 2);
  EXPECT_NE(err_.find("gone.yaml: cannot open the study file"), std::string::npos) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
}

TEST_F(CliTest, HelpAndVersion) {
  EXPECT_EQ(run("--help"), 0);
  for (const char* text :
       {"run", "validate STUDY.yaml", "report DIR", "report.html", "gnuplot", "--out",
        "timeseries.csv", "summary.json", "Exit codes", "balanced-timeseries.csv", "balanced.yaml",
        "comparison.csv", "optimize:", "optimized-timeseries.csv", "optimized.yaml", "pareto.csv",
        "  4  the optimiser found no design"}) {
    EXPECT_NE(out_.find(text), std::string::npos) << text;
  }
  EXPECT_EQ(run("run --help"), 0);
  EXPECT_NE(out_.find("--out"), std::string::npos) << out_;
  EXPECT_EQ(run("--version"), 0);
  EXPECT_EQ(out_.rfind("balance-design ", 0), 0u) << out_;
}

// each command's help says what that command does, not the outputs of run; `help` is help
TEST_F(CliTest, HelpPerCommand) {
  EXPECT_EQ(run("help"), 0) << err_;
  const std::string top = out_;
  EXPECT_NE(top.find("Exit codes"), std::string::npos) << top;
  EXPECT_EQ(run("--help"), 0);
  EXPECT_EQ(out_, top);
  EXPECT_EQ(run("help run"), 0) << err_;
  EXPECT_NE(out_.find("balanced-timeseries.csv"), std::string::npos) << out_;
  for (const char* command : {"validate", "report", "bench"}) {
    EXPECT_EQ(run(std::string(command) + " --help"), 0) << command;
    EXPECT_EQ(out_.find("balanced-timeseries.csv"), std::string::npos) << command << "\n" << out_;
    EXPECT_LT(std::count(out_.begin(), out_.end(), '\n'), 30) << command << "\n" << out_;
    const std::string own = out_;
    EXPECT_EQ(run(std::string("help ") + command), 0) << command;
    EXPECT_EQ(out_, own) << command;
  }
}

// `help TOPIC` of a topic that is no command is a mistake: one line naming the commands, the
// usage exit code, and neither run's help nor the overview; `help help` is the overview
TEST_F(CliTest, HelpOnAnUnknownTopicIsAnError) {
  EXPECT_EQ(run("help"), 0) << err_;
  const std::string top = out_;
  for (const char* topic : {"bogus", "study.yaml", "--out"}) {
    EXPECT_EQ(run(std::string("help ") + topic), 2) << topic;
    EXPECT_TRUE(out_.empty()) << topic << "\n" << out_;
    EXPECT_EQ(err_.find('\n'), err_.size() - 1) << topic << "\n" << err_;
    EXPECT_NE(err_.find(std::string("no help on \"") + topic + "\""), std::string::npos) << err_;
    EXPECT_NE(err_.find("run, validate, report and bench"), std::string::npos) << err_;
  }
  EXPECT_EQ(run("help help"), 0) << err_;
  EXPECT_EQ(out_, top);
}

// The terminal says which part of the shaking force its lines give, and shows a value that is
// round-off of its natural scale as 0 (the report page's rule): the optimised Watt six-bar's
// crank counterweight on its link's axis (y of 1e-17 m in summary.json, a linkage of about 1 m),
// a balanced linkage's shaking force beside its bearing forces and its ratio to the original's.
TEST_F(CliTest, TerminalSaysTheInertialPartAndShowsRoundOffAsZero) {
  EXPECT_EQ(run("run " + quote(kExamples + "/watt-sixbar-optimized.yaml") + " --out w"), 0) << err_;
  EXPECT_NE(out_.find("\n  |Fsh|    inertial rms 11.8807 N, max 25.0743 N\n"), std::string::npos)
      << out_;
  EXPECT_NE(out_.find("\n  |Msh|    inertial rms "), std::string::npos) << out_;
  const std::string summary = read(dir_ / "w" / "summary.json");
  const std::regex y(
      "\"name\": \"crank counterweight y from O2 in link axes \\[m\\]\",\\s*"
      "\"value\": ([-+0-9.eE]+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(summary, m, y)) << summary;
  ASSERT_GT(std::abs(std::stod(m[1].str())), 0.0);
  ASSERT_LT(std::abs(std::stod(m[1].str())), 1e-12);
  EXPECT_NE(out_.find("counterweight 0.46 kg at [-0.25, 0] m from O2"), std::string::npos) << out_;

  EXPECT_EQ(
      run("run " + quote(kExamples + "/paper-fourbar-driven-force-balanced.yaml") + " --out b"), 0)
      << err_;
  const std::regex after("\n  Fsh_rms +169\\.865 +([^ ]+) +([^ \n]+)\n");
  ASSERT_TRUE(std::regex_search(out_, m, after)) << out_;
  EXPECT_EQ(m[1].str(), "0") << "round-off of the run's forces";
  EXPECT_EQ(m[2].str(), "0") << "the ratio of round-off";
  const std::string comparison = read(dir_ / "b" / "comparison.csv");
  ASSERT_TRUE(std::regex_search(comparison, m, std::regex("\nFsh_rms,[^,]+,([^,]+),")));
  EXPECT_GT(std::abs(std::stod(m[1].str())), 0.0) << "the file keeps the exact value";
}

// the output folder holds its study: `report DIR` from another directory gives the same page,
// even when the study was given by a relative path that does not lead there
TEST_F(CliTest, ReportFromAnotherDirectoryGivesTheSamePage) {
  fs::copy_file(kExamples + "/paper-fourbar-driven.yaml", dir_ / "mine.yaml");
  EXPECT_EQ(run("run mine.yaml --out res"), 0) << err_;
  ASSERT_TRUE(fs::exists(dir_ / "res" / "study.yaml"));
  EXPECT_EQ(read(dir_ / "res" / "study.yaml"), read(dir_ / "mine.yaml"));
  const std::string first = read(dir_ / "res" / "report.html");
  fs::create_directories(dir_ / "elsewhere");
  fs::remove(dir_ / "mine.yaml");  // even with the original gone
  EXPECT_EQ(std::system(("cd " + quote((dir_ / "elsewhere").string()) + " && " + quote(kExe) +
                         " report ../res >/dev/null 2>&1")
                            .c_str()),
            0);
  EXPECT_EQ(read(dir_ / "res" / "report.html"), first);
}

}  // namespace
