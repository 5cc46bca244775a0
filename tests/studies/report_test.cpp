// The study report: every run writes a self-contained report.html with the study's name, the
// metrics exactly as summary.json has them, a chart per figure when gnuplot is there (and a plain
// notice when it is not), and no reference to the network.
#include "studies/report/report.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

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

  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const std::vector<std::string> charts = svgs(html);
  EXPECT_EQ(charts.size(), 7u);  // angles, reactions, hodograph, Msh, drive, both linkages
  for (const char* id : {"angles", "reactions", "hodograph", "shaking-moment", "drive", "linkage",
                         "linkage-balanced"}) {
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
  EXPECT_EQ(html.find("<svg"), std::string::npos);
  for (const std::string& v : metric_values(read(r.summary))) {
    EXPECT_NE(html.find("\"" + v + "\""), std::string::npos) << v;
  }
  EXPECT_NE(html.find("href=\"timeseries.csv\""), std::string::npos);
  EXPECT_NE(html.find("The linkage at the drawn samples"), std::string::npos);
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
  EXPECT_EQ(svgs(html).size(), 8u);
  EXPECT_NE(html.find("id=\"chart-pareto\""), std::string::npos);
  EXPECT_NE(html.find("id=\"chart-linkage-optimized\""), std::string::npos);
  EXPECT_NE(html.find("The optimised linkage at the drawn samples"), std::string::npos);
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
    if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
    const std::size_t original = html.find("id=\"chart-linkage\""),
                      balanced = html.find("id=\"chart-linkage-balanced\"");
    ASSERT_NE(original, std::string::npos);
    ASSERT_NE(balanced, std::string::npos);
    const std::string a = html.substr(original, html.find("</svg>", original) - original);
    const std::string b = html.substr(balanced, html.find("</svg>", balanced) - balanced);
    EXPECT_EQ(a.find("balance shafts"), std::string::npos) << example;
    EXPECT_NE(b.find("balance shafts"), std::string::npos) << example;
    const bool lanchester = std::string(example) == "engine-lanchester.yaml";
    EXPECT_NE(b.find(lanchester ? "shaft_-1, shaft_2, shaft_-2" : "counter_rocker"),
              std::string::npos)
        << example;
    // only eccentric shafts carry a mass to draw
    EXPECT_EQ(b.find("shaft masses") != std::string::npos, lanchester) << example;
  }
}

TEST_F(ReportTest, BalancedLinkageIsDrawnWithItsCounterweights) {
  const Study study =
      load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  // columns: sample, t, theta1, A1, A2, G1, G2, G3, P1, P2, P3, S
  const auto original = table_after(html, "The linkage at the drawn samples");
  const auto balanced = table_after(html, "The balanced linkage at the drawn samples");
  ASSERT_EQ(original.size(), 4u);
  ASSERT_EQ(balanced.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    ASSERT_EQ(balanced[i].size(), 12u);
    // the same driven motion: the same joints
    EXPECT_EQ(balanced[i][3], original[i][3]);
    EXPECT_EQ(balanced[i][4], original[i][4]);
    // force balanced: S stays where it is (to the 4 digits shown); the original's moves
    EXPECT_EQ(balanced[i][11], balanced[0][11]);
    if (i > 0) {
      EXPECT_NE(original[i][11], original[0][11]);
    }
  }
  // at theta1 = 0 the crank lies along +x: its centre of mass is ahead of A0, the balanced
  // crank's (counterweight merged) behind it
  ASSERT_EQ(original[0][2], "0");
  EXPECT_EQ(original[0][5].rfind("(0.", 0), 0u) << original[0][5];
  EXPECT_EQ(balanced[0][5].rfind("(-", 0), 0u) << balanced[0][5];
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  EXPECT_NE(html.find("id=\"chart-linkage-balanced\""), std::string::npos);
}

// The legend of the linkage chart shows each marker as it is drawn: every legend entry of a
// marker (P1 P2 P3, S, G1 G2 G3) is the plot of that marker, not a stand-in beside it, so its
// key sample and its points share one symbol and one colour; one entry per sample, each in the
// sample's colour.
TEST_F(ReportTest, LinkageLegendShowsTheMarkersAsDrawn) {
  if (find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: charts not checked";
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  ASSERT_TRUE(run_study(study, dir_).ok());
  const std::string html = read(dir_ / "report.html");
  const std::size_t at = html.find("id=\"chart-linkage\"");
  ASSERT_NE(at, std::string::npos);
  const std::string svg = html.substr(at, html.find("</svg>", at) - at);
  const std::regex use("<use xlink:href='#linkage-gpPt([0-9]+)'[^>]*color='([^']*)'");
  std::map<std::string, std::set<std::string>> colours;  // marker kind -> colours of entries
  const std::string group = "<g id=\"linkage-gnuplot_plot_";
  for (std::size_t g = svg.find(group); g != std::string::npos;) {
    const std::size_t next = svg.find(group, g + 1);
    const std::string body =
        svg.substr(g, next == std::string::npos ? std::string::npos : next - g);
    g = next;
    std::string kind;
    for (const char* k : {">  P1 P2 P3<", ">  S<", ">  G1 G2 G3<"})
      if (body.find(k) != std::string::npos) kind = k;
    if (kind.empty()) continue;
    std::set<std::string> symbols, colour;
    std::size_t uses = 0;
    for (auto u = std::sregex_iterator(body.begin(), body.end(), use); u != std::sregex_iterator();
         ++u, ++uses) {
      symbols.insert((*u)[1].str());
      colour.insert((*u)[2].str());
    }
    EXPECT_GE(uses, 2u) << kind << ": the legend's marker and at least one drawn";
    EXPECT_EQ(symbols.size(), 1u) << kind;
    EXPECT_EQ(colour.size(), 1u) << kind;
    if (colour.size() == 1) colours[kind].insert(*colour.begin());
  }
  ASSERT_EQ(colours.size(), 3u);
  for (const auto& [kind, c] : colours) EXPECT_EQ(c.size(), 4u) << kind;  // one per sample
}

TEST_F(ReportTest, ReportIsRebuiltFromTheDataFiles) {
  const Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  run_study(study, dir_);
  const std::string first = read(dir_ / "report.html");
  fs::remove(dir_ / "report.html");
  EXPECT_EQ(write_report(study, dir_), dir_ / "report.html");
  EXPECT_EQ(read(dir_ / "report.html"), first);  // the same files give the same page
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
