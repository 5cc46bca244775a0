// The study report: every run writes a self-contained report.html with the study's name, the
// metrics exactly as summary.json has them, a chart per figure when gnuplot is there (and a plain
// notice when it is not), and no reference to the network.
#include "studies/report/report.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

using bd::testing::read;

using bd::testing::count;

// a number as the animation's hover text writes it (4 significant digits)
std::string fmt_for_test(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// sets an environment variable for the scope, restoring the old value after
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_report_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// every "name": number pair of summary.json's metrics objects, as written
std::vector<std::string> metric_values(const std::string& json) {
  std::vector<std::string> values;
  const std::regex pair("\"(Fsh|Msh|tau|RA0|RA3)_(rms|max)\": ([-+0-9.eE]+)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), pair); it != std::sregex_iterator();
       ++it) {
    values.push_back((*it)[3].str());
  }
  return values;
}

// the text with the SVG and XLink namespace names taken out
std::string without_namespaces(std::string html) {
  for (const std::string ns : {"http://www.w3.org/2000/svg", "http://www.w3.org/1999/xlink"}) {
    for (std::size_t at = html.find(ns); at != std::string::npos; at = html.find(ns, at)) {
      html.erase(at, ns.size());
    }
  }
  return html;
}

// every <svg ...>...</svg> of the page
std::vector<std::string> svgs(const std::string& html) {
  std::vector<std::string> out;
  for (std::size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at)) {
    const std::size_t end = html.find("</svg>", at);
    if (end == std::string::npos) break;
    out.push_back(html.substr(at, end - at));
    at = end;
  }
  return out;
}

TEST_F(ReportTest, BalanceRunWritesASelfContainedReport) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const fs::path page = dir_ / "report.html";
  ASSERT_TRUE(fs::exists(page));
  const std::string html = read(page);
  EXPECT_NE(html.find("<title>" + study.name), std::string::npos);
  EXPECT_NE(html.find("mass-matrix"), std::string::npos);  // the method used, and why
  EXPECT_NE(html.find(r.method.reason), std::string::npos);
  EXPECT_NE(html.find(">completed<"), std::string::npos);

  // every metric value (original and balanced) exactly as summary.json writes it
  const std::vector<std::string> values = metric_values(read(r.summary));
  ASSERT_EQ(values.size(), 30u);  // metrics, balanced_metrics, reduction
  for (const std::string& v : values) EXPECT_NE(html.find("\"" + v + "\""), std::string::npos) << v;
  // the comparison table's rows, from comparison.csv
  EXPECT_NE(html.find("comparison.csv"), std::string::npos);
  EXPECT_NE(html.find(">added_mass<"), std::string::npos);

  // nothing fetched from anywhere
  const std::string rest = without_namespaces(html);
  EXPECT_EQ(rest.find("http://"), std::string::npos);
  EXPECT_EQ(rest.find("https://"), std::string::npos);
  EXPECT_EQ(rest.find("<script"), std::string::npos);
  EXPECT_EQ(rest.find("<link"), std::string::npos);

  // the linkage animated (no gnuplot needed): the original and the balanced design
  EXPECT_NE(html.find("<svg class=\"animation\" id=\"animation-original\""), std::string::npos);
  EXPECT_NE(html.find("<svg class=\"animation\" id=\"animation-balanced\""), std::string::npos);

  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  std::vector<std::string> charts;
  for (const std::string& svg : svgs(html))
    if (svg.find("class=\"animation\"") == std::string::npos) charts.push_back(svg);
  // angles, reactions, hodograph, Msh, drive, harmonic orders of both designs
  EXPECT_EQ(charts.size(), 7u);
  for (const char* id : {"angles", "reactions", "hodograph", "shaking-moment", "drive",
                         "harmonics-original", "harmonics-balanced"}) {
    EXPECT_NE(html.find(std::string("id=\"chart-") + id + "\""), std::string::npos) << id;
  }
  for (const std::string& svg : charts) EXPECT_GT(count(svg, "<path"), 3u);
  EXPECT_NE(html.find("balanced"), std::string::npos);  // the overlay's legend
  EXPECT_EQ(html.find("need gnuplot"), std::string::npos);
  // ids made unique per chart
  EXPECT_EQ(count(html, "id='gpPt0'"), 0u);
  EXPECT_EQ(count(html, "id='angles-gpPt0'"), 1u);
}

TEST_F(ReportTest, WithoutGnuplotTheReportSaysSoAndKeepsTheTables) {
  const ScopedEnv env("BD_GNUPLOT", "/nonexistent/gnuplot");
  EXPECT_EQ(find_gnuplot(), "");
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("The charts need gnuplot"), std::string::npos);
  // no chart, but the animation, which needs no gnuplot
  EXPECT_EQ(html.find("<figure class=\"chart\""), std::string::npos);
  EXPECT_EQ(count(html, "<svg"), 1u);
  EXPECT_NE(html.find("<svg class=\"animation\" id=\"animation-original\""), std::string::npos);
  for (const std::string& v : metric_values(read(r.summary))) {
    EXPECT_NE(html.find("\"" + v + "\""), std::string::npos) << v;
  }
  EXPECT_NE(html.find("href=\"timeseries.csv\""), std::string::npos);
  EXPECT_NE(html.find("The linkage at four samples"), std::string::npos);
}

TEST_F(ReportTest, OptimizeRunWithParetoFrontHasItsChartAndTable) {
  std::string yaml = read(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  yaml +=
      "optimize:\n"
      "  objective: {Fsh_rms: 1}\n"
      "  variables:\n"
      "    counterweights: {crank: {mass_max: 10}, rocker: {mass_max: 10}}\n"
      "  pareto: {first: Fsh_rms, second: Msh_rms, points: 3}\n";
  const fs::path file = dir_ / "pareto.yaml";
  std::ofstream(file) << yaml;
  const Study study = load_study(file.string());
  const fs::path out = dir_ / "out";
  const RunResult r = run_study(study, out);
  ASSERT_TRUE(r.ok());
  const std::string html = read(out / "report.html");
  EXPECT_NE(html.find("<h2>Pareto front</h2>"), std::string::npos);
  EXPECT_NE(html.find("<h2>Comparison</h2>"), std::string::npos);
  EXPECT_NE(html.find("optimised"), std::string::npos);
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  // angles, reactions, hodograph, Msh, drive, two harmonic charts, Pareto; two animations
  EXPECT_EQ(svgs(html).size(), 10u);
  EXPECT_NE(html.find("id=\"chart-pareto\""), std::string::npos);
  EXPECT_NE(html.find("id=\"animation-optimized\""), std::string::npos);
  EXPECT_NE(html.find("The optimised linkage at four samples"), std::string::npos);
  // the front's axes with their units, the original and the chosen optimum marked
  const std::size_t at = html.find("id=\"chart-pareto\"");
  const std::string pareto = html.substr(at, html.find("</svg>", at) - at);
  EXPECT_NE(pareto.find("Fsh_rms [N]"), std::string::npos);
  EXPECT_NE(pareto.find("Msh_rms [N m]"), std::string::npos);
  EXPECT_NE(pareto.find("original design"), std::string::npos);
  EXPECT_NE(pareto.find("chosen optimum"), std::string::npos);
  // the front's table names its columns' units
  EXPECT_NE(html.find("<th>Fsh_rms [N]</th><th>Msh_rms [N m]</th>"), std::string::npos);
}

// the cells' text of each row of the table that follows <h3>heading</h3>
std::vector<std::vector<std::string>> table_after(const std::string& html,
                                                  const std::string& heading) {
  std::vector<std::vector<std::string>> rows;
  const std::size_t at = html.find("<h3>" + heading + "</h3>");
  if (at == std::string::npos) return rows;
  const std::string table = html.substr(at, html.find("</table>", at) - at);
  const std::regex row("<tr>(.*?)</tr>"), cell("<td[^>]*>([^<]*)</td>");
  for (auto r = std::sregex_iterator(table.begin(), table.end(), row); r != std::sregex_iterator();
       ++r) {
    const std::string text = (*r)[1].str();
    std::vector<std::string> cells;
    for (auto c = std::sregex_iterator(text.begin(), text.end(), cell); c != std::sregex_iterator();
         ++c) {
      cells.push_back((*c)[1].str());
    }
    if (!cells.empty()) rows.push_back(cells);
  }
  return rows;
}

// A planar balanced design's balance shafts are parts of its drawing: the shafts (one label for
// the Lanchester shafts that share the crank's pivot), and the eccentric masses of those that
// have one; the original, which has none, is drawn without them.
TEST_F(ReportTest, BalanceShaftsAreDrawnAsParts) {
  for (const char* example : {"engine-lanchester.yaml", "watt-sixbar-moment-balanced.yaml"}) {
    const Study study = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + example);
    const fs::path out = dir_ / example;
    ASSERT_TRUE(run_study(study, out).ok());
    const std::string html = read(out / "report.html");
    const std::size_t original = html.find("id=\"animation-original\""),
                      balanced = html.find("id=\"animation-balanced\"");
    ASSERT_NE(original, std::string::npos);
    ASSERT_NE(balanced, std::string::npos);
    const std::string a = html.substr(original, html.find("</svg>", original) - original);
    const std::string b = html.substr(balanced, html.find("</svg>", balanced) - balanced);
    EXPECT_EQ(a.find("balance shaft"), std::string::npos) << example;
    EXPECT_NE(b.find("balance shaft"), std::string::npos) << example;
    const bool lanchester = std::string(example) == "engine-lanchester.yaml";
    for (const char* shaft : {"shaft_-1", "shaft_2", "shaft_-2"}) {
      EXPECT_EQ(b.find(std::string("balance shaft ") + shaft) != std::string::npos, lanchester)
          << example << " " << shaft;
    }
    EXPECT_EQ(b.find("balance shaft counter_rocker") != std::string::npos, !lanchester) << example;
    // only eccentric shafts carry a mass to draw, and it moves
    EXPECT_EQ(b.find("eccentric mass of") != std::string::npos, lanchester) << example;
  }
}

TEST_F(ReportTest, BalancedLinkageIsDrawnWithItsCounterweights) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  // columns: t, theta1, A1, A2, G1, G2, G3, P1, P2, P3, S
  const auto original = table_after(html, "The linkage at four samples");
  const auto balanced = table_after(html, "The balanced linkage at four samples");
  ASSERT_EQ(original.size(), 4u);
  ASSERT_EQ(balanced.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    ASSERT_EQ(balanced[i].size(), 11u);
    // the same driven motion: the same joints
    EXPECT_EQ(balanced[i][2], original[i][2]);
    EXPECT_EQ(balanced[i][3], original[i][3]);
    // force balanced: S stays where it is (to the 4 digits shown); the original's moves
    EXPECT_EQ(balanced[i][10], balanced[0][10]);
    if (i > 0) {
      EXPECT_NE(original[i][10], original[0][10]);
    }
  }
  // at theta1 = 0 the crank lies along +x: its centre of mass is ahead of A0, the balanced
  // crank's (counterweight merged) behind it
  ASSERT_EQ(original[0][1], "0");
  EXPECT_EQ(original[0][4].rfind("(0.", 0), 0u) << original[0][4];
  EXPECT_EQ(balanced[0][4].rfind("(-", 0), 0u) << balanced[0][4];
  // the counterweights are drawn as parts on the balanced design's links, not on the original's
  const std::size_t a = html.find("id=\"animation-original\""),
                    b = html.find("id=\"animation-balanced\"");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  const std::string first = html.substr(a, html.find("</svg>", a) - a);
  const std::string second = html.substr(b, html.find("</svg>", b) - b);
  EXPECT_EQ(first.find("counterweight on the"), std::string::npos);
  EXPECT_NE(
      second.find("counterweight on the crank: " +
                  std::string(fmt_for_test(study.balance->crank_counterweight->mass)) + " kg"),
      std::string::npos);
  EXPECT_NE(second.find("counterweight on the rocker"), std::string::npos);
}

// the points of a polyline's "x,y x,y ..." text
std::vector<std::pair<double, double>> points_of(const std::string& text) {
  std::vector<std::pair<double, double>> out;
  std::istringstream in(text);
  for (std::string p; in >> p;) {
    const std::size_t comma = p.find(',');
    out.push_back({std::stod(p.substr(0, comma)), std::stod(p.substr(comma + 1))});
  }
  return out;
}

// The linkage animation moves every link over one revolution of the crank and loops without a
// jump: each link's polyline has an <animate> of its points whose last frame is its first (the
// periodic end); in every frame the crank's drawn length is the same (l1 at the picture's
// scale: a rigid link), as are the coupler's and the rocker's, and the ground joints stay put.
TEST_F(ReportTest, AnimationMovesTheLinksRigidlyOverOneRevolution) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  const std::size_t at = html.find("<svg class=\"animation\" id=\"animation-original\"");
  ASSERT_NE(at, std::string::npos);
  const std::string svg = html.substr(at, html.find("</svg>", at) - at);
  const std::regex link(
      "<polyline[^>]*><title>(crank A0-A1|coupler A1-A2|rocker A2-A3)</title>"
      "<animate attributeName=\"points\" dur=\"4s\" repeatCount=\"indefinite\""
      "[^>]*values=\"([^\"]*)\"");
  std::map<std::string, std::vector<double>> lengths;  // per link, its length in each frame [px]
  std::size_t frames = 0;
  for (auto m = std::sregex_iterator(svg.begin(), svg.end(), link); m != std::sregex_iterator();
       ++m) {
    std::vector<std::string> values;
    std::istringstream in((*m)[2].str());
    for (std::string v; std::getline(in, v, ';');) values.push_back(v);
    frames = values.size();
    ASSERT_GE(values.size(), 100u);
    EXPECT_EQ(values.front(), values.back()) << (*m)[1] << ": the loop closes";
    for (const std::string& v : values) {
      const auto p = points_of(v);
      ASSERT_EQ(p.size(), 2u);
      lengths[(*m)[1].str()].push_back(
          std::hypot(p[1].first - p[0].first, p[1].second - p[0].second));
    }
  }
  ASSERT_EQ(lengths.size(), 3u);
  EXPECT_EQ(frames, 121u);  // 120 samples of the revolution and the first again
  // rigid links: one length in every frame, to the rounding of the written coordinates (0.05 px
  // each: a drawn length is within 2 * 0.05 * sqrt(2) = 0.141 px of the true one, so two frames'
  // differ by at most 0.283 px), and the lengths in the
  // ratio of l1 : l2 : l3 = 1 : 3 : 2 (each mean to 0.1 px in about 180 px: 1e-3)
  const double l[] = {1.0, 3.0, 2.0};
  const char* names[] = {"crank A0-A1", "coupler A1-A2", "rocker A2-A3"};
  double mean[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& d = lengths[names[k]];
    const auto [lo, hi] = std::minmax_element(d.begin(), d.end());
    EXPECT_LE(*hi - *lo, 0.29) << names[k];
    for (double x : d) mean[k] += x / static_cast<double>(d.size());
  }
  for (int k = 1; k < 3; ++k) EXPECT_NEAR(mean[k] / mean[0], l[k] / l[0], 1e-3 * l[k]) << names[k];
}

TEST_F(ReportTest, ReportIsRebuiltFromTheDataFiles) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  run_study(study, dir_);
  const std::string first = read(dir_ / "report.html");
  fs::remove(dir_ / "report.html");
  EXPECT_EQ(write_report(study, dir_), dir_ / "report.html");
  EXPECT_EQ(read(dir_ / "report.html"), first);  // the same files give the same page
}

TEST_F(ReportTest, AMissingTimeSeriesOfTheBalancedDesignIsSaidAsMissing) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  fs::remove(dir_ / "balanced-timeseries.csv");
  write_report(study, dir_);
  const std::string html = read(dir_ / "report.html");
  // it was simulated (summary.json says so): the page does not say otherwise
  EXPECT_EQ(html.find("was not simulated"), std::string::npos);
  EXPECT_NE(html.find("<code>balanced-timeseries.csv</code> is missing from this folder"),
            std::string::npos);
}

TEST_F(ReportTest, RunFactsSayIntegratorStepsOnlyForAFreeScene) {
  const auto facts = [&](const char* example) {
    const Study study = load_study(std::string(BD_SOURCE_DIR "/studies/examples/") + example);
    run_study(study, dir_);
    return read(dir_ / "report.html");
  };
  const std::string driven = facts("paper-fourbar-driven.yaml");
  EXPECT_EQ(driven.find("integrator steps"), std::string::npos);
  EXPECT_NE(driven.find("<tr><th>dynamics evaluations</th>"), std::string::npos);
  const std::string free = facts("paper-fourbar.yaml");
  EXPECT_NE(free.find("<tr><th>integrator steps</th>"), std::string::npos);
  EXPECT_NE(free.find("<tr><th>dynamics evaluations</th>"), std::string::npos);
  // each peak says where the original's lies, in either scene: its time and the crank's angle,
  // as the charts' axes have it (degrees within the turn, from 0 to 360)
  for (const std::string* page : {&driven, &free}) {
    const std::regex where(
        "<tr><th>Fsh_max</th>.*?<td>N</td><td>t = [-0-9.e]+ s, θ1 = [0-9.e+]+°</td>");
    EXPECT_TRUE(std::regex_search(*page, where));
  }
}

TEST_F(ReportTest, FolderWithoutSummaryIsAnError) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  EXPECT_THROW(report_html(study, dir_, ""), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir_ / "report.html"));
}

TEST_F(ReportTest, GnuplotFailureIsAWarningAndTheRunGoesOn) {
  const ScopedEnv env("BD_GNUPLOT", "/bin/false");
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  ::testing::internal::CaptureStderr();
  const RunResult r = run_study(study, dir_);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(fs::exists(dir_ / "summary.json"));
  EXPECT_FALSE(fs::exists(dir_ / "report.html"));
  // the warning is returned, never printed by the library (the command line prints it)
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].rfind("report.html not written: gnuplot failed", 0), 0u) << r.warnings[0];
  EXPECT_EQ(err, "");
}

}  // namespace
}  // namespace bd::studies
