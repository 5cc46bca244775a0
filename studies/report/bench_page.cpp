// The report's "Speed against accuracy" section, charted from the folder's
// work-precision.csv or driven-convergence.csv (written by write_bench(), studies/bench/).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
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

// the line colour and point type of an integrator, the same in every chart
std::string line_style(const std::string& integrator) {
  static const char* const colours[] = {"#9400d3", "#009e73", "#56b4e9", "#e69f00", "#c8b400",
                                        "#0072b2", "#e51e10", "#000000", "#a0522d"};
  std::size_t i = 0;
  for (core::Integrator k : core::kIntegrators) {
    if (integrator == core::to_string(k)) break;
    ++i;
  }
  return " lc rgb '" + std::string(colours[i % 9]) + "' pt " + std::to_string(i + 1);
}

std::string free_section(const fs::path& file, const std::string& gnuplot) {
  const Csv csv = report_support::read_csv(file);
  const std::size_t c_f = column(csv, "formulation", file), c_i = column(csv, "integrator", file),
                    c_tol = column(csv, "tolerance", file), c_st = column(csv, "status", file),
                    c_t = column(csv, "cpu_time", file), c_e = column(csv, "final_error", file),
                    c_d = column(csv, "digits", file), c_m = column(csv, "max_error", file),
                    c_steps = column(csv, "steps", file),
                    c_rf = column(csv, "reference_formulation", file),
                    c_ri = column(csv, "reference_integrator", file),
                    c_rt = column(csv, "reference_tolerance", file);

  // methods in file order, each with its rows
  std::vector<std::pair<std::string, std::string>> methods;
  std::map<std::pair<std::string, std::string>, std::vector<const std::vector<std::string>*>> of;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    const auto key = std::pair{row[c_f], row[c_i]};
    if (of.find(key) == of.end()) methods.push_back(key);
    of[key].push_back(&row);
  }
  std::vector<std::string> formulations;
  for (const auto& m : methods) {
    if (std::find(formulations.begin(), formulations.end(), m.first) == formulations.end()) {
      formulations.push_back(m.first);
    }
  }

  std::string h =
      "<p>From <a href=\"work-precision.csv\">work-precision.csv</a> (<code>balance-design "
      "bench</code>): every formulation with every integrator it supports, at each tolerance "
      "(absolute tolerance 1e-2 of it), the median CPU time of one run of the study's free "
      "scene against its error. The error is that of &theta;1..&theta;3 against a reference "
      "computed by a different formulation";
  if (!csv.rows.empty() && csv.rows.front().size() > c_rt) {
    const auto& r = csv.rows.front();
    h += " (" + esc(r[c_ri]) + " at tolerance " + esc(fmt(number_at(r, c_rt), "%.0e")) +
         "; the reference of " + esc(r[c_f]) + " is " + esc(r[c_rf]) + ")";
  }
  h += ": the largest relative error at the final time (its -log10 is the number of correct "
       "digits) and the largest error over all samples.</p>\n";

  // the charts: one per formulation, a line per integrator
  std::string datablocks;
  std::vector<Chart> charts;
  for (std::size_t fi = 0; fi < formulations.size(); ++fi) {
    std::string plot;
    int lines = 0;
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      if (methods[mi].first != formulations[fi]) continue;
      const std::string block = "$wp_" + std::to_string(mi);
      std::string data;
      for (const auto* row : of[methods[mi]]) {
        const double e = number_at(*row, c_e), t = number_at(*row, c_t);
        if ((*row)[c_st] != "completed" || !(e > 0) || !(t > 0)) continue;
        data += fmt(e, "%.6g") + "," + fmt(1e3 * t, "%.6g") + "\n";
      }
      if (data.empty()) continue;
      datablocks += block + " << EOD\n" + data + "EOD\n";
      ++lines;
      plot += std::string(lines > 1 ? ", " : "") + block + " using 1:2 with linespoints lw 2" +
              line_style(methods[mi].second) + " title " + gp_string(methods[mi].second);
    }
    if (lines == 0) continue;
    charts.push_back(
        {"work-precision-" + formulations[fi], "Work-precision: " + formulations[fi],
         "CPU time of one run against the largest relative error of theta1..theta3 at the "
         "final time, one line per integrator, one point per tolerance (more accurate to the "
         "right); runs that stopped early are left out. From work-precision.csv.",
         "set logscale xy\nset format x '1e%L'\nset xrange [*:*] reverse\n"
         "set xlabel 'relative error at the final time'\nset ylabel 'CPU time per run [ms]'\n"
         "plot " +
             plot});
  }

  // the compact table: per method, the run at tolerance 1e-10 and the cheapest run with
  // 10 correct digits
  h += "<table><tr><th>formulation</th><th>integrator</th><th>at tolerance 1e-10: CPU time "
       "[ms]</th><th>digits</th><th>max error [rad]</th><th>steps</th><th>cheapest run with "
       "&ge; 10 digits: tolerance</th><th>CPU time [ms]</th><th>failed runs</th></tr>";
  for (const auto& m : methods) {
    const std::vector<std::string>* at = nullptr;
    const std::vector<std::string>* best = nullptr;
    int failed = 0;
    for (const auto* row : of[m]) {
      if ((*row)[c_st] != "completed") ++failed;
      if (std::abs(number_at(*row, c_tol) / 1e-10 - 1) < 1e-6) at = row;
      if ((*row)[c_st] == "completed" && number_at(*row, c_d) >= 10 &&
          (best == nullptr || number_at(*row, c_t) < number_at(*best, c_t))) {
        best = row;
      }
    }
    const auto cell = [](double v, const char* f) {
      return std::isnan(v) ? std::string("<td class=\"n\">&ndash;</td>")
                           : "<td class=\"n\">" + esc(fmt(v, f)) + "</td>";
    };
    h += "<tr><td>" + esc(m.first) + "</td><td>" + esc(m.second) + "</td>";
    if (at != nullptr && (*at)[c_st] == "completed") {
      h += cell(1e3 * number_at(*at, c_t), "%.3g") + cell(number_at(*at, c_d), "%.1f") +
           cell(number_at(*at, c_m), "%.2g") + cell(number_at(*at, c_steps), "%.0f");
    } else {
      h += "<td colspan=\"4\">" + esc(at != nullptr ? (*at)[c_st] : std::string("not run")) +
           "</td>";
    }
    if (best != nullptr) {
      h += cell(number_at(*best, c_tol), "%.0e") + cell(1e3 * number_at(*best, c_t), "%.3g");
    } else {
      h += "<td colspan=\"2\">none</td>";
    }
    h += "<td class=\"n\">" + std::to_string(failed) + "</td></tr>";
  }
  h += "</table>\n";

  if (gnuplot.empty()) return h + kChartNotice;
  const std::vector<std::string> svgs = report_support::draw(gnuplot, datablocks, charts);
  for (std::size_t i = 0; i < charts.size(); ++i) h += figure(charts[i], svgs[i]);
  return h;
}

std::string driven_section(const fs::path& file, const std::string& gnuplot) {
  const Csv csv = report_support::read_csv(file);
  const std::size_t c_f = column(csv, "formulation", file), c_n = column(csv, "samples", file),
                    c_st = column(csv, "status", file), c_t = column(csv, "cpu_time", file),
                    c_ef = column(csv, "Fsh_rms_error", file),
                    c_em = column(csv, "Msh_rms_error", file),
                    c_rf = column(csv, "reference_formulation", file),
                    c_rn = column(csv, "reference_samples", file);
  std::vector<std::string> formulations;
  std::map<std::string, std::vector<const std::vector<std::string>*>> of;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    if (of.find(row[c_f]) == of.end()) formulations.push_back(row[c_f]);
    of[row[c_f]].push_back(&row);
  }

  std::string h =
      "<p>From <a href=\"driven-convergence.csv\">driven-convergence.csv</a> "
      "(<code>balance-design bench</code>): one revolution of the study's driven scene per "
      "formulation and number of samples per revolution, its median CPU time, and the relative "
      "error of its RMS shaking force and moment against a revolution of ";
  if (!csv.rows.empty()) {
    h += esc(csv.rows.front()[c_rn]) + " samples computed by a different formulation (that of " +
         esc(csv.rows.front()[c_f]) + " is " + esc(csv.rows.front()[c_rf]) + ")";
  }
  h += ". Evenly spaced samples of a periodic motion make the RMS a trapezoidal rule of a "
       "smooth periodic function, which converges faster than any power of the samples "
       "(spectrally) down to round-off.</p>\n";

  std::string datablocks, errors, times;
  int lines = 0;
  for (std::size_t fi = 0; fi < formulations.size(); ++fi) {
    std::string ef, em, t;
    for (const auto* row : of[formulations[fi]]) {
      if ((*row)[c_st] != "completed") continue;
      const double n = number_at(*row, c_n);
      const double e1 = number_at(*row, c_ef), e2 = number_at(*row, c_em);
      const double ct = number_at(*row, c_t);
      if (e1 > 0) ef += fmt(n, "%.0f") + "," + fmt(e1, "%.6g") + "\n";
      if (e2 > 0) em += fmt(n, "%.0f") + "," + fmt(e2, "%.6g") + "\n";
      if (ct > 0) t += fmt(n, "%.0f") + "," + fmt(1e6 * ct, "%.6g") + "\n";
    }
    const std::string id = std::to_string(fi);
    const std::string name = formulations[fi];
    const auto add = [&](const std::string& block, const std::string& data, std::string& plot,
                         const std::string& title, int dash) {
      if (data.empty()) return;
      datablocks += block + " << EOD\n" + data + "EOD\n";
      plot += std::string(plot.empty() ? "" : ", ") + block +
              " using 1:2 with linespoints lw 2 lc " + std::to_string(fi + 1) + " dt " +
              std::to_string(dash) + " pt " + std::to_string(fi + 5) + " title " + gp_string(title);
      ++lines;
    };
    add("$dc_f" + id, ef, errors, name + ": Fsh_rms", 1);
    add("$dc_m" + id, em, errors, name + ": Msh_rms", 2);
    add("$dc_t" + id, t, times, name, 1);
  }
  std::vector<Chart> charts;
  if (!errors.empty()) {
    charts.push_back({"driven-convergence-error", "RMS error against samples per revolution",
                      "Relative error of the RMS shaking force and moment of one revolution "
                      "against the reference, per formulation; errors of exactly 0 are left "
                      "out. From driven-convergence.csv.",
                      "set logscale xy\nset format y '1e%L'\nset xlabel 'samples per "
                      "revolution'\nset ylabel 'relative error of the RMS'\nplot " +
                          errors});
  }
  if (!times.empty()) {
    charts.push_back({"driven-convergence-time", "CPU time against samples per revolution",
                      "Median CPU time of one revolution (core::simulate_driven and "
                      "core::metrics), per formulation. From driven-convergence.csv.",
                      "set logscale xy\nset xlabel 'samples per revolution'\nset ylabel 'CPU "
                      "time per revolution [us]'\nplot " +
                          times});
  }

  h += "<table><tr><th>formulation</th><th>samples for both errors &lt; 1e-12</th><th>CPU time "
       "[&micro;s]</th><th>at 360 samples: CPU time [&micro;s]</th><th>Fsh_rms error</th>"
       "<th>Msh_rms error</th></tr>";
  for (const std::string& f : formulations) {
    const std::vector<std::string>* enough = nullptr;
    const std::vector<std::string>* at = nullptr;
    for (const auto* row : of[f]) {
      const double e1 = number_at(*row, c_ef), e2 = number_at(*row, c_em);
      const bool small = (std::isnan(e1) || e1 < 1e-12) && (std::isnan(e2) || e2 < 1e-12) &&
                         !(std::isnan(e1) && std::isnan(e2));
      if ((*row)[c_st] == "completed" && small && enough == nullptr) enough = row;
      if ((*row)[c_n] == "360") at = row;
    }
    const auto cell = [](const std::string& v) { return report_support::num_cell(v); };
    h += "<tr><td>" + esc(f) + "</td>";
    h += enough != nullptr ? cell((*enough)[c_n]) + "<td class=\"n\">" +
                                 esc(fmt(1e6 * number_at(*enough, c_t), "%.3g")) + "</td>"
                           : std::string("<td colspan=\"2\">none</td>");
    h += at != nullptr ? "<td class=\"n\">" + esc(fmt(1e6 * number_at(*at, c_t), "%.3g")) +
                             "</td>" + cell((*at)[c_ef]) + cell((*at)[c_em])
                       : std::string("<td colspan=\"3\">not measured</td>");
    h += "</tr>";
  }
  h += "</table>\n";

  if (gnuplot.empty()) return h + kChartNotice;
  const std::vector<std::string> svgs = report_support::draw(gnuplot, datablocks, charts);
  for (std::size_t i = 0; i < charts.size(); ++i) h += figure(charts[i], svgs[i]);
  return h;
}

}  // namespace

std::string work_precision_section(const fs::path& dir, const std::string& gnuplot) {
  std::string h;
  std::error_code ec;
  if (fs::is_regular_file(dir / "work-precision.csv", ec)) {
    h += free_section(dir / "work-precision.csv", gnuplot);
  }
  if (fs::is_regular_file(dir / "driven-convergence.csv", ec)) {
    h += driven_section(dir / "driven-convergence.csv", gnuplot);
  }
  return h.empty() ? h : "<h2 id=\"speed-against-accuracy\">Speed against accuracy</h2>\n" + h;
}

}  // namespace bd::studies
