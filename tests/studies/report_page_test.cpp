// What a machine designer reads on the report page: a long run's page stays a few MB (its charts
// draw a decimated set of samples, the data files keep all), a value that is round-off of its
// quantity's scale shows as 0 (never 6.123e-17), a driven run's hodograph is closed by its
// periodic end, tables carry their units, the harmonic bars are harmonics.csv's numbers, a
// Pareto run without a single design still gets its page, and a chart gnuplot cannot draw costs
// that chart only.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "studies/report/report.hpp"
#include "studies/report/study_parts.hpp"
#include "studies/run/files.hpp"
#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;
using bd::testing::read;

class ReportPageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_report_page_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// the <svg> of the chart or animation with this id
std::string svg_of(const std::string& html, const std::string& id) {
  const std::size_t at = html.find("id=\"" + id + "\"");
  if (at == std::string::npos) return "";
  return html.substr(at, html.find("</svg>", at) - at);
}

TEST_F(ReportPageTest, ALongRunsPageStaysSmallAndLinksTheFullData) {
  // 200 001 samples of the driven paper four-bar: 2e5 rows of 32 numbers in timeseries.csv
  const std::string text =
      bd::testing::edited(read(bd::testing::example_path("paper-fourbar-driven.yaml")),
                          "samples: 360", "samples: 200001");
  const RunResult r = run_study(parse_study(text, "long.yaml"), dir_);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(fs::exists(dir_ / "report.html")) << (r.warnings.empty() ? "" : r.warnings[0]);
  const auto page = fs::file_size(dir_ / "report.html");
  EXPECT_GT(fs::file_size(dir_ / "timeseries.csv"), 50u << 20);   // the full data: > 50 MB
  EXPECT_LT(page, 3u << 20) << "a page of " << page << " bytes";  // a few MB at most
  const std::string html = read(dir_ / "report.html");
  std::smatch drawn;
  const std::regex note(
      "The run has 200001 samples; the charts over the run draw ([0-9]+) of them");
  ASSERT_TRUE(std::regex_search(html, drawn, note));
  EXPECT_LE(std::stoi(drawn[1].str()), 2000);
  EXPECT_GE(std::stoi(drawn[1].str()), 1000);
  EXPECT_NE(html.find("<a href=\"timeseries.csv\">timeseries.csv</a>"), std::string::npos);
}

TEST(ReportPage, DecimatedReadingKeepsTheFirstTheLastAndAtMostTheRowsAsked) {
  const fs::path file = fs::temp_directory_path() / ("bd_decimate_" + std::to_string(::getpid()));
  std::string text = "t,x\n";
  for (int i = 0; i < 10007; ++i) text += std::to_string(i) + "," + std::to_string(2 * i) + "\n";
  write_text_file(text, file);
  for (std::size_t max : {3u, 10u, 2000u, 10007u, 20000u}) {
    std::size_t total = 0;
    const report_support::Csv csv = report_support::read_csv_decimated(file, max, &total);
    EXPECT_EQ(total, 10007u);
    ASSERT_FALSE(csv.rows.empty());
    EXPECT_LE(csv.rows.size(), max);
    EXPECT_GE(csv.rows.size(), std::min<std::size_t>(max, 10007) / 2) << max;
    EXPECT_EQ(csv.rows.front()[0], "0");
    EXPECT_EQ(csv.rows.back()[0], "10006");
    EXPECT_EQ(csv.rows.back()[1], "20012");
  }
  fs::remove(file);
}

TEST_F(ReportPageTest, RoundOffOfAQuantitysScaleShowsAsZero) {
  // the coupler's centre of mass on its line's normal: e = 1.45 cos(pi/2) = 8.9e-17 m
  std::string text = read(bd::testing::example_path("paper-fourbar-driven.yaml"));
  text = bd::testing::edited(text, "s: 1.45, sigma: 0.4,", "s: 1.45, sigma: 1.5707963267948966,");
  const Study study = parse_study(text, "normal.yaml");
  ASSERT_GT(std::abs(study.fourbar().coupler.e), 0.0);
  ASSERT_LT(std::abs(study.fourbar().coupler.e), 1e-15);
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  // no number of that size is shown as text anywhere on the page (titles keep the exact text)
  const std::regex tiny(">[-+]?[0-9.]+e-1[5-9]<");
  EXPECT_FALSE(std::regex_search(html, tiny)) << "round-off shown as a number";
  EXPECT_NE(html.find("<th>2 coupler</th><td class=\"n\">3</td><td class=\"n\">3</td><td "
                      "class=\"n\">1.45</td><td class=\"n\">1.5708</td><td class=\"n\">0</td>"),
            std::string::npos);
}

TEST_F(ReportPageTest, DrivenHodographIsClosedByItsPeriodicEnd) {
  const Study study = load_study(bd::testing::example_path("paper-fourbar-driven.yaml"));
  ASSERT_TRUE(run_study(study, dir_).ok());
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const std::string svg = svg_of(read(dir_ / "report.html"), "chart-hodograph");
  ASSERT_FALSE(svg.empty());
  // the curve: the path of the first plot, after its legend sample (M .. L ..)
  const std::size_t g = svg.find("<g id=\"hodograph-gnuplot_plot_1\"");
  ASSERT_NE(g, std::string::npos);
  const std::size_t d = svg.find("d='", g);
  const std::string path = svg.substr(d + 3, svg.find('\'', d + 3) - d - 3);
  const std::regex point("([-0-9.]+),([-0-9.]+)");
  std::vector<std::string> points;
  for (auto m = std::sregex_iterator(path.begin(), path.end(), point); m != std::sregex_iterator();
       ++m) {
    points.push_back((*m)[0].str());
  }
  ASSERT_GT(points.size(), 300u);  // 2 of the legend, 360 samples and the end
  EXPECT_EQ(points[2], points.back()) << "the curve ends where it starts";
  EXPECT_NE(points[2], points[points.size() - 2]);
  EXPECT_NE(read(dir_ / "report.html").find("closed by the periodic end"), std::string::npos);
}

TEST_F(ReportPageTest, TablesCarryTheirUnits) {
  const Study study =
      load_study(bd::testing::example_path("paper-fourbar-driven-force-balanced.yaml"));
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  // the scene, the counterweights, the metrics and the comparison
  for (const char* header :
       {"<th>theta1 [rad]</th>", "<th>omega1 [rad/s]</th>", "<th>mass [kg]</th>",
        "<th>position [m]</th>", "<th>distance [m]</th>", "<th>unit</th>"}) {
    EXPECT_NE(html.find(header), std::string::npos) << header;
  }
  // a point mass has no radius: no radius column for the counterweights
  EXPECT_EQ(html.find("<th>radius [m]</th>"), std::string::npos);
  const std::regex metric_row(
      "<tr><th>(Fsh_rms|Msh_max|tau_rms|RA0_max)</th>.*?<td>([^<]*)</td>"
      "(<td></td>|<td>t = [^<]*</td>){0,2}</tr>");  // the last cells: where the peaks lie
  int rows = 0;
  for (auto m = std::sregex_iterator(html.begin(), html.end(), metric_row);
       m != std::sregex_iterator(); ++m, ++rows) {
    const std::string name = (*m)[1].str(), unit = (*m)[2].str();
    EXPECT_EQ(unit, name.rfind("Fsh", 0) == 0 || name.rfind("RA0", 0) == 0 ? "N" : "N m") << name;
  }
  EXPECT_GE(rows, 8);  // the metrics table and the comparison table
  EXPECT_NE(html.find("Units on this page and in the data files: SI"), std::string::npos);
}

TEST_F(ReportPageTest, UnitsReadAreListed) {
  std::string text = read(bd::testing::example_path("paper-fourbar-driven.yaml"));
  text = bd::testing::edited(text, "omega1: 6.283185307179586", "omega1: 60 rpm");
  ASSERT_TRUE(run_study(parse_study(text, "rpm.yaml"), dir_).ok());
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("The study file gave these values in units of their own"), std::string::npos);
  EXPECT_NE(html.find("<li>scene.omega1: 60 rpm"), std::string::npos);
}

TEST_F(ReportPageTest, HarmonicBarsAreTheNumbersOfHarmonicsCsv) {
  const Study study =
      load_study(bd::testing::example_path("paper-fourbar-driven-force-balanced.yaml"));
  ASSERT_TRUE(run_study(study, dir_).ok());
  std::string blocks;
  const report_support::Json summary =
      report_support::parse_json(read(dir_ / "summary.json"), "summary.json");
  const report_support::Scales scales = report_support::run_scales(summary, linkage_size(study));
  const std::vector<report_support::Chart> charts =
      report_support::harmonic_charts(dir_, blocks, scales);
  ASSERT_EQ(charts.size(), 2u);
  EXPECT_EQ(charts[0].id, "harmonics-original");
  EXPECT_EQ(charts[1].id, "harmonics-balanced");
  // each bar's number against harmonics.csv, read here on its own
  const report_support::Csv csv = report_support::read_csv(dir_ / "harmonics.csv");
  auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(csv.header.begin(), csv.header.end(), name) -
                                    csv.header.begin());
  };
  const std::size_t design = column("design"), order = column("order");
  const std::size_t cols[] = {column("Fsh_forward"), column("Fsh_backward"),
                              column("Msh_amplitude"), column("tau_amplitude")};
  // the largest forward/backward amplitude or the largest force of the run (its metrics in N,
  // read here from summary.json on their own): a bar of round-off of it is drawn as 0
  double fsh_scale = 0;
  for (const auto& row : csv.rows) {
    if (row[order] == "0") continue;
    fsh_scale =
        std::max({fsh_scale, std::abs(std::stod(row[cols[0]])), std::abs(std::stod(row[cols[1]]))});
  }
  for (const char* key : {"metrics", "balanced_metrics"}) {
    for (const auto& [name, v] : summary.at(key).items()) {
      if (summary.at("metric_units").at(name) == "N")
        fsh_scale = std::max(fsh_scale, v.get<double>());
    }
  }
  int bars = 0, zeros = 0;
  for (const auto& row : csv.rows) {
    if (row[order] == "0") continue;
    const std::string block_name = "$harmonics_" + row[design] + " << EOD\n";
    const std::size_t at = blocks.find(block_name);
    ASSERT_NE(at, std::string::npos) << row[design];
    const std::string block = blocks.substr(at, blocks.find("EOD\n", at + block_name.size()) - at);
    std::string line = row[order];
    for (std::size_t k = 0; k < 4; ++k) {
      const double v = std::stod(row[cols[k]]);
      const bool noise = k < 2 && std::abs(v) <= 1e-12 * fsh_scale;
      line += "," + (noise ? std::string("0") : row[cols[k]]);
      zeros += noise;
    }
    EXPECT_NE(block.find("\n" + line + "\n"), std::string::npos) << line;
    ++bars;
  }
  EXPECT_GE(bars, 2 * 6);
  EXPECT_GE(zeros, 6) << "the balanced design's force amplitudes are round-off";
  const std::string html = read(dir_ / "report.html");
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  EXPECT_FALSE(svg_of(html, "chart-harmonics-original").empty());
  EXPECT_FALSE(svg_of(html, "chart-harmonics-balanced").empty());
}

// the points (SVG pixels) of the curve of plot `plot` of chart `id`, its legend sample left out
std::vector<std::pair<double, double>> curve_points(const std::string& html, const std::string& id,
                                                    int plot) {
  const std::string svg = svg_of(html, "chart-" + id);
  const std::size_t g = svg.find("<g id=\"" + id + "-gnuplot_plot_" + std::to_string(plot) + "\"");
  if (g == std::string::npos) return {};
  const std::size_t d = svg.find("d='", g);
  const std::string path = svg.substr(d + 3, svg.find('\'', d + 3) - d - 3);
  const std::regex point("([-0-9.]+),([-0-9.]+)");
  std::vector<std::pair<double, double>> points;
  for (auto m = std::sregex_iterator(path.begin(), path.end(), point); m != std::sregex_iterator();
       ++m) {
    points.emplace_back(std::stod((*m)[1].str()), std::stod((*m)[2].str()));
  }
  if (points.size() >= 2) points.erase(points.begin(), points.begin() + 2);  // the legend's
  return points;
}

// A force-balanced four-bar under gravity (the driven paper four-bar's example with g): its
// metrics (the inertial part) say Fsh_max 0, its total carries the weight. The page says which
// part each table and chart shows, and the hodograph draws the inertial part: the balanced
// design's curve sits where the original's is centred, at the origin (over a period of a periodic
// motion −Σ m a has mean 0), not at its weight, 121.9 N below.
TEST_F(ReportPageTest, ShakingChartsAndMetricsSayWhichPartTheyShow) {
  const std::string text = bd::testing::edited(
      read(bd::testing::example_path("paper-fourbar-driven-force-balanced.yaml")), "\nscene:\n",
      "\nloads:\n  gravity: [0, -9.81]\nscene:\n");
  const Study study = parse_study(text, "fbg.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("Fsh, Msh: the inertial part of the shaking force and moment about A0"),
            std::string::npos);
  EXPECT_NE(html.find("Fsh_total, Msh_total: the total the frame feels, weights and applied "
                      "loads included"),
            std::string::npos);
  EXPECT_NE(html.find("<h3>Shaking-force hodograph, inertial part</h3>"), std::string::npos);
  EXPECT_NE(html.find("<h3>Shaking moment, inertial part</h3>"), std::string::npos);
  EXPECT_NE(html.find("the inertial shaking force and moment (what balancing acts on; weights "
                      "and applied loads are not in them)"),
            std::string::npos);
  // the table's caption and the charts' alike
  EXPECT_NE(html.find("design) of the inertial shaking force and moment (what balancing acts on"),
            std::string::npos);
  EXPECT_EQ(html.find("total shaking force and moment"), std::string::npos);
  // and they are: under gravity the mean (order 0) of the force is zero, not the weight
  {
    const report_support::Csv csv = report_support::read_csv(dir_ / "harmonics.csv");
    const auto column = [&csv](const char* name) {
      return static_cast<std::size_t>(std::find(csv.header.begin(), csv.header.end(), name) -
                                      csv.header.begin());
    };
    const std::size_t order = column("order"), fy = column("Fshy_amplitude");
    ASSERT_LT(fy, csv.header.size());
    int means = 0;
    for (const std::vector<std::string>& row : csv.rows) {
      if (row[order] != "0") continue;
      ++means;
      EXPECT_LE(std::stod(row[fy]), 1e-9 * 7.3 * 9.81) << row[0];
    }
    EXPECT_EQ(means, 2);  // the original and the balanced design
  }
  // the original's total is its inertial hodograph moved by its weight, 7.3 kg x 9.81 m/s² down
  EXPECT_NE(html.find("the original's is the same curve moved by (0, " +
                      text::digits(-7.3 * 9.81, 6) + ") N"),
            std::string::npos);
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const auto original = curve_points(html, "hodograph", 1);
  const auto balanced = curve_points(html, "hodograph", 2);
  ASSERT_GT(original.size(), 300u);
  ASSERT_FALSE(balanced.empty());
  double x = 0, y = 0;
  for (std::size_t i = 0; i + 1 < original.size(); ++i) {  // the last closes the curve
    x += original[i].first / static_cast<double>(original.size() - 1);
    y += original[i].second / static_cast<double>(original.size() - 1);
  }
  for (const auto& [bx, by] : balanced) {
    EXPECT_NEAR(bx, x, 1.0) << "the balanced design's inertial shaking force is 0";
    EXPECT_NEAR(by, y, 1.0) << "the balanced design's inertial shaking force is 0";
  }
}

// every number shown as text on a page (a table cell, a chart's tick) that looks like round-off;
// a relative error (verification_error: its own scale is 1, and it is shown as it is) aside
std::vector<std::string> tiny_numbers(const std::string& html) {
  const std::regex tiny(">\\s*([-+]?[0-9.]+e-(1[3-9]|[2-9][0-9]))\\s*<");
  std::vector<std::string> found;
  for (auto m = std::sregex_iterator(html.begin(), html.end(), tiny); m != std::sregex_iterator();
       ++m) {
    const std::size_t th = html.rfind("<th>", static_cast<std::size_t>(m->position()));
    const std::string row = th == std::string::npos ? "" : html.substr(th, 60);
    if (row.find("_error") == std::string::npos) found.push_back((*m)[1].str());
  }
  return found;
}

// Round-off of a quantity's natural scale shows as 0 in every table and chart: the optimised
// Watt six-bar's crank counterweight on its link's axis (y = 1.5e-17 m beside a linkage of
// about 1 m), in the variables and the Pareto tables; a balance shaft's order it cancels
// (engine-lanchester); a balanced linkage's shaking force beside its bearing forces
// (paper-fourbar-balanced, the only design of its run). The optimised Watt design's force
// harmonics are constraint-tolerance noise (1e-10 N beside the original's 14 N): its chart,
// on the original's axes, says they are too small to see.
TEST_F(ReportPageTest, RoundOffIsZeroInEveryTableAndChart) {
  for (const char* example :
       {"watt-sixbar-optimized.yaml", "engine-lanchester.yaml", "paper-fourbar-balanced.yaml"}) {
    const fs::path out = dir_ / example;
    const Study study = load_study(bd::testing::example_path(example));
    ASSERT_TRUE(run_study(study, out).ok()) << example;
    const std::string html = read(out / "report.html");
    const std::vector<std::string> tiny = tiny_numbers(html);
    EXPECT_TRUE(tiny.empty()) << example << ": " << tiny.size() << " numbers of round-off, "
                              << (tiny.empty() ? "" : tiny[0]);
    const report_support::Json summary =
        report_support::parse_json(read(out / "summary.json"), "summary.json");
    const std::string name = example;
    if (name == "watt-sixbar-optimized.yaml") {
      const double size = linkage_size(study);
      EXPECT_GT(size, 0.5);
      const report_support::Json& y = summary.at("optimize").at("variables").at(2);
      ASSERT_EQ(y.at("name"), "crank counterweight y from O2 in link axes [m]");
      ASSERT_GT(std::abs(y.at("value").get<double>()), 0.0);
      ASSERT_LT(std::abs(y.at("value").get<double>()), 1e-12 * size);
      EXPECT_NE(html.find("<td>crank counterweight y from O2 in link axes [m]</td><td class=\"n\" "
                          "title=\"" +
                          report_support::text(y.at("value")) + "\">0</td>"),
                std::string::npos);
      if (!find_gnuplot().empty()) {
        const std::string chart = svg_of(html, "chart-harmonics-optimized");
        EXPECT_NE(chart.find("too small to see at this scale"), std::string::npos);
        EXPECT_EQ(svg_of(html, "chart-harmonics-original").find("too small to see"),
                  std::string::npos);
      }
    }
    if (name == "paper-fourbar-balanced.yaml") {
      const double fsh = summary.at("metrics").at("Fsh_rms").get<double>();
      const double bearing = summary.at("metrics").at("RA0_max").get<double>();
      ASSERT_GT(fsh, 0.0);
      ASSERT_LT(fsh, 1e-12 * bearing);
      EXPECT_NE(html.find("<tr><th>Fsh_rms</th><td class=\"n\" title=\"" +
                          report_support::text(summary.at("metrics").at("Fsh_rms")) + "\">0</td>"),
                std::string::npos);
    }
  }
}

// Data that one chart cannot draw (every value of its curve undefined: gnuplot stops the whole
// script at it) costs that chart only: it becomes a notice with gnuplot's reason, the other
// charts are drawn, and the page is written. A gnuplot that draws nothing at all still fails.
TEST(ReportPage, AChartGnuplotCannotDrawIsANoticeAndTheOthersAreDrawn) {
  const std::string gnuplot = find_gnuplot();
  if (gnuplot.empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const std::string blocks =
      "$good << EOD\n0,1\n1,2\n2,0.5\nEOD\n$bad << EOD\n0,\n1,\n2,\nEOD\n";
  const std::vector<report_support::Chart> charts = {
      {"first", "first", "", "plot $good using 1:2 with lines title 'a'"},
      {"undefined", "undefined", "", "plot $bad using 1:2 with lines title 'b'"},
      {"last", "last", "", "plot $good using 1:2 with points title 'c'"}};
  const std::vector<std::string> svgs = report_support::draw(gnuplot, blocks, charts);
  ASSERT_EQ(svgs.size(), 3u);
  EXPECT_EQ(svgs[0].rfind("<svg", 0), 0u);
  EXPECT_EQ(svgs[2].rfind("<svg", 0), 0u);
  EXPECT_EQ(svgs[1].rfind("<p class=\"notice\">This chart could not be drawn", 0), 0u) << svgs[1];
  EXPECT_NE(svgs[1].find("undefined"), std::string::npos) << "gnuplot's reason: " << svgs[1];
  EXPECT_THROW(report_support::draw("/bin/false", blocks, charts), std::runtime_error);
}

// the driven paper four-bar with counterweights to optimise and a front of 3 points
Study pareto_study() {
  return parse_study(read(bd::testing::example_path("paper-fourbar-driven.yaml")) +
                         "optimize:\n"
                         "  objective: {Fsh_rms: 1}\n"
                         "  variables:\n"
                         "    counterweights: {crank: {mass_max: 10}, rocker: {mass_max: 10}}\n"
                         "  pareto: {first: Fsh_rms, second: Msh_rms, points: 3}\n",
                     "p.yaml");
}

// A point of the front where the solver found no design has empty metric and variable cells
// (the solver's last iterate is no design), though the result holds one.
TEST(ReportPage, ParetoRowWithoutADesignHasEmptyCells) {
  const Study study = pareto_study();
  OptimizedRun run;
  run.variable_names = {"a", "b", "c", "d", "e", "f"};
  run.design_variables = 6;
  optimize::ParetoPoint point;
  point.epsilon = 0.5;
  point.result.termination = optimize::Termination::kFailed;
  point.result.x = Eigen::VectorXd::Ones(6);  // the solver's last iterate: no design
  run.pareto = {point};
  std::istringstream lines(pareto_csv(study, run));
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  EXPECT_EQ(row, "0.5,,,failed,,,,,,,") << row;
}

// The page of a Pareto run whose every point found no design: the front's chart has only the
// original and the chosen optimum (gnuplot is not handed an empty data set), and the page says
// how many points found a design.
TEST_F(ReportPageTest, ParetoFrontWithoutADesignStillGetsItsPage) {
  const Study study = pareto_study();
  ASSERT_TRUE(run_study(study, dir_).ok());
  // every row as the runner writes a point without a design
  report_support::Csv pareto = report_support::read_csv(dir_ / "pareto.csv");
  std::string text;
  for (std::size_t k = 0; k < pareto.header.size(); ++k) text += (k ? "," : "") + pareto.header[k];
  text += "\n";
  for (const auto& row : pareto.rows) {
    text += row[0] + ",,,failed,";
    for (std::size_t k = 5; k < pareto.header.size(); ++k) text += ",";
    text += "\n";
  }
  write_text_file(text, dir_ / "pareto.csv");
  fs::remove(dir_ / "report.html");
  ASSERT_NO_THROW(write_report(study, dir_));
  const std::string html = read(dir_ / "report.html");
  EXPECT_NE(html.find("0 of its 3 points found a design"), std::string::npos);
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const std::string chart = svg_of(html, "chart-pareto");
  ASSERT_FALSE(chart.empty());
  EXPECT_NE(chart.find("original design"), std::string::npos);
  EXPECT_EQ(chart.find(">front<"), std::string::npos);
  EXPECT_NE(html.find("3 of the 3 points found no design"), std::string::npos);
}

}  // namespace
}  // namespace bd::studies
