// The report's "Speed against accuracy" section, charted from the folder's
// work-precision.csv or driven-convergence.csv (written by write_bench(), studies/bench/).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/number_text.hpp"
#include "studies/bench/work_precision.hpp"
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/run/files.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

namespace {

using report_support::Chart;
using report_support::Csv;
using report_support::esc;
using report_support::fmt;
using report_support::gp_string;

// the column index of `name` in a CSV header
std::size_t column(const Csv& csv, const char* name, const fs::path& file) {
  const auto it = std::find(csv.header.begin(), csv.header.end(), name);
  if (it == csv.header.end()) {
    throw std::runtime_error(file.string() + ": no column " + name);
  }
  return static_cast<std::size_t>(it - csv.header.begin());
}

double number_at(const std::vector<std::string>& row, std::size_t i) {
  if (i >= row.size() || row[i].empty()) return kNaN;
  char* end = nullptr;
  const double v = std::strtod(row[i].c_str(), &end);
  return end == row[i].c_str() ? kNaN : v;
}

const char* const kChartNotice =
    "<p class=\"notice\">The charts need gnuplot, which was not found on this machine; the table "
    "and the data file hold every number.</p>\n";

std::string figure(const Chart& chart, const std::string& svg) {
  return "<h3>" + esc(chart.heading) + "</h3>\n<figure class=\"chart\" id=\"chart-" + chart.id +
         "\">\n" + svg + "\n<figcaption>" + esc(chart.caption) + "</figcaption>\n</figure>\n";
}

// the line colour and point type of item `i` of a list (integrators, methods), the same in
// every chart
std::string line_style(std::size_t i) {
  static const char* const colours[] = {"#9400d3", "#009e73", "#56b4e9", "#e69f00", "#c8b400",
                                        "#0072b2", "#e51e10", "#000000", "#a0522d"};
  return " lc rgb '" + std::string(colours[i % 9]) + "' pt " + std::to_string(i + 1);
}

std::string integrator_style(const std::string& integrator) {
  std::size_t i = 0;
  for (core::Integrator k : core::kIntegrators) {
    if (integrator == core::to_string(k)) break;
    ++i;
  }
  return line_style(i);
}

// a method's: the closed forms in warm and green colours, the general engine in red (truss) and
// blue (truss-dae), so that the two stand apart in the charts that compare them
std::string method_style(const std::string& method) {
  static const std::pair<Method, std::size_t> styles[] = {{Method::kOpenedLoop, 1},
                                                          {Method::kComplexMasses, 2},
                                                          {Method::kMassMatrix, 3},
                                                          {Method::kTrussDae, 5},
                                                          {Method::kTruss, 6}};
  for (const auto& [m, i] : styles) {
    if (method == to_string(m)) return line_style(i);
  }
  return line_style(0);
}

using Row = const std::vector<std::string>*;

// the names in column c of the rows, in file order, each once
std::vector<std::string> distinct(const Csv& csv, std::size_t c) {
  std::vector<std::string> names;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    if (std::find(names.begin(), names.end(), row[c]) == names.end()) names.push_back(row[c]);
  }
  return names;
}

// "the reference of A is B, of C is D" from a method column and its reference column
std::string references_text(const Csv& csv, std::size_t c_method, std::size_t c_reference) {
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    const auto pair = std::pair{row[c_method], row[c_reference]};
    if (std::find(pairs.begin(), pairs.end(), pair) == pairs.end()) pairs.push_back(pair);
  }
  std::string s;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    s += std::string(i == 0 ? "the reference of " : ", of ") + esc(pairs[i].first) + " is " +
         esc(pairs[i].second);
  }
  return s;
}

// a notice naming the runs that stopped before the end of the scene (empty when none)
std::string stopped_notice(
    const Csv& csv, std::size_t c_status, std::size_t c_message,
    const std::function<std::string(const std::vector<std::string>&)>& what) {
  std::size_t stopped = 0, all = 0;
  Row first = nullptr;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    ++all;
    if (row[c_status] == "completed") continue;
    ++stopped;
    if (first == nullptr) first = &row;
  }
  if (stopped == 0) return "";
  return "<p class=\"notice bad\">" + std::to_string(stopped) + " of " + std::to_string(all) +
         " runs stopped before the end of the scene; their rows keep what they computed, with the "
         "status and message (the first: " +
         esc(what(*first)) + ", " + esc((*first)[c_status]) + ": " + esc((*first)[c_message]) +
         ").</p>\n";
}

// The charts of a section: their gnuplot data blocks and the charts drawn from them.
struct Charts {
  std::string datablocks;
  std::vector<Chart> list;
};

// the section's text `h` followed by its charts (or the notice that gnuplot is missing)
std::string with_charts(std::string h, const std::string& gnuplot, const Charts& charts) {
  if (gnuplot.empty()) return h + kChartNotice;
  const std::vector<std::string> svgs =
      report_support::draw(gnuplot, charts.datablocks, charts.list);
  for (std::size_t i = 0; i < charts.list.size(); ++i) h += figure(charts.list[i], svgs[i]);
  return h;
}

// work-precision.csv read back: its columns, and its rows by (method, integrator) in file order.
// Rows point into `csv`, so the object stays where it was made.
struct FreeRuns {
  using Pair = std::pair<std::string, std::string>;  // method, integrator
  Csv csv;
  std::size_t c_f, c_i, c_tol, c_st, c_t, c_e, c_d, c_m, c_steps, c_rf, c_ri, c_rt, c_msg;
  std::vector<Pair> pairs;              // (method, integrator) in file order, each once
  std::map<Pair, std::vector<Row>> of;  // each pair's rows
  std::vector<std::string> methods;     // in file order, each once

  explicit FreeRuns(const fs::path& file)
      : csv(report_support::read_csv(file)),
        c_f(column(csv, "method", file)),
        c_i(column(csv, "integrator", file)),
        c_tol(column(csv, "tolerance", file)),
        c_st(column(csv, "status", file)),
        c_t(column(csv, "cpu_time", file)),
        c_e(column(csv, "final_error", file)),
        c_d(column(csv, "digits", file)),
        c_m(column(csv, "max_error", file)),
        c_steps(column(csv, "steps", file)),
        c_rf(column(csv, "reference_method", file)),
        c_ri(column(csv, "reference_integrator", file)),
        c_rt(column(csv, "reference_tolerance", file)),
        c_msg(column(csv, "message", file)) {
    for (const auto& row : csv.rows) {
      if (row.size() < csv.header.size()) continue;
      const auto key = Pair{row[c_f], row[c_i]};
      if (of.find(key) == of.end()) pairs.push_back(key);
      of[key].push_back(&row);
    }
    methods = distinct(csv, c_f);
  }
  FreeRuns(const FreeRuns&) = delete;
  FreeRuns& operator=(const FreeRuns&) = delete;

  // a chart's point: error at the final time, CPU time [ms]
  std::string point(Row row) const {
    return fmt(number_at(*row, c_e), "%.6g") + "," + fmt(1e3 * number_at(*row, c_t), "%.6g") + "\n";
  }
  // whether a run is charted: completed, with an error and a time to put on log axes
  bool plotted(Row row) const {
    return (*row)[c_st] == "completed" && number_at(*row, c_e) > 0 && number_at(*row, c_t) > 0;
  }
};

// what the free section measures and against what, and which runs stopped early
std::string free_intro(const FreeRuns& r) {
  std::string h =
      "<p>From <a href=\"work-precision.csv\">work-precision.csv</a> (<code>balance-design "
      "bench</code>): every method (as the study file names them: a four-bar's formulations, "
      "and the general planar engine as truss, reduced to the inputs, and truss-dae, the "
      "stabilised DAE in every node coordinate) with every integrator it supports, at each "
      "tolerance (absolute tolerance 1e-2 of it), the median CPU time of one run of the study's "
      "free scene against its error. The error is that of the linkage's positions (its link "
      "angles in rad, its slider positions and moving node coordinates divided by its length "
      "scale, the longest link) against a reference computed by a different method";
  if (!r.csv.rows.empty() && r.csv.rows.front().size() > r.c_rt) {
    const auto& first = r.csv.rows.front();
    h += " (" + esc(first[r.c_ri]) + " at tolerance " + esc(fmt(number_at(first, r.c_rt), "%.0e")) +
         "; " + references_text(r.csv, r.c_f, r.c_rf) + ")";
  }
  h += ": the largest difference at the final time (its -log10 is the number of correct "
       "digits) and the largest over all samples.</p>\n";
  h += stopped_notice(r.csv, r.c_st, r.c_msg, [&](const std::vector<std::string>& row) {
    return row[r.c_f] + " / " + row[r.c_i] + " at " + fmt(number_at(row, r.c_tol), "%.0e");
  });
  return h;
}

// the gnuplot axes of every work-precision chart, up to the plot command
const char* const kWorkPrecisionAxes =
    "set logscale xy\nset format x '1e%L'\nset xrange [*:*] reverse\n"
    "set xlabel 'error at the final time (rad; lengths / length scale)'\n"
    "set ylabel 'CPU time per run [ms]'\nplot ";

// the runs of a method that no other run of it beats in both CPU time and error, by CPU time
std::vector<Row> front_of(const FreeRuns& r, const std::string& method) {
  std::vector<Row> runs;
  for (const auto& [key, rows] : r.of) {
    if (key.first != method) continue;
    for (Row row : rows) {
      if (r.plotted(row)) runs.push_back(row);
    }
  }
  // by CPU time; a run is on the front when it is more accurate than every cheaper one
  std::sort(runs.begin(), runs.end(),
            [&](Row a, Row b) { return number_at(*a, r.c_t) < number_at(*b, r.c_t); });
  std::vector<Row> front;
  for (Row row : runs) {
    if (front.empty() || number_at(*row, r.c_e) < number_at(*front.back(), r.c_e)) {
      front.push_back(row);
    }
  }
  return front;
}

// the methods compared, each by its front (only when there are several)
void add_methods_chart(const FreeRuns& r, Charts& charts) {
  if (r.methods.size() <= 1) return;
  std::string plot;
  for (std::size_t fi = 0; fi < r.methods.size(); ++fi) {
    const std::vector<Row> front = front_of(r, r.methods[fi]);
    if (front.empty()) continue;
    const std::string block = "$wpf_" + std::to_string(fi);
    charts.datablocks += block + " << EOD\n";
    for (Row row : front) charts.datablocks += r.point(row);
    charts.datablocks += "EOD\n";
    plot += std::string(plot.empty() ? "" : ", ") + block + " using 1:2 with linespoints lw 2" +
            method_style(r.methods[fi]) + " title " + gp_string(r.methods[fi]);
  }
  if (plot.empty()) return;
  charts.list.push_back({"work-precision-methods", "Work-precision: the methods compared",
                         "Per method, the cheapest runs for their accuracy: of all its "
                         "integrators and tolerances, the runs that no other run of the method "
                         "beats in both CPU time and error (more accurate to the right). From "
                         "work-precision.csv.",
                         kWorkPrecisionAxes + plot});
}

// one chart per method, a line per integrator
void add_integrator_charts(const FreeRuns& r, Charts& charts) {
  for (const std::string& method : r.methods) {
    std::string plot;
    for (std::size_t mi = 0; mi < r.pairs.size(); ++mi) {
      if (r.pairs[mi].first != method) continue;
      std::string data;
      for (Row row : r.of.at(r.pairs[mi])) {
        if (r.plotted(row)) data += r.point(row);
      }
      if (data.empty()) continue;
      const std::string block = "$wp_" + std::to_string(mi);
      charts.datablocks += block + " << EOD\n" + data + "EOD\n";
      plot += std::string(plot.empty() ? "" : ", ") + block + " using 1:2 with linespoints lw 2" +
              integrator_style(r.pairs[mi].second) + " title " + gp_string(r.pairs[mi].second);
    }
    if (plot.empty()) continue;
    charts.list.push_back({"work-precision-" + method, "Work-precision: " + method,
                           "CPU time of one run against the largest error of the positions at "
                           "the final time, one line per integrator, one point per tolerance "
                           "(more accurate to the right); runs that stopped early are left out. "
                           "From work-precision.csv.",
                           kWorkPrecisionAxes + plot});
  }
}

// a number as a right-aligned table cell, a dash for NaN
std::string number_cell(double v, const char* format) {
  return std::isnan(v) ? std::string("<td class=\"n\">&ndash;</td>")
                       : "<td class=\"n\">" + esc(fmt(v, format)) + "</td>";
}

// the compact table's row of one (method, integrator): its run at tolerance 1e-10 and its
// cheapest run with 10 correct digits
std::string free_table_row(const FreeRuns& r, const FreeRuns::Pair& m) {
  Row at = nullptr;
  Row best = nullptr;
  int failed = 0;
  for (Row row : r.of.at(m)) {
    if ((*row)[r.c_st] != "completed") ++failed;
    if (std::abs(number_at(*row, r.c_tol) / 1e-10 - 1) < 1e-6) at = row;
    if ((*row)[r.c_st] == "completed" && number_at(*row, r.c_d) >= 10 &&
        (best == nullptr || number_at(*row, r.c_t) < number_at(*best, r.c_t))) {
      best = row;
    }
  }
  std::string h = "<tr><td>" + esc(m.first) + "</td><td>" + esc(m.second) + "</td>";
  if (at != nullptr && (*at)[r.c_st] == "completed") {
    h += number_cell(1e3 * number_at(*at, r.c_t), "%.3g") +
         number_cell(number_at(*at, r.c_d), "%.1f") + number_cell(number_at(*at, r.c_m), "%.2g") +
         number_cell(number_at(*at, r.c_steps), "%.0f");
  } else {
    h += "<td colspan=\"4\">" + esc(at != nullptr ? (*at)[r.c_st] : std::string("not run")) +
         "</td>";
  }
  if (best != nullptr) {
    h += number_cell(number_at(*best, r.c_tol), "%.0e") +
         number_cell(1e3 * number_at(*best, r.c_t), "%.3g");
  } else {
    h += "<td colspan=\"2\">none</td>";
  }
  return h + "<td class=\"n\">" + std::to_string(failed) + "</td></tr>";
}

// the compact table: a row per method and integrator
std::string free_table(const FreeRuns& r) {
  std::string h =
      "<table><tr><th>method</th><th>integrator</th><th>at tolerance 1e-10: CPU time "
      "[ms]</th><th>digits</th><th>max error</th><th>steps</th><th>cheapest run with "
      "&ge; 10 digits: tolerance</th><th>CPU time [ms]</th><th>failed runs</th></tr>";
  for (const auto& m : r.pairs) h += free_table_row(r, m);
  return h + "</table>\n";
}

std::string free_section(const fs::path& file, const std::string& gnuplot) {
  const FreeRuns runs(file);
  Charts charts;
  add_methods_chart(runs, charts);
  add_integrator_charts(runs, charts);
  return with_charts(free_intro(runs) + free_table(runs), gnuplot, charts);
}

// driven-convergence.csv read back: its columns, and its rows by method in file order. Rows
// point into `csv`, so the object stays where it was made.
struct DrivenRuns {
  Csv csv;
  std::size_t c_f, c_n, c_st, c_t, c_ef, c_em, c_rf, c_rn, c_msg;
  std::vector<std::string> methods;            // in file order, each once
  std::map<std::string, std::vector<Row>> of;  // each method's rows
  std::string per;  // "per revolution", or "over the duration" of a planar scene given by one

  DrivenRuns(const fs::path& file, bool over_duration)
      : csv(report_support::read_csv(file)),
        c_f(column(csv, "method", file)),
        c_n(column(csv, "samples", file)),
        c_st(column(csv, "status", file)),
        c_t(column(csv, "cpu_time", file)),
        c_ef(column(csv, "Fsh_rms_error", file)),
        c_em(column(csv, "Msh_rms_error", file)),
        c_rf(column(csv, "reference_method", file)),
        c_rn(column(csv, "reference_samples", file)),
        c_msg(column(csv, "message", file)),
        methods(distinct(csv, c_f)),
        per(over_duration ? "over the duration" : "per revolution") {
    for (const auto& row : csv.rows) {
      if (row.size() >= csv.header.size()) of[row[c_f]].push_back(&row);
    }
  }
  DrivenRuns(const DrivenRuns&) = delete;
  DrivenRuns& operator=(const DrivenRuns&) = delete;
};

// what the driven section measures and against what, and which runs stopped early
std::string driven_intro(const DrivenRuns& r, bool over_duration) {
  std::string h =
      "<p>From <a href=\"driven-convergence.csv\">driven-convergence.csv</a> "
      "(<code>balance-design bench</code>): " +
      std::string(over_duration ? "the study's driven scene over its duration"
                                : "one revolution of the study's driven scene") +
      " per method and number of samples " + r.per +
      ", its median CPU time (the run and its metrics), and the relative error of its RMS "
      "shaking force and moment against a run of ";
  if (!r.csv.rows.empty()) {
    h += esc(r.csv.rows.front()[r.c_rn]) + " samples (" + references_text(r.csv, r.c_f, r.c_rf) +
         ")";
  }
  h += over_duration
           ? ". The samples include both ends of the duration, so the RMS is not the "
             "trapezoidal rule of a periodic function and converges like a power of the "
             "samples.</p>\n"
           : ". Evenly spaced samples of a periodic motion make the RMS a trapezoidal rule of a "
             "smooth periodic function, which converges faster than any power of the samples "
             "(spectrally) down to round-off.</p>\n";
  h += stopped_notice(r.csv, r.c_st, r.c_msg, [&](const std::vector<std::string>& row) {
    return row[r.c_f] + " with " + row[r.c_n] + " samples";
  });
  return h;
}

// the two driven charts: the RMS errors and the CPU time against the samples, a line per method
Charts driven_charts(const DrivenRuns& r) {
  Charts charts;
  std::string errors, times;
  for (std::size_t fi = 0; fi < r.methods.size(); ++fi) {
    std::string ef, em, t;
    for (Row row : r.of.at(r.methods[fi])) {
      if ((*row)[r.c_st] != "completed") continue;
      const double n = number_at(*row, r.c_n);
      const double e1 = number_at(*row, r.c_ef), e2 = number_at(*row, r.c_em);
      const double ct = number_at(*row, r.c_t);
      if (e1 > 0) ef += fmt(n, "%.0f") + "," + fmt(e1, "%.6g") + "\n";
      if (e2 > 0) em += fmt(n, "%.0f") + "," + fmt(e2, "%.6g") + "\n";
      if (ct > 0) t += fmt(n, "%.0f") + "," + fmt(1e6 * ct, "%.6g") + "\n";
    }
    const std::string id = std::to_string(fi);
    const std::string& name = r.methods[fi];
    const auto add = [&](const std::string& block, const std::string& data, std::string& plot,
                         const std::string& title, int dash) {
      if (data.empty()) return;
      charts.datablocks += block + " << EOD\n" + data + "EOD\n";
      plot += std::string(plot.empty() ? "" : ", ") + block +
              " using 1:2 with linespoints lw 2 dt " + std::to_string(dash) + method_style(name) +
              " title " + gp_string(title);
    };
    add("$dc_f" + id, ef, errors, name + ": Fsh_rms", 1);
    add("$dc_m" + id, em, errors, name + ": Msh_rms", 2);
    add("$dc_t" + id, t, times, name, 1);
  }
  if (!errors.empty()) {
    charts.list.push_back({"driven-convergence-error", "RMS error against samples " + r.per,
                           "Relative error of the RMS shaking force and moment against the "
                           "reference, per method; errors of exactly 0 are left out. From "
                           "driven-convergence.csv.",
                           "set logscale xy\nset format y '1e%L'\nset xlabel 'samples " + r.per +
                               "'\nset ylabel 'relative error of the RMS'\nplot " + errors});
  }
  if (!times.empty()) {
    charts.list.push_back({"driven-convergence-time", "CPU time against samples " + r.per,
                           "Median CPU time of one run with its metrics, per method. From "
                           "driven-convergence.csv.",
                           "set logscale xy\nset xlabel 'samples " + r.per +
                               "'\nset ylabel 'CPU time per run [us]'\nplot " + times});
  }
  return charts;
}

// the driven table: per method, the fewest samples with both errors below 1e-12, and the run
// at 360 samples
std::string driven_table(const DrivenRuns& r) {
  std::string h =
      "<table><tr><th>method</th><th>samples for both errors &lt; 1e-12</th><th>CPU time "
      "[&micro;s]</th><th>at 360 samples: CPU time [&micro;s]</th><th>Fsh_rms error</th>"
      "<th>Msh_rms error</th></tr>";
  for (const std::string& f : r.methods) {
    Row enough = nullptr;
    Row at = nullptr;
    for (Row row : r.of.at(f)) {
      const double e1 = number_at(*row, r.c_ef), e2 = number_at(*row, r.c_em);
      const bool small = (std::isnan(e1) || e1 < 1e-12) && (std::isnan(e2) || e2 < 1e-12) &&
                         !(std::isnan(e1) && std::isnan(e2));
      if ((*row)[r.c_st] == "completed" && small && enough == nullptr) enough = row;
      if ((*row)[r.c_n] == "360") at = row;
    }
    const auto cell = [](const std::string& v) { return report_support::num_cell(v); };
    h += "<tr><td>" + esc(f) + "</td>";
    h += enough != nullptr ? cell((*enough)[r.c_n]) + "<td class=\"n\">" +
                                 esc(fmt(1e6 * number_at(*enough, r.c_t), "%.3g")) + "</td>"
                           : std::string("<td colspan=\"2\">none</td>");
    h += at != nullptr ? "<td class=\"n\">" + esc(fmt(1e6 * number_at(*at, r.c_t), "%.3g")) +
                             "</td>" + cell((*at)[r.c_ef]) + cell((*at)[r.c_em])
                       : std::string("<td colspan=\"3\">not measured</td>");
    h += "</tr>";
  }
  return h + "</table>\n";
}

std::string driven_section(const fs::path& file, const std::string& gnuplot, bool over_duration) {
  const DrivenRuns runs(file, over_duration);
  return with_charts(driven_intro(runs, over_duration) + driven_table(runs), gnuplot,
                     driven_charts(runs));
}

}  // namespace

std::string work_precision_section(const Study& study, const fs::path& dir,
                                   const std::string& gnuplot) {
  std::string h;
  std::error_code ec;
  if (fs::is_regular_file(dir / "work-precision.csv", ec)) {
    h += free_section(dir / "work-precision.csv", gnuplot);
  }
  if (fs::is_regular_file(dir / "driven-convergence.csv", ec)) {
    const auto* planar = std::get_if<core::planar::DrivenScene>(&study.scene);
    h += driven_section(dir / "driven-convergence.csv", gnuplot,
                        planar != nullptr && planar->duration > 0);
  }
  return h.empty() ? h : "<h2 id=\"speed-against-accuracy\">Speed against accuracy</h2>\n" + h;
}

}  // namespace bd::studies
