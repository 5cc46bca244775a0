// The sweep's report page, built from sweep.csv and sweep.json alone: its tables hold the files'
// numbers as written, each design of sweep gets its charts (metric against parameter, heat maps,
// coloured scatter plots, a grid of small charts), an interrupted sweep still gets a page, and
// a folder without the data files is a clear error.
//
// The sweep folders here are written by the test itself, as the spec of sweep.csv and
// sweep.json (docs/study-format.md "sweep") lays them out, from real simulations of the example
// linkage at each point, so the page is tested on its own, apart from run_sweep().
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "balance/synthesis.hpp"
#include "core/input_error.hpp"
#include "core/fourbar/metrics.hpp"
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/sweep/sweep.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

using bd::testing::read;

using bd::testing::count;

std::string g17(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// a sweep folder as run_sweep() writes it (the spec's formats), from simulations at each point

constexpr const char* kMetricNames[] = {
    "Fsh_rms",       "Fsh_max",       "Msh_rms",       "Msh_max",       "tau_rms",  "tau_max",
    "RA0_rms",       "RA0_max",       "RA3_rms",       "RA3_max",       "Fsh_total_rms",
    "Fsh_total_max", "Msh_total_rms", "Msh_total_max", "FA1_max",       "FA2_max"};

std::vector<double> metric_values(const core::Metrics& m) {
  return {m.Fsh_rms,       m.Fsh_max,       m.Msh_rms,       m.Msh_max,       m.tau_rms,
          m.tau_max,       m.RA0_rms,       m.RA0_max,       m.RA3_rms,       m.RA3_max,
          m.Fsh_total_rms, m.Fsh_total_max, m.Msh_total_rms, m.Msh_total_max, m.FA1_max,
          m.FA2_max};
}

std::string csv_quoted(const std::string& text) {
  std::string q = "\"";
  for (const char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

struct Param {
  std::string path;
  bool log_scale = false;
  double from{}, to{};
  std::vector<double> values;  // grid only
};

class SweepFolder {
 public:
  SweepFolder(Study study, std::vector<Param> params, std::string design)
      : study_(std::move(study)), params_(std::move(params)), design_(std::move(design)) {}

  std::vector<std::string> header() const {
    std::vector<std::string> h{"point"};
    for (const Param& p : params_) h.push_back(p.path);
    for (const char* m : kMetricNames) h.push_back(m);
    if (study_.balance) {
      for (const char* m : kMetricNames) h.push_back(std::string("balanced_") + m);
      h.push_back("added_mass");
      h.push_back("added_inertia");
    }
    h.push_back("status");
    h.push_back("message");
    return h;
  }

  // the row of point i at `values`: the study simulated there (and its balanced design)
  std::string row(std::size_t i, const std::vector<double>& values) const {
    core::FourBar model = study_.fourbar();
    Scene scene = study_.scene;
    for (std::size_t j = 0; j < params_.size(); ++j) {
      const std::string& p = params_[j].path;
      const double v = values[j];
      if (p == "linkage.crank.mass")
        model.crank.mass = v;
      else if (p == "linkage.coupler.mass")
        model.coupler.mass = v;
      else if (p == "linkage.rocker.mass")
        model.rocker.mass = v;
      else if (p == "linkage.coupler.s") {
        const core::Link& c = model.coupler;
        model.coupler = core::link_from_polar(c.length, c.mass, v, c.sigma(), c.inertia);
      } else if (p == "scene.omega1")
        if (auto* f = std::get_if<core::FreeScene>(&scene)) {
          f->omega1 = v;
        } else {
          std::get<core::DrivenScene>(scene).omega1 = v;
        }
      else
        ADD_FAILURE() << "the test cannot set " << p;
    }
    std::string r = std::to_string(i);
    for (const double v : values) r += "," + g17(v);
    const std::size_t metrics = header().size() - 3 - params_.size();
    try {
      model = core::make_fourbar(model);
    } catch (const InputError& e) {
      for (std::size_t k = 0; k < metrics; ++k) r += ",";
      return r + ",bad-input," + csv_quoted(e.what()) + "\n";
    }
    const auto simulate = [&](const core::FourBar& m) {
      if (const auto* f = std::get_if<core::FreeScene>(&scene)) {
        core::SimulateOptions o;
        o.tolerance = 1e-8;
        return core::simulate_free(m, *f, o);
      }
      return core::simulate_driven(m, std::get<core::DrivenScene>(scene));
    };
    const core::Trajectory t = simulate(model);
    for (const double v : metric_values(core::metrics(t))) r += "," + g17(v);
    std::string status = t.ok() ? "ok" : "stopped-early";
    std::string message = t.ok() ? "" : t.message;
    if (study_.balance) {
      const balance::BalancedDesign b = balance::balance_design(model, study_.balance->request);
      const core::Trajectory tb = simulate(b.model);
      for (const double v : metric_values(core::metrics(tb))) r += "," + g17(v);
      r += "," + g17(b.added_mass) + "," + g17(b.added_inertia);
      if (!tb.ok() && t.ok()) {
        status = "stopped-early";
        message = tb.message;
      }
    }
    return r + "," + status + "," + (message.empty() ? "" : csv_quoted(message)) + "\n";
  }

  // writes sweep.csv (the first `rows` points) and sweep.json
  void write(const fs::path& dir, const std::vector<std::vector<double>>& points, std::size_t rows,
             const std::string& status) const {
    fs::create_directories(dir);
    std::string csv;
    for (const std::string& h : header()) csv += (csv.empty() ? "" : ",") + h;
    csv += "\n";
    int failed = 0;
    for (std::size_t i = 0; i < rows; ++i) {
      const std::string r = row(i, points[i]);
      failed += r.find(",ok,") == std::string::npos;
      csv += r;
    }
    std::ofstream(dir / "sweep.csv", std::ios::binary) << csv;
    std::string json = "{\n  \"study\": \"" + study_.name + "\",\n  \"source\": \"" +
                       study_.source + "\",\n  \"fingerprint\": \"0123456789abcdef\",\n" +
                       "  \"design\": \"" + design_ +
                       "\",\n  \"seed\": 1,\n  \"points\": " + std::to_string(points.size()) +
                       ",\n  \"threads\": 2,\n  \"parameters\": [";
    for (std::size_t j = 0; j < params_.size(); ++j) {
      const Param& p = params_[j];
      json += std::string(j ? "," : "") + "\n    {\"path\": \"" + p.path + "\", \"scale\": \"" +
              (p.log_scale ? "log" : "linear") + "\", \"from\": " + g17(p.from) +
              ", \"to\": " + g17(p.to);
      if (!p.values.empty()) {
        json += ", \"values\": [";
        for (std::size_t k = 0; k < p.values.size(); ++k)
          json += (k ? ", " : "") + g17(p.values[k]);
        json += "]";
      }
      json += "}";
    }
    json += "\n  ],\n  \"status\": \"" + status + "\",\n  \"done\": " + std::to_string(rows) +
            ", \"resumed\": 0, \"failed\": " + std::to_string(failed) +
            ",\n  \"elapsed_s\": 0.25\n}\n";
    std::ofstream(dir / "sweep.json", std::ios::binary) << json;
  }

  const Study& study() const { return study_; }

 private:
  Study study_;
  std::vector<Param> params_;
  std::string design_;
};

// the grid's points: the Cartesian product, the first parameter varying slowest
std::vector<std::vector<double>> grid(const std::vector<Param>& params) {
  std::vector<std::vector<double>> points{{}};
  for (const Param& p : params) {
    std::vector<std::vector<double>> next;
    for (const auto& head : points) {
      for (const double v : p.values) {
        next.push_back(head);
        next.back().push_back(v);
      }
    }
    points = next;
  }
  return points;
}

// `n` Latin-hypercube points in the parameters' box: one point per stratum of each parameter,
// the strata paired by a fixed shuffle (the page does not care how they were drawn)
std::vector<std::vector<double>> lhs(const std::vector<Param>& params, int n) {
  std::mt19937 rng(7);
  std::vector<std::vector<double>> points(static_cast<std::size_t>(n));
  for (const Param& p : params) {
    std::vector<int> strata(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) strata[static_cast<std::size_t>(i)] = i;
    for (int i = n - 1; i > 0; --i) {
      std::swap(strata[static_cast<std::size_t>(i)],
                strata[rng() % static_cast<std::size_t>(i + 1)]);
    }
    for (int i = 0; i < n; ++i) {
      const double u =
          (strata[static_cast<std::size_t>(i)] + static_cast<double>(rng() % 1000) / 1000.0) / n;
      points[static_cast<std::size_t>(i)].push_back(
          p.log_scale ? p.from * std::pow(p.to / p.from, u) : p.from + u * (p.to - p.from));
    }
  }
  return points;
}

std::vector<double> geometric(double from, double to, int count) {
  std::vector<double> v;
  for (int i = 0; i < count; ++i) v.push_back(from * std::pow(to / from, double(i) / (count - 1)));
  return v;
}

// ---------------------------------------------------------------------------------------------
// what every page must satisfy

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

// the page's text between the heading `h2` and the next <h2>
std::string section(const std::string& html, const std::string& h2) {
  const std::size_t at = html.find("<h2>" + h2 + "</h2>");
  if (at == std::string::npos) return {};
  return html.substr(at, html.find("<h2>", at + 4) - at);
}

// sweep.csv's rows as fields (no quoted commas in the columns the tests read)
std::vector<std::vector<std::string>> csv_rows(const fs::path& file,
                                               std::vector<std::string>* header) {
  std::istringstream in(read(file));
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);
  for (const std::string& f : csv_fields(line)) header->push_back(f);
  while (std::getline(in, line)) rows.push_back(csv_fields(line));
  return rows;
}

// the page's checks shared by every sweep: headings, one SVG per chart and each drawn, no NaN,
// and the least value of each main metric exactly as sweep.csv writes it
void expect_sound_page(const std::string& html, const fs::path& dir, std::size_t charts,
                       const std::vector<std::string>& metrics) {
  for (const char* h :
       {"Status", "Design", "Best points", "Failed points", "Charts", "Study", "Data files"}) {
    EXPECT_NE(html.find(std::string("<h2>") + h + "</h2>"), std::string::npos) << h;
  }
  EXPECT_EQ(html.find("<script"), std::string::npos);
  const std::regex nan("[^A-Za-z]nan[^A-Za-z]", std::regex::icase);
  EXPECT_FALSE(std::regex_search(html, nan));
  EXPECT_EQ(count(html, "<figure class=\"chart\""), charts);
  const std::vector<std::string> drawn = svgs(html);
  EXPECT_EQ(drawn.size(), charts);
  for (const std::string& svg : drawn) EXPECT_GT(count(svg, "<path"), 3u);

  std::vector<std::string> header;
  const auto rows = csv_rows(dir / "sweep.csv", &header);
  const std::string best = section(html, "Best points");
  ASSERT_FALSE(best.empty());
  for (const std::string& name : metrics) {
    std::size_t c = 0;
    while (c < header.size() && header[c] != name) ++c;
    ASSERT_LT(c, header.size()) << name;
    const std::size_t status = header.size() - 2;
    // the least among the rows whose status is ok, as written
    std::string least;
    double v = std::numeric_limits<double>::infinity();
    for (const auto& r : rows) {
      // a line cut short (a kill while it was written) is no row: the page leaves it out
      if (r.size() != header.size() || r[status] != "ok") continue;
      const double x = std::stod(r[c]);
      if (x < v) {
        v = x;
        least = r[c];
      }
    }
    std::smatch m;
    const std::regex cell("<tr><th>" + name + "</th><td class=\"n\" title=\"([^\"]*)\">");
    ASSERT_TRUE(std::regex_search(best, m, cell)) << name;
    EXPECT_EQ(m[1].str(), least) << name;
  }
}

// The distinct x (or y) coordinates, in pixels, of the corners of every filled rectangle in the
// groups "<chart>-gnuplot_plot_<k>a" (the first panel's plots) of a chart's SVG, in order.
std::vector<double> cell_edges_px(const std::string& svg, const std::string& chart, bool y) {
  std::vector<double> edges;
  const std::regex polygon("<polygon fill = '[^']*' points = '([^']*)'");
  const std::regex corner("([-0-9.]+),([-0-9.]+)");
  for (const char* k : {"1", "2"}) {
    const std::string group = "id=\"" + chart + "-gnuplot_plot_" + k + "a\"";
    const std::size_t at = svg.find(group);
    if (at == std::string::npos) continue;
    const std::string body = svg.substr(at, svg.find("</g>\n\t</g>", at) - at);
    for (auto p = std::sregex_iterator(body.begin(), body.end(), polygon);
         p != std::sregex_iterator(); ++p) {
      const std::string points = (*p)[1].str();
      for (auto c = std::sregex_iterator(points.begin(), points.end(), corner);
           c != std::sregex_iterator(); ++c) {
        edges.push_back(std::stod((*c)[y ? 2 : 1].str()));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  // gnuplot writes 0.01 px and lets neighbouring cells overlap by one such step
  std::vector<double> distinct;
  for (const double e : edges)
    if (distinct.empty() || e - distinct.back() > 0.05) distinct.push_back(e);
  return distinct;
}

// `edges` scaled to [0, 1] over their span
std::vector<double> normalised(std::vector<double> edges) {
  const double a = edges.front(), b = edges.back();
  for (double& e : edges) e = (e - a) / (b - a);
  return edges;
}

class SweepReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_sweep_report_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    gnuplot_ = find_gnuplot();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // the driven paper four-bar, force balanced, 90 samples a revolution
  static Study driven_balanced() {
    Study s =
        load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
    std::get<core::DrivenScene>(s.scene).samples = 90;
    return s;
  }

  std::size_t charts_or_none(std::size_t n) const { return gnuplot_.empty() ? 0 : n; }

  fs::path dir_;
  std::string gnuplot_;
};

const std::vector<std::string> kBalancedMain = {
    "Fsh_rms",          "Msh_rms",          "tau_rms",          "RA0_rms",
    "RA3_rms",          "balanced_Fsh_rms", "balanced_Msh_rms", "balanced_tau_rms",
    "balanced_RA0_rms", "balanced_RA3_rms", "added_mass"};

TEST_F(SweepReportTest, OneParameterOnALogScale) {
  const std::vector<Param> params{{"linkage.coupler.mass", true, 0.5, 8, geometric(0.5, 8, 7)}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 7, "complete");
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  // one chart per main metric: Fsh, Msh, tau (a driven scene), RA0, RA3; and the added mass
  expect_sound_page(html, dir_, charts_or_none(6), kBalancedMain);
  EXPECT_NE(html.find("Complete: 7 of 7 points done."), std::string::npos);
  EXPECT_NE(html.find("None: every point ran with status ok."), std::string::npos);
  EXPECT_NE(html.find("<td>log</td>"), std::string::npos);
  if (!gnuplot_.empty()) {
    EXPECT_NE(html.find("id=\"chart-sweep-tau\""), std::string::npos);
    EXPECT_NE(html.find("balanced RMS"), std::string::npos);  // the overlay's legend
  }
  // the linkage's inputs come from the study
  EXPECT_NE(html.find("<h3>Linkage</h3>"), std::string::npos);
  EXPECT_NE(html.find("force full, moment none"), std::string::npos);
}

TEST_F(SweepReportTest, TwoParametersOnANonUniformGridWithFailedPoints) {
  // a crank mass below zero makes the point's study invalid: four bad-input rows
  const std::vector<Param> params{{"linkage.crank.mass", false, -0.5, 4, {-0.5, 1.0, 2.1, 4.0}},
                                  {"linkage.coupler.s", false, 1.0, 1.7, {1.0, 1.2, 1.45, 1.7}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 16, "complete");
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  expect_sound_page(html, dir_, charts_or_none(6), kBalancedMain);
  const std::string failed = section(html, "Failed points");
  EXPECT_EQ(count(failed, ">bad-input<"), 4u);
  EXPECT_NE(failed.find("crank.mass must be &gt; 0 kg, got -0.5"), std::string::npos) << failed;
  if (gnuplot_.empty()) return;
  EXPECT_NE(html.find("one rectangle per point"), std::string::npos);
  // the cells sit at their true places on the non-uniform grid: each reaches halfway to its
  // neighbours, the end cells as far outside their value as inside, failed ones (grey) included.
  // crank.mass -0.5, 1, 2.1, 4: edges -1.25, 0.25, 1.55, 3.05, 4.95;
  // coupler.s 1, 1.2, 1.45, 1.7: edges 0.9, 1.1, 1.325, 1.575, 1.825.
  // In pixels the edges come rounded to 0.01 px on a panel ~300 px wide: 1e-3 of the span.
  const std::size_t at = html.find("id=\"chart-sweep-Fsh\"");
  ASSERT_NE(at, std::string::npos);
  const std::string svg = html.substr(at, html.find("</svg>", at) - at);
  const std::vector<double> x = normalised(cell_edges_px(svg, "sweep-Fsh", false));
  const std::vector<double> y = normalised(cell_edges_px(svg, "sweep-Fsh", true));
  const std::vector<double> want_x{0, 1.5 / 6.2, 2.8 / 6.2, 4.3 / 6.2, 1};
  const std::vector<double> want_y{0, 0.2 / 0.925, 0.425 / 0.925, 0.675 / 0.925, 1};
  ASSERT_EQ(x.size(), want_x.size());
  ASSERT_EQ(y.size(), want_y.size());
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i], want_x[i], 1e-3) << i;
  // y grows downwards in SVG
  for (std::size_t i = 0; i < y.size(); ++i) EXPECT_NEAR(1 - y[i], want_y[4 - i], 1e-3) << i;
}

TEST_F(SweepReportTest, TwoParametersLatinHypercubeInFreeMotion) {
  Study study = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar.yaml");
  study.scene = core::FreeScene{1.0, 0.0, 0.5, 51};
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {}},
                                  {"scene.omega1", false, 0, 2, {}}};
  const SweepFolder f(study, params, "lhs");
  f.write(dir_, lhs(params, 12), 12, "complete");
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  // free motion: no drive torque chart; no second design
  expect_sound_page(html, dir_, charts_or_none(4), {"Fsh_rms", "Msh_rms", "RA0_rms", "RA3_rms"});
  EXPECT_NE(html.find("Latin hypercube draws"), std::string::npos);
  EXPECT_EQ(html.find("balanced"), std::string::npos);
  if (!gnuplot_.empty()) {
    EXPECT_NE(html.find("Latin-hypercube design, by colour"), std::string::npos);
  }
}

TEST_F(SweepReportTest, ThreeParametersAtRandom) {
  const std::vector<Param> params{{"linkage.crank.mass", false, 1, 3, {}},
                                  {"linkage.coupler.mass", true, 1, 9, {}},
                                  {"linkage.rocker.mass", false, 1, 3, {}}};
  const SweepFolder f(driven_balanced(), params, "random");
  f.write(dir_, lhs(params, 10), 10, "complete");
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  expect_sound_page(html, dir_, charts_or_none(6), kBalancedMain);
  EXPECT_NE(html.find("uniform random draws (uniform in log)"), std::string::npos);
  if (!gnuplot_.empty()) {
    EXPECT_NE(html.find("against each parameter in turn, the original design filled, the "
                        "balanced one open"),
              std::string::npos);
  }
}

TEST_F(SweepReportTest, InterruptedSweepShowsWhatIsThereAndHowToResume) {
  const std::vector<Param> params{{"linkage.crank.mass", false, 1.0, 4, {1.0, 2.1, 4.0}},
                                  {"linkage.coupler.s", false, 1.0, 1.7, {1.0, 1.2, 1.45, 1.7}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  const auto points = grid(params);
  f.write(dir_, points, 5, "interrupted");
  // a kill while the sixth row was written: a line cut short
  const std::string sixth = f.row(5, points[5]);
  std::ofstream(dir_ / "sweep.csv", std::ios::app | std::ios::binary)
      << sixth.substr(0, sixth.size() / 2);
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  expect_sound_page(html, dir_, charts_or_none(6), kBalancedMain);
  EXPECT_NE(html.find("Interrupted after 5 of 12 points."), std::string::npos);
  EXPECT_NE(html.find("--resume"), std::string::npos);
  EXPECT_NE(html.find("The last line of sweep.csv was cut short"), std::string::npos);
  // the points table lists the five rows, not the cut one
  EXPECT_EQ(count(section(html, "Points"), "<tr>"), 6u);  // header + 5
}

TEST_F(SweepReportTest, NoPointDoneYetStillGivesAPage) {
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 3, 5}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 0, "running");
  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  EXPECT_NE(html.find("0 of 3 points are in sweep.csv"), std::string::npos);
  EXPECT_NE(html.find("no point has finished with status ok yet"), std::string::npos);
  EXPECT_EQ(html.find("<svg"), std::string::npos);
}

TEST_F(SweepReportTest, OptimizeSweepKeepsTheOriginalOfAPointWithoutOptimum) {
  // a balance sweep's folder relabelled as an optimize sweep: the least original Fsh_rms lies at
  // the first point, which is made a point without an optimum (its optimum's columns empty)
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 2, 3, 4, 5}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 5, "complete");
  std::string csv = read(dir_ / "sweep.csv");
  for (std::size_t at = csv.find("balanced_"); at != std::string::npos;
       at = csv.find("balanced_", at))
    csv.replace(at, 9, "optimized_");
  std::vector<std::string> lines;
  std::istringstream in(csv);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::vector<std::string> fields = csv_fields(lines[1]);
  const std::size_t n = fields.size();
  for (std::size_t c = 12; c < n - 2; ++c) fields[c].clear();  // optimized_*, added_*
  fields[n - 2] = "no-optimum";
  fields[n - 1] = "\"no feasible design found\"";
  std::string row;
  for (const std::string& x : fields) row += (row.empty() ? "" : ",") + x;
  lines[1] = row;
  csv.clear();
  for (const std::string& l : lines) csv += l + "\n";
  std::ofstream(dir_ / "sweep.csv", std::ios::binary) << csv;

  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  EXPECT_EQ(count(html, "<figure class=\"chart\""), charts_or_none(6));
  EXPECT_NE(html.find("optimised"), std::string::npos);
  // Fsh_rms grows with the coupler's mass here, so its least value is the no-optimum point's
  std::vector<std::string> header;
  const auto rows = csv_rows(dir_ / "sweep.csv", &header);
  ASSERT_LT(std::stod(rows[0][2]), std::stod(rows[1][2]));
  std::smatch m;
  const std::string best = section(html, "Best points");
  ASSERT_TRUE(std::regex_search(
      best, m, std::regex("<tr><th>Fsh_rms</th><td class=\"n\" title=\"([^\"]*)\">")));
  EXPECT_EQ(m[1].str(), rows[0][2]);
  // the second design here is force-balanced: its Fsh is round-off, ranked nowhere
  EXPECT_TRUE(std::regex_search(
      best, std::regex("<tr><th>optimized_Fsh_rms</th><td class=\"n\" title=\"[^\"]*\">0"
                       "</td><td>N</td><td colspan=\"2\">zero to round-off")))
      << best;
  ASSERT_TRUE(std::regex_search(
      best, m,
      std::regex("<tr><th>optimized_Msh_rms</th><td class=\"n\" title=\"[^\"]*\">[^<]*</td>"
                 "<td>N m</td><td class=\"n\" title=\"([0-9]+)\">")));
  EXPECT_NE(m[1].str(), "0");  // not at the point without an optimum
  EXPECT_EQ(count(section(html, "Failed points"), ">no-optimum<"), 1u);
}

TEST_F(SweepReportTest, WithoutGnuplotThePageSaysSoAndKeepsTheTables) {
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 3, 5}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 3, "complete");
  const std::string html = sweep_report_html(f.study(), dir_, "");
  EXPECT_NE(html.find("The charts need gnuplot"), std::string::npos);
  EXPECT_EQ(html.find("<svg"), std::string::npos);
  expect_sound_page(html, dir_, 0, kBalancedMain);
}

TEST_F(SweepReportTest, MissingDataFilesAreClearErrors) {
  const Study study = driven_balanced();
  fs::create_directories(dir_);
  try {
    sweep_report_html(study, dir_, "");
    ADD_FAILURE() << "no error without sweep.json";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sweep.json not found"), std::string::npos) << e.what();
  }
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 3, 5}}};
  SweepFolder(study, params, "grid").write(dir_, grid(params), 3, "complete");
  fs::remove(dir_ / "sweep.csv");
  try {
    sweep_report_html(study, dir_, "");
    ADD_FAILURE() << "no error without sweep.csv";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sweep.csv not found"), std::string::npos) << e.what();
  }
  // a header that does not match sweep.json's parameters
  std::ofstream(dir_ / "sweep.csv") << "point,linkage.coupler.lenght,Fsh_rms,status,message\n";
  try {
    sweep_report_html(study, dir_, "");
    ADD_FAILURE() << "no error for a foreign header";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not match"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "report.html"));
}

// the folders above follow the format run_sweep() writes
TEST_F(SweepReportTest, HandWrittenColumnsAreTheRunnersColumns) {
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 3, 5}}};
  Study balanced = driven_balanced();
  Study plain = load_study(BD_SOURCE_DIR "/studies/examples/paper-fourbar-driven.yaml");
  for (Study* study : {&balanced, &plain}) {
    SweepRequest request;
    request.parameters.push_back({"linkage.coupler.mass", {1, 3, 5}, 1, 5, false, 1, 1});
    study->sweep = request;
    EXPECT_EQ(SweepFolder(*study, params, "grid").header(), sweep_columns(*study)) << study->name;
  }
}

// the page of a real run: the sweep example, made small, run by run_sweep(), which writes the
// page itself; the same files give the same page
TEST_F(SweepReportTest, PageOfARealSweepRun) {
  std::string yaml = read(BD_SOURCE_DIR "/studies/examples/paper-fourbar-sweep.yaml");
  // 5 x 4 points of 90 samples instead of 21 x 21 of 360
  for (const char* count : {"count: 5 ", "count: 4 "}) {
    const std::size_t at = yaml.find("count: 21");
    ASSERT_NE(at, std::string::npos);
    yaml.replace(at, 9, count);
  }
  ASSERT_NE(yaml.find("samples: 360"), std::string::npos);
  yaml.replace(yaml.find("samples: 360"), 12, "samples: 90 ");
  fs::create_directories(dir_);
  const fs::path file = dir_ / "sweep.yaml";
  std::ofstream(file) << yaml;
  const Study study = load_study(file.string());
  SweepOptions options;
  options.threads = 2;
  const fs::path out = dir_ / "out";
  const SweepResult r = run_sweep(study, out, options);
  ASSERT_TRUE(r.complete());
  ASSERT_EQ(r.points, 20);
  const std::string html = read(out / "report.html");
  expect_sound_page(html, out, charts_or_none(6), kBalancedMain);
  EXPECT_NE(html.find("Complete: 20 of 20 points done."), std::string::npos);
  EXPECT_EQ(sweep_report_html(study, out, find_gnuplot()), html);
}

TEST_F(SweepReportTest, WrittenPageIsTheBuiltPage) {
  const std::vector<Param> params{{"linkage.coupler.mass", false, 1, 5, {1, 3, 5}}};
  const SweepFolder f(driven_balanced(), params, "grid");
  f.write(dir_, grid(params), 3, "complete");
  EXPECT_EQ(write_sweep_report(f.study(), dir_), dir_ / "report.html");
  EXPECT_EQ(read(dir_ / "report.html"), sweep_report_html(f.study(), dir_, find_gnuplot()));
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
}

}  // namespace
}  // namespace bd::studies

namespace bd::studies {
namespace {

// A 150 x 150 grid (22,500 points, written by hand: the page reads only the files): the charts
// draw a regular sample of at most 40 values a side and say so, while the best points and the
// counts are over every row (the least value sits off the sample), the page stays small, and a
// force-balanced design's shaking force (round-off, 1e-14 N) is ranked nowhere.
TEST_F(SweepReportTest, LargeGridIsSampledForTheChartsAndRankedWhole) {
  std::vector<double> xs, ys;
  for (int k = 0; k < 150; ++k) {
    xs.push_back(1.0 + 0.02 * k);
    ys.push_back(0.5 + 0.01 * k);
  }
  const std::vector<Param> params{{"linkage.coupler.mass", false, xs.front(), xs.back(), xs},
                                  {"linkage.coupler.s", false, ys.front(), ys.back(), ys}};
  const SweepFolder f(driven_balanced(), params, "grid");
  const std::vector<std::vector<double>> points = grid(params);
  f.write(dir_, points, 1, "complete");
  const std::vector<std::string> header = f.header();
  std::string csv;
  for (const std::string& h : header) csv += (csv.empty() ? "" : ",") + h;
  csv += "\n";
  const std::size_t metrics = header.size() - 5;  // after point and the two values, before status
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i][0], y = points[i][1];
    std::string row = std::to_string(i) + "," + g17(x) + "," + g17(y);
    for (std::size_t c = 0; c < metrics; ++c) {
      const bool balanced_force = header[3 + c].rfind("balanced_Fsh", 0) == 0;
      // a bowl with its least value at point 151 (x index 1, y index 1: off the sample, which
      // keeps indices 0, 4, 8, 11, ..., 149); the balanced force 1e-14 N of round-off
      const double v = balanced_force ? 1e-14 * (1 + std::sin(double(i)))
                                      : 10 + (x - xs[1]) * (x - xs[1]) + (y - ys[1]) * (y - ys[1]);
      row += "," + g17(v);
    }
    csv += row + ",ok,\n";
  }
  std::ofstream(dir_ / "sweep.csv", std::ios::binary) << csv;

  const std::string html = sweep_report_html(f.study(), dir_, gnuplot_);
  EXPECT_LT(html.size(), 5u << 20) << "the page grows with the points";
  EXPECT_NE(html.find("22500 of 22500 points done"), std::string::npos);
  const std::string best = section(html, "Best points");
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(best, m,
                        std::regex("<tr><th>Fsh_rms</th><td class=\"n\" title=\"[^\"]*\">[^<]*</td>"
                                   "<td>N</td><td class=\"n\" title=\"([0-9]+)\">")));
  EXPECT_EQ(m[1].str(), "151");
  EXPECT_NE(best.find("<tr><th>balanced_Fsh_rms</th>"), std::string::npos);
  EXPECT_TRUE(
      std::regex_search(best, std::regex("<tr><th>balanced_Fsh_rms</th><td class=\"n\" "
                                         "title=\"[^\"]*\">0</td><td>N</td><td colspan=\"3\">"
                                         "zero to round-off")))
      << best;
  if (gnuplot_.empty()) return;
  // 40 values a side, the last ones included (every 4th value from the first stopped at the
  // 148th of 150: 38 x 38, the grid's far edges left out)
  EXPECT_NE(html.find("Drawn: 40 of the 150 values of linkage.coupler.mass and 40 of the 150 "
                      "values of linkage.coupler.s, each from its first value to its last (40 x 40 "
                      "of the grid's points) of sweep.csv's 22500 rows"),
            std::string::npos);
  EXPECT_NE(html.find("coupler mass m2 [kg]"), std::string::npos);  // axes in an engineer's words
  EXPECT_NE(html.find("every value zero to round-off"), std::string::npos);
}

}  // namespace
}  // namespace bd::studies

namespace bd::studies {
namespace {

// A list of numbers in summary.json (an optimiser's added instants, a sweep's values) shows on
// the page one by one up to twelve; a longer one by its count and range, the values left to
// summary.json.
TEST(ReportCells, ALongListOfNumbersShowsItsCountAndRange) {
  using report_support::Json;
  using report_support::json_cell;
  Json many = Json::array();
  for (int k = 20; k >= 1; --k) many.push_back(0.5 * k);  // not in order: the range is found
  EXPECT_EQ(json_cell(many), "<td>20 values from 0.5 to 10 (each in summary.json)</td>");
  Json few = Json::array({0.25, 2.0, 1.5});
  EXPECT_EQ(json_cell(few), "<td>0.25, 2, 1.5</td>");
}

}  // namespace
}  // namespace bd::studies
